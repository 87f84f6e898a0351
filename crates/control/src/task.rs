//! The task model `c = [p0, d, n]` (Eq. 1) and its validation.

use emg_kinematics::{JointVector, Plate, Robot, Vec3, WorkSurface};
use serde::{Deserialize, Serialize};

use crate::path::Path;

/// Largest `|d·n|` accepted as perpendicular; smaller deviations are removed exactly.
pub const PERPENDICULAR_TOLERANCE: f64 = 1e-6;

/// Deviations (of `‖v‖` from 1, of `d·n` from 0) this small are rounding: such vectors are kept
/// unchanged, so that `Task::new` on an already validated task returns it bit for bit.
const ROUNDING: f64 = 4.0 * f64::EPSILON;

/// Largest distance (m) between `p0` and the TCP of a supplied `q0_seed`.
pub const SEED_POSITION_TOLERANCE_M: f64 = 1e-6;

/// A straight-line task: start `p0`, unit direction `d`, unit task-plane normal `n` (`d ⟂ n`),
/// and optionally the configuration that generated it (`q0_seed`, the fallback seed); or a
/// path task ([`Task::on_path`]): a [`Path`] from `p0`, with `d` its tangent at the start.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Task {
    /// Start position `p0` (m).
    pub p0: Vec3,
    /// Unit motion direction `d`.
    pub d: Vec3,
    /// Unit task-plane normal `n`; the tool axis must stay within `θ_max` of it.
    pub n: Vec3,
    /// Configuration that generated the task, if known (`q0_seed`).
    #[serde(default)]
    pub q0_seed: Option<JointVector>,
    /// The path the tool follows, when it is not the straight line from `p0` along `d`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<Path>,
    /// The space the arm's base occupies ([`Robot::base_column`]: start, end, radius), where a
    /// line's plate ends: derived from the robot whenever the task is validated ([`Task::new`],
    /// [`Task::revalidated`]), so not part of a task file.
    #[serde(skip)]
    pub base_column: Option<(Vec3, Vec3, f64)>,
}

/// Tasks are equal when what a task file holds is (`p0`, `d`, `n`, `q0_seed`, the path): the
/// base column is the robot's, derived again whenever a task is validated.
impl PartialEq for Task {
    fn eq(&self, other: &Self) -> bool {
        (self.p0, self.d, self.n, self.q0_seed) == (other.p0, other.d, other.n, other.q0_seed)
            && self.path == other.path
    }
}

/// Where the TCP stands along its task: how far it has come, which way the task goes on, and
/// its offset from the line or path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Along {
    /// Progress along the line or arc length along the path (m).
    pub s_m: f64,
    /// Unit direction the task commands from here: `d` on a line, the path's tangent on a path
    /// (the next piece's once the TCP is at a corner).
    pub heading: Vec3,
    /// Lateral error vector from the TCP to the line or to its nearest path point.
    pub lateral: Vec3,
}

/// Arc length (m) within which the TCP counts as at a corner or at the end of its path.
pub const ARRIVAL_M: f64 = 1e-4;

/// Arc length (m) beyond the last known progress that a path task searches for the TCP's
/// nearest path point at most: far more than one step goes.
pub const TRACKING_WINDOW_M: f64 = 0.05;

/// How far (m of arc length per m of distance) the progress along a path may advance from the
/// last known progress `s` for a TCP at `p`: `PROGRESS_PER_DISTANCE · |p − P(s)| +`
/// [`PROGRESS_SLACK_M`]; it never goes back. A TCP on the path that moves by `δ` advances by
/// about `δ` (a little more on a curve: the arc of a chord `δ` on a circle of radius `r ≥ δ/2`
/// is at most `π/2 · δ`, for the half-turn; 1.05 `δ` at `δ = r/2`), so the progress keeps up
/// with any motion along the path; but it cannot jump from one leg of a reversal (or of a path
/// that comes back near itself) to the other, which lie near in space and far apart along the
/// path, nor slip back along the leg it came by: the TCP must travel the stretch between them
/// to be measured against the second.
pub const PROGRESS_PER_DISTANCE: f64 = 1.6;

/// The progress's move allowed for a TCP exactly at its last known path point (m): the
/// rounding of the nearest-point search, far less than a tolerance.
pub const PROGRESS_SLACK_M: f64 = 1e-5;

/// The arc length (m) beyond the last known progress `s_hint` that a path task searches for a
/// TCP at distance `distance_m` from the path point at `s_hint` ([`PROGRESS_PER_DISTANCE`]).
pub fn progress_window_m(distance_m: f64) -> f64 {
    (PROGRESS_PER_DISTANCE * distance_m + PROGRESS_SLACK_M).min(TRACKING_WINDOW_M)
}

/// Why a task was rejected; names the field and what is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TaskError {
    /// A field holds NaN or infinity.
    #[error("task field '{field}' is not finite: {value:?}")]
    NotFinite {
        /// Field name.
        field: &'static str,
        /// Values given.
        value: Vec<f64>,
    },
    /// A direction field is (numerically) the zero vector.
    #[error("task field '{field}' is a zero vector; it must be a direction")]
    ZeroVector {
        /// Field name.
        field: &'static str,
    },
    /// `d` and `n` are not perpendicular.
    #[error(
        "task fields 'd' and 'n' are not perpendicular: |d·n| = {dot:.3e} exceeds {PERPENDICULAR_TOLERANCE:e}"
    )]
    NotPerpendicular {
        /// `|d·n|` after normalisation.
        dot: f64,
    },
    /// `p0` lies outside the arm's reach.
    #[error(
        "task field 'p0' = {p0:?} is unreachable: {distance_m:.3} m from the first joint, reach is {reach_m:.3} m"
    )]
    Unreachable {
        /// The start given.
        p0: [f64; 3],
        /// Its distance from the reach centre (m).
        distance_m: f64,
        /// The arm's reach (m).
        reach_m: f64,
    },
    /// `q0_seed` is not a valid generating configuration of this task.
    #[error("task field 'q0_seed' {problem}")]
    BadSeed {
        /// What is wrong with it.
        problem: String,
    },
}

impl Task {
    /// Builds and validates a task: `d` and `n` are normalised, `d` is made exactly
    /// perpendicular to `n` when it already is within [`PERPENDICULAR_TOLERANCE`] (vectors
    /// already unit and perpendicular to rounding are kept bit for bit, so validation is
    /// idempotent), and `p0` must
    /// lie within the robot's reach. A given `q0_seed` must lie within the joint limits and put the
    /// TCP at `p0`.
    pub fn new(
        robot: &Robot,
        p0: Vec3,
        d: Vec3,
        n: Vec3,
        q0_seed: Option<JointVector>,
    ) -> Result<Self, TaskError> {
        finite("p0", p0.as_slice())?;
        let d = unit("d", d)?;
        let n = unit("n", n)?;
        let dot = d.dot(&n);
        if dot.abs() > PERPENDICULAR_TOLERANCE {
            return Err(TaskError::NotPerpendicular { dot: dot.abs() });
        }
        // Already perpendicular to rounding: keep `d` as is, so that validating a validated task
        // (e.g. one read back from a task file) reproduces it bit for bit.
        let d = if dot.abs() <= ROUNDING {
            d
        } else {
            (d - n * dot).normalize()
        };
        let (centre, reach) = robot.reach_sphere();
        let distance = (p0 - centre).norm();
        if distance > reach {
            return Err(TaskError::Unreachable {
                p0: [p0.x, p0.y, p0.z],
                distance_m: distance,
                reach_m: reach,
            });
        }
        if let Some(q) = &q0_seed {
            finite("q0_seed", q.as_slice())?;
            if let Some(joint) = robot.limits().first_violation(q, 0.0) {
                return Err(TaskError::BadSeed {
                    problem: format!(
                        "joint {} = {:.4} rad is outside its limits [{:.4}, {:.4}]",
                        joint + 1,
                        q[joint],
                        robot.limits().lower[joint],
                        robot.limits().upper[joint]
                    ),
                });
            }
            let offset = (robot.forward(q).tcp() - p0).norm();
            if offset > SEED_POSITION_TOLERANCE_M {
                return Err(TaskError::BadSeed {
                    problem: format!("puts the TCP {offset:.3e} m from p0"),
                });
            }
        }
        Ok(Self {
            p0,
            d,
            n,
            q0_seed,
            path: None,
            base_column: robot.base_column(),
        })
    }

    /// A path task: the tool follows `path` from its start, the tool axis within the cone
    /// around its normal; `d` is the path's tangent at the start. Validated as [`Task::new`]
    /// validates a line from the path's start along that tangent.
    pub fn on_path(
        robot: &Robot,
        path: Path,
        q0_seed: Option<JointVector>,
    ) -> Result<Self, TaskError> {
        let start = path.point_at(0.0);
        let line = Self::new(robot, start, path.tangent_at(0.0), path.normal(), q0_seed)?;
        Ok(Self {
            path: Some(path),
            ..line
        })
    }

    /// Where the TCP at `p` stands along the task; on a path, its nearest path point within
    /// [`progress_window_m`] of the progress `s_hint` it last had, and not past the next
    /// unblended corner unless `s_hint` lies within [`ARRIVAL_M`] of it: the progress follows
    /// the TCP's travel, so each point is measured against the stretch of the path it has
    /// reached, and no corner counts as passed that the TCP did not come to.
    #[inline]
    pub fn along(&self, p: &Vec3, s_hint: f64) -> Along {
        match &self.path {
            None => Along {
                s_m: self.progress(p),
                heading: self.d,
                lateral: self.lateral_error(p),
            },
            Some(path) => {
                // An unblended corner is passed only from within ARRIVAL_M of it: the TCP must
                // come to the corner (be measured against it) before it counts as beyond.
                let window = progress_window_m((path.point_at(s_hint) - p).norm());
                let window = path
                    .next_corner_m(s_hint + ARRIVAL_M)
                    .map_or(window, |corner| window.min(corner - s_hint));
                let located = path.locate(p, s_hint, window);
                let at_corner = path
                    .next_corner_m(located.s - ARRIVAL_M)
                    .filter(|&corner| corner <= located.s + ARRIVAL_M);
                Along {
                    s_m: located.s,
                    heading: at_corner.map_or(located.tangent, |corner| path.tangent_at(corner)),
                    lateral: located.point - p,
                }
            }
        }
    }

    /// The point at progress `s_m` along the line, or at arc length `s_m` along the path
    /// (clamped to it).
    pub fn point_at(&self, s_m: f64) -> Vec3 {
        match &self.path {
            None => self.p0 + self.d * s_m,
            Some(path) => path.point_at(s_m),
        }
    }

    /// The unit direction of the line, or the path's tangent at arc length `s_m`.
    pub fn heading_at(&self, s_m: f64) -> Vec3 {
        match &self.path {
            None => self.d,
            Some(path) => path.tangent_at(s_m),
        }
    }

    /// The path's length (m); `None` for a line, which goes on as far as the arm can follow it.
    pub fn length_m(&self) -> Option<f64> {
        self.path.as_ref().map(Path::length_m)
    }

    /// The task validated again for `robot` (a task read from a file): a validated task comes
    /// back bit for bit, its path kept.
    pub fn revalidated(&self, robot: &Robot) -> Result<Self, TaskError> {
        match &self.path {
            None => Self::new(robot, self.p0, self.d, self.n, self.q0_seed),
            Some(path) => Self::on_path(robot, path.clone(), self.q0_seed),
        }
    }

    /// The work surface `surface` names, for this task. A plate is a part, and no part stands
    /// where the arm's base does:
    /// - on a path task it covers the path with its margins and no more: half its width to each
    ///   side of the path, `behind_m` behind its rearmost point and as much beyond its foremost
    ///   (`ahead_m` is a line's);
    /// - on a line it reaches `ahead_m` beyond `p0`, or less: it ends where it would come
    ///   within the arm's base column ([`Robot::base_column`]), which no configuration moves
    ///   out of the way (tested with the plate's half-diagonal `√(half_width² + thickness²)`
    ///   around the line; a line starting within it keeps the whole plate).
    pub fn work_surface(&self, surface: &WorkSurface) -> WorkSurface {
        match (surface, &self.path) {
            (WorkSurface::Plate(plate), Some(path)) => {
                let extent = path.extent();
                WorkSurface::Plate(Plate {
                    half_width_m: plate.half_width_m + extent.across_m,
                    behind_m: plate.behind_m + extent.behind_m,
                    ahead_m: extent.ahead_m + plate.behind_m,
                    thickness_m: plate.thickness_m,
                })
            }
            (WorkSurface::Plate(plate), None) => WorkSurface::Plate(Plate {
                ahead_m: plate.ahead_m.min(self.base_clear_ahead_m(plate)),
                ..*plate
            }),
            _ => *surface,
        }
    }

    /// Whether `p0` lies inside the space the arm's base occupies ([`Robot::base_column`]).
    pub fn inside_base_column(&self) -> bool {
        self.base_column.is_some_and(|(start, end, radius)| {
            emg_kinematics::segment_distance(&self.p0, &self.p0, &start, &end) <= radius
        })
    }

    /// How far along `d` a line's plate reaches before it would meet the base column
    /// (unbounded when it never does, or when `p0` already lies within it).
    fn base_clear_ahead_m(&self, plate: &Plate) -> f64 {
        let Some((start, end, radius)) = &self.base_column else {
            return f64::INFINITY;
        };
        let half_diagonal = libm::hypot(plate.half_width_m, plate.thickness_m);
        match emg_kinematics::capsule_ray_entry(
            start,
            end,
            *radius,
            half_diagonal,
            &self.p0,
            &self.d,
        ) {
            Some(s) if s > 0.0 => s,
            _ => f64::INFINITY,
        }
    }

    /// The distance (m) from `p` to the line, or to the nearest point of the whole path.
    pub fn distance(&self, p: &Vec3) -> f64 {
        self.offset(p).norm()
    }

    /// The vector from `p` to the nearest point of the line, or of the whole path.
    pub fn offset(&self, p: &Vec3) -> Vec3 {
        match &self.path {
            None => self.lateral_error(p),
            Some(path) => path.nearest_point(p).point - p,
        }
    }

    /// How far (m) the TCP at arc length `s_m` may go before it must stop: the next corner or
    /// the end of its path; unbounded on a line.
    pub fn stop_ahead_m(&self, s_m: f64) -> f64 {
        match &self.path {
            None => f64::INFINITY,
            Some(path) => {
                let stop = path
                    .next_corner_m(s_m + ARRIVAL_M)
                    .unwrap_or(path.length_m());
                (stop - s_m).max(0.0)
            }
        }
    }

    /// Whether the TCP at arc length `s_m` has reached the end of its path (never on a line).
    pub fn completed(&self, s_m: f64) -> bool {
        self.path
            .as_ref()
            .is_some_and(|path| s_m >= path.length_m() - ARRIVAL_M)
    }

    /// Signed progress `(p − p0)·d` of a TCP position along the line (m).
    pub fn progress(&self, p: &Vec3) -> f64 {
        (p - self.p0).dot(&self.d)
    }

    /// Lateral error vector from `p` to the task line (component of `p0 − p` ⟂ `d`).
    pub fn lateral_error(&self, p: &Vec3) -> Vec3 {
        let offset = self.p0 - p;
        offset - self.d * offset.dot(&self.d)
    }
}

fn finite(field: &'static str, values: &[f64]) -> Result<(), TaskError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(TaskError::NotFinite {
            field,
            value: values.to_vec(),
        })
    }
}

fn unit(field: &'static str, v: Vec3) -> Result<Vec3, TaskError> {
    finite(field, v.as_slice())?;
    let norm = v.norm();
    if norm < 1e-9 {
        return Err(TaskError::ZeroVector { field });
    }
    // A vector that is unit to rounding is kept unchanged (idempotent validation).
    Ok(if (norm - 1.0).abs() <= ROUNDING {
        v
    } else {
        v / norm
    })
}
