//! What lies between a plan's end and its bound: motions planned back from points beyond the
//! plan's end, and whether the arm can change in place from the plan's branch to theirs.
//!
//! The bound ([`crate::reach`]) only says that every point up to it has a valid configuration;
//! where a plan ends well short of it, either the search missed a motion or the configurations
//! beyond lie on branches no motion from `p0` reaches. [`gap_probes`] asks the line from the
//! far side: from a few points between the plan's end and the bound it plans the reversed task
//! (the whole planner, as [`Planner::plan`] plans, its far-end stage left out:
//! `Planner::motion_back`, the motions the search's own far-end stage asks for from the
//! same points) and sees where each motion back gets to:
//! - past `p0`: read forwards, a motion from `p0` to that point exists, longer than the plan;
//! - past the plan's end but not to `p0`: both motions cover the points between, and
//!   [`in_place_motion`] tries to join, at one of them, the plan's configuration to the motion
//!   back's with the TCP held still: joined, the two motions make one (with a stop to
//!   reconfigure);
//! - not back to the plan's end: no motion found from either side covers the points between.
//!
//! Where a motion back does not pass `p0`, [`motion_along_line`] also tries to join the plan's
//! configurations to the motion back's with the TCP anywhere on the line up to where the motion
//! back starts, going back and forth along it as it needs: joined, a motion from `p0` reaches
//! that start (retracing part of the line on the way).

use emg_control::{Task, Trajectory};
use emg_kinematics::{JointVector, Robot, Vec3, project_to_point};
use serde::{Deserialize, Serialize};

use crate::far_end::probe_starts;
use crate::in_place::{InPlaceConfig, in_place_motion, motion_along_line};
use crate::planner::{Plan, Planner};

/// Where a motion planned back from a point beyond a plan's end got to.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "outcome", rename_all = "snake_case")]
pub enum GapProbeOutcome {
    /// No motion starts at the point (no valid configuration there, or no plan).
    NoStart,
    /// The motion back passes `p0`: read forwards, a motion from `p0` to the point.
    PassesP0,
    /// The motion back ends before the plan's end.
    StopsShort,
    /// The motion back passes the plan's end; at `at_m` along the line, the plan's
    /// configuration and the motion back's, with the TCP on the point, are joined by a motion
    /// in place or not ([`in_place_motion`]; `None` where either is not a valid configuration
    /// on the point).
    Overlaps {
        /// Where the two configurations were compared (m along the line).
        at_m: f64,
        /// Whether a motion in place joins them.
        joined_in_place: Option<bool>,
        /// Largest joint difference between the two (rad); `None` as for `joined_in_place`.
        joint_gap_rad: Option<f64>,
    },
}

/// One motion planned back from a point beyond a plan's end ([`gap_probes`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GapProbe {
    /// Where the motion back starts (m along the line).
    pub from_m: f64,
    /// Where it ends (m along the line; negative past `p0`).
    pub back_to_m: f64,
    /// Whether a motion along the line up to `from_m` ([`motion_along_line`]) joins the plan's
    /// configurations to the motion back's; `None` where there is no motion back or it passes
    /// `p0`.
    pub joined_along_line: Option<bool>,
    /// What that means for the plan.
    #[serde(flatten)]
    pub outcome: GapProbeOutcome,
}

/// Grid steps of the scan on each side of the plan's end within which an overlap is compared.
const OVERLAP_GRID_STEPS: f64 = 4.0;

/// Motions planned back to `task`'s line from points beyond `plan`'s end, with `planner`'s
/// configuration (its work surface seen from each point), and what each says of the gap
/// between the plan and its bound (module documentation). The points
/// (`crate::far_end::probe_starts`): 3 and 10 grid steps of the scan past the plan's end,
/// halfway to the bound, and half a grid step before the bound; those not between the plan's
/// end and the bound are left out. Empty on a path task.
pub fn gap_probes(
    planner: &Planner,
    task: &Task,
    plan: &Plan,
    in_place: &InPlaceConfig,
) -> Vec<GapProbe> {
    if task.path.is_some() {
        return Vec::new();
    }
    let reach = planner.reach_of(task, plan);
    probe_starts(plan.trajectory.path_length_m, &reach)
        .into_iter()
        .map(|from_m| GapProbe {
            from_m,
            ..probe_from(planner, task, &plan.trajectory, from_m, in_place)
        })
        .collect()
}

/// The probe of [`gap_probes`] from `from_m` along the line.
fn probe_from(
    planner: &Planner,
    task: &Task,
    forward: &Trajectory,
    from_m: f64,
    in_place: &InPlaceConfig,
) -> GapProbe {
    let no_start = GapProbe {
        from_m,
        back_to_m: from_m,
        joined_along_line: None,
        outcome: GapProbeOutcome::NoStart,
    };
    let robot = planner.robot();
    let Some(back) = planner.motion_back(task, from_m) else {
        return no_start;
    };
    let back_to_m = from_m - back.path_length_m;
    let end_m = forward.path_length_m;
    let outcome = if back_to_m <= 0.0 {
        GapProbeOutcome::PassesP0
    } else if back_to_m >= end_m {
        GapProbeOutcome::StopsShort
    } else {
        let grid_m = planner.config().reach.grid_m;
        let at_m = 0.5 * (back_to_m.max(end_m - OVERLAP_GRID_STEPS * grid_m) + end_m);
        let point = task.point_at(at_m);
        let ends =
            [forward, &back].map(|trajectory| on_point(robot, task, trajectory, at_m, &point));
        let joint_gap_rad = match ends {
            [Some(a), Some(b)] => Some((a - b).amax()),
            _ => None,
        };
        let joined_in_place = match ends {
            [Some(a), Some(b)] => Some(
                in_place_motion(
                    robot,
                    task,
                    &planner.config().rollout.constraints,
                    &point,
                    &a,
                    &b,
                    in_place,
                )
                .is_some(),
            ),
            _ => None,
        };
        GapProbeOutcome::Overlaps {
            at_m,
            joined_in_place,
            joint_gap_rad,
        }
    };
    let joined_along_line = (outcome != GapProbeOutcome::PassesP0).then(|| {
        let configurations = |trajectory: &Trajectory| {
            trajectory
                .steps
                .iter()
                .map(|step| step.q)
                .collect::<Vec<_>>()
        };
        motion_along_line(
            robot,
            task,
            &planner.config().rollout.constraints,
            0.0,
            from_m,
            &configurations(forward),
            &configurations(&back),
            in_place,
        )
        .is_some()
    });
    GapProbe {
        from_m,
        back_to_m,
        joined_along_line,
        outcome,
    }
}

/// The configuration of `trajectory` nearest `at_m` along `task`'s line, moved onto `point`
/// ([`project_to_point`]).
fn on_point(
    robot: &Robot,
    task: &Task,
    trajectory: &Trajectory,
    at_m: f64,
    point: &Vec3,
) -> Option<JointVector> {
    let nearest = trajectory.steps.iter().min_by(|a, b| {
        (task.progress(&a.tcp) - at_m)
            .abs()
            .total_cmp(&(task.progress(&b.tcp) - at_m).abs())
    })?;
    project_to_point(robot, &nearest.q, point)
}
