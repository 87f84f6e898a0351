//! The line seen from its far end: the task, work surface and scan of the motion back from a
//! point along the line to `p0`, and the forward reference such a motion gives.
//!
//! A motion's joint path is as valid backwards as forwards: every configuration holds the same
//! constraints, and every step the same joint-speed limits. So a motion planned from a point
//! `s_far` along the line back to `p0` and beyond, read backwards, shows a motion from `p0`
//! out to `s_far`. Planned from the far end, the search starts where the arm has the fewest
//! configurations left, and the branch it keeps is one that reaches that far; planned from
//! `p0`, it must guess that branch at the start. The search's far-end stage (`crate::search`)
//! plans such motions (`Planner::motion_back`) from the points gap-eval asks from
//! ([`probe_starts`]) and takes each that passes `p0` read forwards ([`read_forwards`]) and
//! followed from `p0` ([`forward_reference`]); `crate::gap` asks the same motions what lies
//! beyond a plan's end.

use emg_control::{
    ActingController, RolloutConfig, StepRecord, Task, Trajectory, first_violation, tool_angle_deg,
};
use emg_kinematics::{
    JointVector, Plate, PoseTarget, ProjectionConfig, Robot, WorkSurface, project_to_pose,
};

use crate::reach::Reach;
use crate::track::Reference;

/// Grid steps of the scan beyond a plan's end from which the first two motions back start.
const NEAR_PROBES_GRID_STEPS: [f64; 2] = [3.0, 10.0];

/// Where the motions back that ask the line beyond a plan ending `end_m` along it start
/// (m along the line): 3 and 10 grid steps of the scan `reach` past the plan's end, halfway
/// to the bound, and half a grid step before the bound; those not between the plan's end and
/// the bound are left out.
pub(crate) fn probe_starts(end_m: f64, reach: &Reach) -> Vec<f64> {
    let grid_m = reach.grid_m;
    NEAR_PROBES_GRID_STEPS
        .map(|steps| end_m + steps * grid_m)
        .into_iter()
        .chain([
            0.5 * (end_m + reach.reachable_m),
            reach.reachable_m - 0.5 * grid_m,
        ])
        .filter(|&from_m| from_m > end_m && from_m < reach.reachable_m)
        .collect()
}

/// `back`, a motion of the reversed task from `s_far_m` along `task`'s line that got back past
/// `p0`, read forwards as far as its start: its last configuration not yet past `p0`, put on
/// `p0` with its own tool axis (the seed), then its steps in reverse order up to the one before
/// its first, each recorded as the forward task sees it. Each reversed step lasts what the step
/// it reverses lasted, so every joint speed is one the motion back had; the seed's lasts what a
/// rollout's step does ([`RolloutConfig::step_duration_s`]). `None`
/// where `back` does not pass `p0` or its seed is not a valid configuration on `p0`. The
/// configuration `back` started from (`back.steps[0]`) is where the forward motion goes on.
pub(crate) fn read_forwards(
    robot: &Robot,
    task: &Task,
    back: &Trajectory,
    s_far_m: f64,
    config: &RolloutConfig,
) -> Option<(JointVector, Vec<StepRecord>)> {
    if back.path_length_m < s_far_m || back.steps.len() < 2 {
        return None;
    }
    // The last step of the motion back still on `p0`'s side of the line.
    let last = back
        .steps
        .iter()
        .rposition(|step| task.progress(&step.tcp) >= 0.0)?;
    let near_p0 = back.steps[last].q;
    let target = PoseTarget {
        position: task.p0,
        tool_axis: robot.forward(&near_p0).tool_axis(),
        roll_axis: None,
    };
    let (seed, _) = project_to_pose(robot, &near_p0, &target, &ProjectionConfig::default()).ok()?;
    let kinematics = robot.forward(&seed);
    if first_violation(robot, task, &kinematics, &config.constraints).is_some() {
        return None;
    }
    let record = |time_s: f64, q: JointVector| {
        let kinematics = robot.forward(&q);
        StepRecord {
            time_s,
            q,
            tcp: kinematics.tcp(),
            tool_angle_deg: tool_angle_deg(&kinematics.tool_axis(), &task.n),
            rho: robot.limits().limit_proximity(&q),
            controller: Some(ActingController::Search),
        }
    };
    // The step from the seed lasts what a rollout's step at its mean joint velocity lasts.
    let velocity = (back.steps[last].q - seed) / config.dt_s;
    let first_s = config.step_duration_s(&velocity, &robot.limits().velocity);
    let mut time_s = 0.0;
    let mut steps = vec![record(time_s, seed)];
    for k in (1..=last).rev() {
        time_s += if k == last {
            first_s
        } else {
            back.steps[k + 1].time_s - back.steps[k].time_s
        };
        steps.push(record(time_s, back.steps[k].q));
    }
    Some((seed, steps))
}

/// The task of the motion back from `s_far_m` along `task`'s line: it starts at that point and
/// runs along `−d`, with the same normal and no generating configuration. `None` on a path
/// task, or where the point lies out of the robot's reach.
pub(crate) fn reversed_task(robot: &Robot, task: &Task, s_far_m: f64) -> Option<Task> {
    if task.path.is_some() {
        return None;
    }
    Task::new(robot, task.point_at(s_far_m), -task.d, task.n, None).ok()
}

/// The same work surface described from the reversed task's start, `s_far_m` along the line,
/// looking back: a plate reaching `behind_m` before `p0` and `ahead_m` beyond it reaches, from
/// there, `ahead_m − s_far_m` behind and `s_far_m + behind_m` ahead (a negative reach behind
/// when the plate ends before the far point: the solid is the same box). A half-space or no
/// surface looks the same from anywhere on the line.
pub(crate) fn reversed_surface(surface: &WorkSurface, s_far_m: f64) -> WorkSurface {
    match surface {
        WorkSurface::Plate(plate) => WorkSurface::Plate(Plate {
            behind_m: plate.ahead_m - s_far_m,
            ahead_m: s_far_m + plate.behind_m,
            ..*plate
        }),
        other => *other,
    }
}

/// The scan `reach` of the forward task, cut at grid point `far` and read from there back to
/// `p0`: the reversed task's scan up to `p0` (its bound is the distance to `p0`; what lies
/// behind `p0` is not scanned). `None` when the scan holds no configuration at `far`.
pub(crate) fn reversed_reach(reach: &Reach, far: usize) -> Option<Reach> {
    let witnesses: Vec<_> = reach.witnesses.get(..=far)?.iter().rev().copied().collect();
    let s_far_m = far as f64 * reach.grid_m;
    Some(Reach {
        reachable_m: s_far_m,
        scanned_m: s_far_m,
        reachable_p0: true,
        grid_m: reach.grid_m,
        witnesses,
    })
}

/// The forward reference that `backward`, a motion of the reversed task from `s_far_m` along
/// `task`'s line, gives: its configurations in reverse order, at their progress along `task`
/// (a configuration that does not advance on the one before it is left out). `None` unless
/// `backward` got back to `p0`.
pub(crate) fn forward_reference(
    task: &Task,
    backward: &Trajectory,
    s_far_m: f64,
) -> Option<Reference> {
    if backward.path_length_m < s_far_m {
        return None;
    }
    let mut progress_m: Vec<f64> = Vec::with_capacity(backward.steps.len());
    let mut configurations = Vec::with_capacity(backward.steps.len());
    for step in backward.steps.iter().rev() {
        let s = task.progress(&step.tcp);
        if progress_m.last().is_none_or(|&last| s > last) {
            progress_m.push(s);
            configurations.push(step.q);
        }
    }
    Reference::along(progress_m, configurations)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{demo, fr3};
    use emg_kinematics::Vec3;

    #[test]
    fn a_reversed_plate_is_the_same_solid() {
        let (p0, d, n) = (
            Vec3::new(0.5, 0.1, 0.2),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        );
        for s_far_m in [0.3, 1.2, 2.5] {
            let plate = WorkSurface::plate();
            let forward = plate.shape(&p0, &d, &n).expect("a plate");
            let reversed = reversed_surface(&plate, s_far_m)
                .shape(&(p0 + d * s_far_m), &-d, &n)
                .expect("a plate");
            // The same box: every probe point is as far from both.
            for probe in [
                Vec3::new(0.5, -0.2, 0.3),
                Vec3::new(0.6, 1.0, 0.25),
                Vec3::new(0.45, 2.3, 0.1),
                Vec3::new(0.5, 0.9, 0.19),
            ] {
                let a = forward.segment_distance(&probe, &probe);
                let b = reversed.segment_distance(&probe, &probe);
                assert!((a - b).abs() < 1e-12, "{s_far_m}: {a} against {b}");
            }
        }
        assert_eq!(
            reversed_surface(&WorkSurface::HalfSpace, 0.4),
            WorkSurface::HalfSpace
        );
    }

    #[test]
    fn a_motion_back_to_p0_read_backwards_is_a_forward_reference() {
        let robot = fr3();
        let (task, q) = demo(&robot);
        let reversed = reversed_task(&robot, &task, 0.1).expect("a reversed task");
        assert_eq!(reversed.d, -task.d);
        assert!((reversed.p0 - task.point_at(0.1)).norm() < 1e-15);
        // A plain motion of the reversed task: a rollout of the classical controller from a
        // configuration at its start.
        let config = emg_control::RolloutConfig::default();
        let start = emg_kinematics::project_to_pose(
            &robot,
            &q,
            &emg_kinematics::PoseTarget {
                position: reversed.p0,
                tool_axis: reversed.n,
                roll_axis: None,
            },
            &emg_kinematics::ProjectionConfig::default(),
        )
        .expect("a start at the far point")
        .0;
        let mut controller = emg_control::ClassicalController::new(Default::default());
        let backward = emg_control::rollout(&robot, &reversed, &start, &mut controller, &config);
        assert!(backward.path_length_m > 0.1, "{}", backward.path_length_m);
        let reference = forward_reference(&task, &backward, 0.1).expect("back past p0");
        // At the far point it is where the backward motion started.
        let at_far = reference.at(0.1 - 1e-12).expect("covered");
        assert!((at_far - start).amax() < 1e-6, "{at_far} against {start}");
        // At p0 it puts the TCP on p0.
        let at_p0 = robot.forward(&reference.at(0.0).expect("covered")).tcp();
        assert!(
            (at_p0 - task.p0).norm() < 1e-3,
            "{at_p0} against {}",
            task.p0
        );
        // A motion that stops short of p0 gives none.
        assert!(forward_reference(&task, &backward, backward.path_length_m + 0.01).is_none());
    }
}
