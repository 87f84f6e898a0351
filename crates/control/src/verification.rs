//! Handing rollouts to the independent checker (`emg-verify`): the task, the constraints and the
//! recorded trajectory as the checker's plain data. Nothing here checks anything; the checker
//! recomputes every quantity from the robot file.

use emg_kinematics::{Shape, WorkSurface};
use emg_verify::{
    Blame, Bounds, CheckFailure, Ending, Line, Obstacle, PathPiece, RecordedStep, Recording,
    ReferenceModel, Solid, Surface,
};

use crate::config::ConstraintConfig;
use crate::constraints::Violation;
use crate::rollout::{Termination, Trajectory};
use crate::task::Task;

impl From<&Task> for Line {
    fn from(task: &Task) -> Self {
        let pieces = task.path.as_ref().map_or(&[][..], |path| path.pieces());
        Self {
            p0: task.p0,
            d: task.d,
            n: task.n,
            path: pieces
                .iter()
                .map(|piece| match piece.outline() {
                    (start, end, None) => PathPiece::Straight { start, end },
                    (start, _, Some((centre, axis))) => PathPiece::Arc {
                        centre,
                        start,
                        axis,
                        sweep_rad: piece.length_m / (start - centre).norm(),
                    },
                })
                .collect(),
        }
    }
}

impl From<&ConstraintConfig> for Bounds {
    fn from(constraints: &ConstraintConfig) -> Self {
        Self {
            line_tolerance_m: constraints.line_tolerance_m,
            theta_max_deg: constraints.theta_max_deg,
            collision_margin_m: constraints.collision_margin_m,
            velocity_limit_fraction: constraints.velocity_limit_fraction.map(|f| f.get()),
            work_surface: surface(&constraints.work_surface),
            obstacles: constraints
                .scene
                .obstacles
                .iter()
                .map(|obstacle| Obstacle {
                    name: obstacle.name.clone(),
                    solid: solid(&obstacle.shape),
                    clearance_m: obstacle.clearance_m,
                    tool_may_touch: obstacle.tool_may_touch,
                })
                .collect(),
        }
    }
}

/// The bounds `constraints` set for `task`, as the checker's plain data: the work surface the
/// task's own ([`Task::work_surface`]: on a path task, a plate grown to cover the path).
pub fn task_bounds(task: &Task, constraints: &ConstraintConfig) -> Bounds {
    Bounds {
        work_surface: surface(&task.work_surface(&constraints.work_surface)),
        ..Bounds::from(constraints)
    }
}

/// The checker's plain description of a work surface.
fn surface(work_surface: &WorkSurface) -> Option<Surface> {
    match *work_surface {
        WorkSurface::Off => None,
        WorkSurface::HalfSpace => Some(Surface::HalfSpace),
        WorkSurface::Plate(plate) => Some(Surface::Plate {
            half_width_m: plate.half_width_m,
            behind_m: plate.behind_m,
            ahead_m: plate.ahead_m,
            thickness_m: plate.thickness_m,
        }),
    }
}

/// The checker's plain description of a shape.
fn solid(shape: &Shape) -> Solid {
    match shape {
        Shape::HalfSpace { point, normal } => Solid::HalfSpace {
            point: *point,
            outward: *normal,
        },
        Shape::Cuboid {
            centre,
            rotation,
            half_extents,
        } => Solid::Box {
            centre: *centre,
            axes: *rotation.matrix(),
            half_extents: *half_extents,
        },
        Shape::Sphere { centre, radius } => Solid::Ball {
            centre: *centre,
            radius: *radius,
        },
        Shape::Capsule { start, end, radius } => Solid::Capsule {
            a: *start,
            b: *end,
            radius: *radius,
        },
    }
}

impl From<&Violation> for Blame {
    fn from(violation: &Violation) -> Self {
        match violation {
            Violation::JointLimit { joint, .. } => Self::JointLimit { joint: *joint },
            Violation::LineTolerance { .. } => Self::LineTolerance,
            Violation::ToolCone { .. } => Self::ToolCone,
            Violation::SelfCollision { .. } => Self::SelfCollision,
            Violation::SceneContact { .. } => Self::SceneContact,
        }
    }
}

impl From<&Trajectory> for Recording {
    fn from(trajectory: &Trajectory) -> Self {
        let ending = match &trajectory.termination {
            Termination::Violation {
                violation,
                rejected_q,
            } => Ending::Rejected {
                blame: violation.into(),
                rejected_q: *rejected_q,
            },
            Termination::InvalidStart { violation } => Ending::InvalidStart {
                blame: violation.into(),
            },
            Termination::StepCap => Ending::Stopped,
            Termination::Completed => Ending::Completed,
        };
        Self {
            steps: trajectory
                .steps
                .iter()
                .map(|step| RecordedStep {
                    time_s: step.time_s,
                    q: step.q,
                    tcp: step.tcp,
                    tool_angle_deg: step.tool_angle_deg,
                })
                .collect(),
            ending,
            path_length_m: trajectory.path_length_m,
        }
    }
}

/// The independent re-check of a rollout: [`ReferenceModel::check_recording`] of the
/// trajectory as recorded, against the task's line and the constraints.
pub trait CheckRollout {
    /// Verifies every recorded step of `trajectory` of `task` under `constraints`.
    fn check(
        &self,
        task: &Task,
        trajectory: &Trajectory,
        constraints: &ConstraintConfig,
    ) -> Result<(), CheckFailure>;
}

impl CheckRollout for ReferenceModel {
    fn check(
        &self,
        task: &Task,
        trajectory: &Trajectory,
        constraints: &ConstraintConfig,
    ) -> Result<(), CheckFailure> {
        self.check_recording(
            &task.into(),
            &trajectory.into(),
            &task_bounds(task, constraints),
        )
    }
}
