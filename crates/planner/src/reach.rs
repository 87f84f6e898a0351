//! The reachability bound of a task: how far along the line the arm can be placed at all.
//!
//! Every point `p0 + s·d` of a 1 cm grid is searched, in order from `s = 0`, for a configuration
//! that puts the TCP on the point (or, failing that, within the line tolerance of it) with the
//! tool axis inside the cone around `n`, inside the joint limits, free of self-collision and
//! clear of the work surface and the scene's obstacles when the constraints hold them. The
//! scan stops at the first grid point where none is found; the bound is the last point reached.
//!
//! It is a *necessary* condition: a motion along the line needs such a configuration at every
//! point, but configurations found independently need not join into one continuous motion. So
//! no planner goes further than the true bound, and this estimate of it is an upper bound only as
//! good as its IK sampling (warm starts from the previous point's solutions, then seeded random
//! restarts): a point the sampling misses ends the scan early.

use emg_control::{ConstraintConfig, OutOfRange, Task, first_contact};
use emg_kinematics::{JointVector, Robot, Vec3};
use emg_seeding::{IkConfig, solve_cone_ik};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Settings of the reachability scan ([`reach`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReachConfig {
    /// Spacing of the grid along the line (m).
    pub grid_m: f64,
    /// Random IK restarts at a grid point (and at each of its offsets) where the warm starts
    /// fail.
    pub restarts: usize,
    /// Configurations carried from one grid point to the next as warm starts (distinct
    /// self-motion branches).
    pub branches: usize,
    /// Points around a missed grid point, at 90 % of the line tolerance from it, that are tried
    /// before the scan stops.
    pub offsets: usize,
    /// Seed of the random restarts.
    pub seed: u64,
}

impl Default for ReachConfig {
    fn default() -> Self {
        Self {
            grid_m: 0.01,
            restarts: 64,
            branches: 4,
            offsets: 6,
            seed: 20_261_123,
        }
    }
}

/// Most restarts per point a configuration may ask for (keeps a scan to seconds).
pub const MAX_REACH_RESTARTS: usize = 10_000;

impl ReachConfig {
    /// Checks every value against its allowed range.
    pub fn validate(&self) -> Result<(), OutOfRange> {
        let count = |n: usize| n as f64;
        OutOfRange::require("reach.grid_m", self.grid_m, "[0.001, 1]", |g| {
            (1e-3..=1.0).contains(&g)
        })?;
        OutOfRange::require("reach.restarts", count(self.restarts), "[0, 10000]", |n| {
            n <= MAX_REACH_RESTARTS as f64
        })?;
        OutOfRange::require("reach.branches", count(self.branches), "[1, 64]", |n| {
            (1.0..=64.0).contains(&n)
        })?;
        OutOfRange::require("reach.offsets", count(self.offsets), "[0, 64]", |n| {
            n <= 64.0
        })
    }
}

/// The reachability bound of one task.
#[derive(Clone, Debug, PartialEq)]
pub struct Reach {
    /// Largest `s` such that every grid point of `[0, s]` has a valid configuration (m); 0 when
    /// not even `p0` has one (then [`Reach::reachable_p0`] is false).
    pub reachable_m: f64,
    /// Whether `p0` itself has a valid configuration.
    pub reachable_p0: bool,
    /// The grid spacing (m).
    pub grid_m: f64,
    /// The evidence: one valid configuration per grid point from `p0` to the bound, in order.
    pub witnesses: Vec<JointVector>,
}

/// The reachability bound of `task` under `constraints` (module documentation); `hints` are
/// tried as warm starts at `p0` (a seed, the task's `q0_seed`). Deterministic for a given
/// `config.seed`.
pub fn reach(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    config: &ReachConfig,
    hints: &[JointVector],
) -> Reach {
    let scan = Scan {
        robot,
        task,
        constraints,
        config,
        ik: IkConfig {
            cone_deg: constraints.theta_max_deg,
            // Strictly inside the limits, which the rollout's check treats as closed.
            joint_margin_rad: 1e-6,
            max_iterations: 100,
            ..IkConfig::default()
        },
    };
    let (centre, radius) = robot.reach_sphere();
    let offsets = offset_directions(&task.n, &task.d, config.offsets);
    let mut carried: Vec<JointVector> = hints.to_vec();
    let mut witnesses = Vec::new();
    for k in 0u64.. {
        let s = k as f64 * config.grid_m;
        let point = task.p0 + task.d * s;
        // Beyond the sphere every link could span, no configuration exists.
        if (point - centre).norm() > radius {
            break;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        rng.set_stream(k);
        let mut targets = std::iter::once(point).chain(
            offsets
                .iter()
                .map(|e| point + e * (0.9 * constraints.line_tolerance_m)),
        );
        let Some(found) = targets.find_map(|target| {
            Some(scan.solutions_at(&target, &carried, &mut rng)).filter(|f| !f.is_empty())
        }) else {
            break;
        };
        witnesses.push(found[0]);
        carried = found;
    }
    Reach {
        reachable_m: witnesses.len().saturating_sub(1) as f64 * config.grid_m,
        reachable_p0: !witnesses.is_empty(),
        grid_m: config.grid_m,
        witnesses,
    }
}

/// One task's scan: what every grid point is searched with.
struct Scan<'a> {
    robot: &'a Robot,
    task: &'a Task,
    constraints: &'a ConstraintConfig,
    config: &'a ReachConfig,
    ik: IkConfig,
}

impl Scan<'_> {
    /// Valid configurations at `target`: the continuations of the `carried` warm starts
    /// (distinct, at most `config.branches`), or, when none continues, the first one random
    /// restarts find.
    fn solutions_at(
        &self,
        target: &Vec3,
        carried: &[JointVector],
        rng: &mut ChaCha8Rng,
    ) -> Vec<JointVector> {
        let (robot, ik, config) = (self.robot, &self.ik, self.config);
        let valid = |start: &JointVector| {
            solve_cone_ik(robot, start, target, &self.task.n, ik).filter(|q| {
                first_contact(robot, self.task, &robot.forward(q), self.constraints).is_none()
            })
        };
        let mut found: Vec<JointVector> = Vec::new();
        for start in carried {
            if found.len() == config.branches {
                break;
            }
            if let Some(q) = valid(start)
                && found.iter().all(|f| (f - q).amax() >= ik.dedup_rad)
            {
                found.push(q);
            }
        }
        if found.is_empty() {
            // Every restart's start is drawn first, in order, then they are tried in parallel
            // and the first one in that order that succeeds is kept: the result of trying them
            // one by one, whatever the thread count (the stream is read on only after all of
            // them failed, and then all of them were drawn either way). The restarts of a point
            // that has no valid configuration, the last of every scan, are most of its work.
            let limits = robot.limits();
            let starts: Vec<JointVector> = (0..config.restarts)
                .map(|_| {
                    JointVector::from_fn(|i, _| {
                        let u: f64 = rng.random();
                        limits.lower[i] + u * (limits.upper[i] - limits.lower[i])
                    })
                })
                .collect();
            found.extend(starts.par_iter().find_map_first(valid));
        }
        found
    }
}

/// `count` unit directions ⟂ `d` (across the line, where the line tolerance allows the TCP to
/// be), evenly spread, the first along `n`.
fn offset_directions(n: &Vec3, d: &Vec3, count: usize) -> Vec<Vec3> {
    let side = n.cross(d);
    (0..count)
        .map(|i| {
            let angle = std::f64::consts::TAU * i as f64 / count as f64;
            let (sin, cos) = libm::sincos(angle);
            n * cos + side * sin
        })
        .collect()
}
