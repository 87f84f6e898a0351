//! The reachability bound of a task: how far along the line the arm can be placed at all.
//!
//! Every point `p0 + s·d` of a 1 cm grid (on a path: every point 1 cm of arc length apart, and
//! its end) is searched, in order from `s = 0`, for a configuration
//! that puts the TCP on the point (or, failing that, within the line tolerance of it) with the
//! tool axis inside the cone around `n`, inside the joint limits, free of self-collision and
//! clear of the work surface and the scene's obstacles when the constraints hold them. The
//! scan stops at the first grid point where none is found; the bound is the last point reached.
//!
//! It is a *necessary* condition: a motion along the line needs such a configuration at every
//! point, but configurations found independently need not join into one continuous motion. So
//! no planner goes further than the true bound, and this estimate of it is an upper bound only as
//! good as its IK sampling (warm starts from the previous point's solutions, then seeded random
//! restarts, each given up once it stops converging): a point the sampling misses ends the
//! scan early. Every configuration a plan
//! visits is valid too, so a plan witnesses its own length ([`Reach::witness`]): the bound a
//! plan reports never reads below the plan.
//!
//! The scan's configurations also guide the search: joined into chains on one self-motion
//! branch ([`witness_chains`]), they show a motion along the line that the search follows. And
//! [`far_end_chains`] tests what the bound cannot say: whether configurations near its end
//! join `p0` through valid configurations at every grid point between.

use emg_control::{ConstraintConfig, OutOfRange, Task, Trajectory, first_contact, first_violation};
use emg_kinematics::{JointVector, PoseTarget, ProjectionConfig, Robot, Vec3, project_to_pose};
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
    /// The bound (m): the larger of [`Reach::scanned_m`] and the length of every plan it has
    /// witnessed ([`Reach::witness`]), since every configuration a plan visits is a valid one.
    pub reachable_m: f64,
    /// Largest `s` such that the scan found a valid configuration at every grid point of
    /// `[0, s]` (m); 0 when not even `p0` has one (then [`Reach::reachable_p0`] is false).
    pub scanned_m: f64,
    /// Whether `p0` itself has a valid configuration.
    pub reachable_p0: bool,
    /// The grid spacing (m).
    pub grid_m: f64,
    /// The evidence of the scan: one valid configuration per grid point from `p0` to
    /// [`Reach::scanned_m`], in order.
    pub witnesses: Vec<JointVector>,
}

impl Reach {
    /// Raises the bound to the length of `trajectory`, a motion every configuration of which
    /// holds every constraint: the points it reached are reachable, whatever the scan missed.
    pub fn witness(&mut self, trajectory: &Trajectory) {
        self.reachable_m = self.reachable_m.max(trajectory.path_length_m);
    }
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
    let scan = Scan::new(robot, task, constraints, config);
    let (centre, radius) = robot.reach_sphere();
    let offsets = offset_directions(&task.n, &task.d, config.offsets);
    let mut carried: Vec<JointVector> = hints.to_vec();
    let mut witnesses = Vec::new();
    let mut scanned_m = 0.0;
    for k in 0u64.. {
        let Some(s) = grid_point(task, k, config.grid_m) else {
            break;
        };
        let point = task.point_at(s);
        // Beyond the sphere every link could span, no configuration exists.
        if (point - centre).norm() > radius {
            break;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        rng.set_stream(k);
        let turned;
        let offsets = match task.path {
            None => &offsets,
            Some(_) => {
                turned = offset_directions(&task.n, &task.heading_at(s), config.offsets);
                &turned
            }
        };
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
        scanned_m = s;
    }
    Reach {
        reachable_m: scanned_m,
        scanned_m,
        reachable_p0: !witnesses.is_empty(),
        grid_m: config.grid_m,
        witnesses,
    }
}

/// The score reachability studies give a path, point by point: of the grid points of the
/// scan of `task`'s path ([`reach`]'s, on the point itself only), how many have a valid
/// configuration (IK with the tool in its cone, within the limits, free of contact), each
/// searched on its own: a miss does not end the count, and nothing asks that the
/// configurations join into a motion. Returns (points with one, points); (0, 0) on a line.
pub fn reachable_points(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    config: &ReachConfig,
) -> (usize, usize) {
    if task.path.is_none() {
        return (0, 0);
    }
    let scan = Scan::new(robot, task, constraints, config);
    let mut carried: Vec<JointVector> = task.q0_seed.into_iter().collect();
    let (mut reached, mut points) = (0, 0);
    for k in 0u64.. {
        let Some(s) = grid_point(task, k, config.grid_m) else {
            break;
        };
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        rng.set_stream(k);
        points += 1;
        let found = scan.solutions_at(&task.point_at(s), &carried, &mut rng);
        if !found.is_empty() {
            reached += 1;
            carried = found;
        }
    }
    (reached, points)
}

/// The arc length of the `k`-th grid point of `task`'s scan: `k · grid_m` along a line; along
/// a path the same, its last point at the path's end, and `None` past it.
fn grid_point(task: &Task, k: u64, grid_m: f64) -> Option<f64> {
    let s = k as f64 * grid_m;
    let Some(length) = task.length_m() else {
        return Some(s);
    };
    let before_end = |s: f64| s < length - 1e-9;
    if before_end(s) {
        Some(s)
    } else if k == 0 || before_end((k - 1) as f64 * grid_m) {
        Some(length)
    } else {
        None
    }
}

/// Share of the reachability bound below which a plan's output says that it ends short.
pub const SHORTFALL_SHARE: f64 = 0.9;

/// What a plan's output says of its task's reachability bound (`Planner::bound_note`).
#[derive(Clone, Debug, PartialEq)]
pub struct BoundNote {
    /// The bound (m), raised to the plan's length where the plan went beyond the scan.
    pub reachable_m: f64,
    /// Why the plan ends below [`SHORTFALL_SHARE`] of the bound, when it does ([`shortfall`]).
    pub shortfall: Option<String>,
    /// Whether the plan ends below [`SHORTFALL_SHARE`] of the bound and no chain of valid
    /// configurations ([`far_end_chains`]) joins `p0` to [`FAR_END_SHARE`] of it: the bound is
    /// likely loose there, its points on self-motion branches no motion joins.
    pub likely_loose: bool,
}

/// Why `trajectory` ends below [`SHORTFALL_SHARE`] of the bound `reachable_m`: how far it got,
/// what ended it, and what the bound's continuity test ([`far_end_chains`]) says: where a chain
/// of valid configurations joins `p0` to near the bound's end (`joined`), a longer motion may
/// exist; where none does, the bound is likely loose there.
pub fn shortfall(trajectory: &Trajectory, reachable_m: f64, joined: bool) -> String {
    let length = trajectory.path_length_m;
    let continuity = if joined {
        format!(
            "a chain of valid configurations joins `p0` to {:.0} % of the bound, so a longer \
             motion may exist (a larger search budget, `search.budget_steps` or \
             `search.widened_budget_steps`, may find it)",
            100.0 * FAR_END_SHARE
        )
    } else {
        format!(
            "the bound only says that every point up to it has a valid configuration, and no \
             chain of them was found that joins `p0` to {:.0} % of it, so the bound is likely \
             loose here",
            100.0 * FAR_END_SHARE
        )
    };
    format!(
        "the plan ends at {length:.2} m, below {SHORTFALL_SHARE} × the bound of {reachable_m:.2} \
         m, because {}; {continuity}",
        trajectory.termination
    )
}

/// The scan's IK gives a restart up once its residual has not fallen by a tenth in this many
/// iterations (`IkConfig::stall_iterations`). Measured on 300 FR3 evaluation tasks: the scan
/// takes 20 ms per task instead of 43, and the bounds sum to 210.506 m instead of 210.526.
const SCAN_STALL_ITERATIONS: usize = 10;

/// One task's scan: what every grid point is searched with.
struct Scan<'a> {
    robot: &'a Robot,
    task: &'a Task,
    constraints: &'a ConstraintConfig,
    config: &'a ReachConfig,
    ik: IkConfig,
}

impl<'a> Scan<'a> {
    fn new(
        robot: &'a Robot,
        task: &'a Task,
        constraints: &'a ConstraintConfig,
        config: &'a ReachConfig,
    ) -> Self {
        Self {
            robot,
            task,
            constraints,
            config,
            ik: IkConfig {
                cone_deg: constraints.theta_max_deg,
                // Strictly inside the limits, which the rollout's check treats as closed.
                joint_margin_rad: 1e-6,
                max_iterations: 100,
                // A restart that stopped converging is given up: the restarts at the point that
                // ends the scan, all of which fail, were most of the scan's work.
                stall_iterations: SCAN_STALL_ITERATIONS,
                ..IkConfig::default()
            },
        }
    }
}

/// The chains of the scan's witnesses joined back to `p0`: the witnesses split where two
/// neighbours differ by more than `max_jump_rad` (largest joint change: another self-motion
/// branch); each piece after the first is extended backwards from its first configuration, at
/// each grid point before it in turn, by the valid configuration on the pose nearest the one
/// after it (the Newton projection from it, else the cone IK from it), while the change stays
/// within `max_jump_rad`. The pieces that reach `p0` this way, with the first piece, are the
/// chains: each holds one configuration per grid point from `p0`, the farthest-reaching first.
pub fn witness_chains(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    config: &ReachConfig,
    reach: &Reach,
    max_jump_rad: f64,
) -> Vec<Vec<JointVector>> {
    if reach.witnesses.is_empty() {
        return Vec::new();
    }
    let scan = Scan::new(robot, task, constraints, config);
    let witnesses = &reach.witnesses;
    let mut starts = vec![0];
    starts.extend(
        (1..witnesses.len()).filter(|&k| (witnesses[k] - witnesses[k - 1]).amax() > max_jump_rad),
    );
    let mut chains = Vec::new();
    for (piece, &start) in starts.iter().enumerate() {
        let end = starts.get(piece + 1).copied().unwrap_or(witnesses.len());
        let mut chain = vec![witnesses[start]];
        for k in (0..start).rev() {
            let point = task.point_at(k as f64 * reach.grid_m);
            let after = chain[chain.len() - 1];
            match scan
                .nearest_on_pose(&point, &after)
                .or_else(|| scan.continuation(&point, &after))
            {
                Some(q) if (q - after).amax() <= max_jump_rad => chain.push(q),
                _ => break,
            }
        }
        if chain.len() == start + 1 {
            chain.reverse();
            chain.extend_from_slice(&witnesses[start + 1..end]);
            chains.push(chain);
        }
    }
    chains.sort_by_key(|chain| std::cmp::Reverse(chain.len()));
    chains
}

/// Share of the scan's reach at which [`far_end_chains`] start.
pub const FAR_END_SHARE: f64 = 0.95;

/// Chains of valid configurations joined from near the far end of the scan back to `p0`: a
/// test of whether the scan's points join into one motion, which the bound alone does not say.
/// Valid configurations at the grid point at [`FAR_END_SHARE`] of the scan (the scan's own
/// there, then cone-IK solutions from `restarts` seeded random starts) are each extended
/// backwards, at every grid point before it in turn, by the valid configuration nearest the one
/// after it (the cone IK from it or the projection onto the pose from it, whichever moves the
/// joints less), while the largest joint change stays within `max_jump_rad`. A chain that comes
/// within the IK's distinctness of an earlier chain's configuration at the same grid point would
/// follow that chain from there and is dropped. Returns the chains that reach `p0`, in the order
/// found, each with one configuration per grid point from `p0`.
pub fn far_end_chains(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    config: &ReachConfig,
    reach: &Reach,
    max_jump_rad: f64,
    restarts: usize,
) -> Vec<Vec<JointVector>> {
    if reach.witnesses.is_empty() {
        return Vec::new();
    }
    let far = ((reach.witnesses.len() - 1) as f64 * FAR_END_SHARE) as usize;
    let scan = Scan::new(robot, task, constraints, config);
    let point = |k: usize| task.point_at(k as f64 * reach.grid_m);
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    rng.set_stream(FAR_END_STREAM);
    let mut ends = vec![reach.witnesses[far]];
    for _ in 0..restarts {
        let start = random_configuration(robot, &mut rng);
        if let Some(q) = scan.continuation(&point(far), &start)
            && ends.iter().all(|e| (e - q).amax() >= scan.ik.dedup_rad)
        {
            ends.push(q);
        }
    }
    // The configurations the chains so far held at each grid point.
    let mut visited: Vec<Vec<JointVector>> = vec![Vec::new(); far + 1];
    let joins = |visited: &[Vec<JointVector>], k: usize, q: &JointVector| {
        visited[k]
            .iter()
            .any(|v| (v - q).amax() < scan.ik.dedup_rad)
    };
    let mut chains = Vec::new();
    for end in ends {
        if joins(&visited, far, &end) {
            continue;
        }
        let mut chain = vec![end];
        for k in (0..far).rev() {
            let after = chain[chain.len() - 1];
            match scan.nearest(&point(k), &after) {
                Some(q) if (q - after).amax() <= max_jump_rad && !joins(&visited, k, &q) => {
                    chain.push(q)
                }
                _ => break,
            }
        }
        for (i, q) in chain.iter().enumerate() {
            visited[far - i].push(*q);
        }
        if chain.len() == far + 1 {
            chain.reverse();
            chains.push(chain);
        }
    }
    chains
}

/// The random stream of [`far_end_chains`]' restarts (the scan's grid points take the streams
/// from 0 up).
const FAR_END_STREAM: u64 = u64::MAX;

impl Scan<'_> {
    /// Of the valid configurations at `target` the cone IK reaches from `start` and on the
    /// pose nearest `start`, the one with the smaller largest joint change.
    fn nearest(&self, target: &Vec3, start: &JointVector) -> Option<JointVector> {
        [
            self.continuation(target, start),
            self.nearest_on_pose(target, start),
        ]
        .into_iter()
        .flatten()
        .min_by(|a, b| (a - start).amax().total_cmp(&(b - start).amax()))
    }
}

impl Scan<'_> {
    /// The valid configuration at `target` with the tool axis along `n` nearest `start` (the
    /// Newton projection from it), if any.
    fn nearest_on_pose(&self, target: &Vec3, start: &JointVector) -> Option<JointVector> {
        let robot = self.robot;
        let pose = PoseTarget {
            position: *target,
            tool_axis: self.task.n,
            roll_axis: None,
        };
        let r = project_to_pose(robot, start, &pose, &ProjectionConfig::default());
        let (q, _) = r.ok()?;
        let kinematics = robot.forward(&q);
        first_violation(robot, self.task, &kinematics, self.constraints)
            .is_none()
            .then_some(q)
    }

    /// The valid configuration at `target` the cone IK reaches from `start`, if any.
    fn continuation(&self, target: &Vec3, start: &JointVector) -> Option<JointVector> {
        let robot = self.robot;
        solve_cone_ik(robot, start, target, &self.task.n, &self.ik).filter(|q| {
            first_contact(robot, self.task, &robot.forward(q), self.constraints).is_none()
        })
    }

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
        let valid = |start: &JointVector| self.continuation(target, start);
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
            let starts: Vec<JointVector> = (0..config.restarts)
                .map(|_| random_configuration(robot, rng))
                .collect();
            found.extend(starts.par_iter().find_map_first(valid));
        }
        found
    }
}

/// What keeps every configuration at a task's start from holding the constraints: of the
/// configurations the scan's IK finds at `p0` (the tool in its cone, the joints within their
/// limits) from seeded random restarts, the contacts they break, worst clearance first within
/// each kind.
#[derive(Clone, Debug, PartialEq)]
pub struct StartBlockers {
    /// Random restarts tried.
    pub restarts: usize,
    /// Configurations found at `p0` with the tool in its cone and the joints in their limits.
    pub found: usize,
    /// Each contact that blocks some of them (self-collision of two links, a link on an
    /// obstacle or on the work surface), with how many it blocks and the deepest clearance
    /// (m) among them; most frequent first.
    pub contacts: Vec<StartContact>,
}

/// One contact that blocks configurations at a task's start ([`StartBlockers`]).
#[derive(Clone, Debug, PartialEq)]
pub struct StartContact {
    /// The violation of the configuration that breaks it deepest.
    pub violation: emg_control::Violation,
    /// How many of the configurations found break it first.
    pub count: usize,
}

/// [`StartBlockers`] of `task`: `config.restarts` seeded random restarts of the scan's cone IK
/// at `p0` (at least 64), each solution's first contact tallied by the links (and obstacle) it
/// names. Deterministic for a given `config.seed`, whatever the number of threads.
pub fn start_blockers(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    config: &ReachConfig,
) -> StartBlockers {
    let scan = Scan::new(robot, task, constraints, config);
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let restarts = config.restarts.max(64);
    let starts: Vec<JointVector> = (0..restarts)
        .map(|_| random_configuration(robot, &mut rng))
        .collect();
    let solutions: Vec<Option<JointVector>> = starts
        .par_iter()
        .map(|start| solve_cone_ik(robot, start, &task.p0, &task.n, &scan.ik))
        .collect();
    let found: Vec<JointVector> = solutions.into_iter().flatten().collect();
    let mut contacts: Vec<StartContact> = Vec::new();
    for q in &found {
        let Some(violation) = first_contact(robot, task, &robot.forward(q), constraints) else {
            continue;
        };
        let same = |c: &&mut StartContact| same_contact(&c.violation, &violation);
        match contacts.iter_mut().find(same) {
            Some(contact) => {
                contact.count += 1;
                if clearance(&violation) < clearance(&contact.violation) {
                    contact.violation = violation;
                }
            }
            None => contacts.push(StartContact {
                violation,
                count: 1,
            }),
        }
    }
    contacts.sort_by_key(|contact| std::cmp::Reverse(contact.count));
    StartBlockers {
        restarts,
        found: found.len(),
        contacts,
    }
}

/// Whether two contacts name the same links (and obstacle).
fn same_contact(a: &emg_control::Violation, b: &emg_control::Violation) -> bool {
    use emg_control::Violation::{SceneContact, SelfCollision};
    match (a, b) {
        (
            SelfCollision {
                first_link: a1,
                second_link: a2,
                ..
            },
            SelfCollision {
                first_link: b1,
                second_link: b2,
                ..
            },
        ) => (a1, a2) == (b1, b2),
        (
            SceneContact {
                link: a_link,
                obstacle: a_obstacle,
                ..
            },
            SceneContact {
                link: b_link,
                obstacle: b_obstacle,
                ..
            },
        ) => (a_link, a_obstacle) == (b_link, b_obstacle),
        _ => false,
    }
}

/// The clearance (m) a contact reports.
fn clearance(violation: &emg_control::Violation) -> f64 {
    match violation {
        emg_control::Violation::SelfCollision { clearance_m, .. }
        | emg_control::Violation::SceneContact { clearance_m, .. } => *clearance_m,
        _ => 0.0,
    }
}

/// A configuration drawn uniformly within the joint limits, joint by joint in order.
fn random_configuration(robot: &Robot, rng: &mut ChaCha8Rng) -> JointVector {
    let limits = robot.limits();
    robot.configuration_from_fn(|i| {
        let u: f64 = rng.random();
        limits.lower[i] + u * (limits.upper[i] - limits.lower[i])
    })
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
