//! The far side of a likely-loose bound (`emg_planner::gap_probes`) on a UR5e line of the
//! evaluation set whose plan ends at 0.31 m of a 1.42 m bound: every probe starts between the
//! plan's end and the bound, says where its motion back got to consistently with its outcome,
//! and the motions back that cover the plan's end lie on branches the plan's configuration is
//! not joined to in place, nor the plan to them along the line (the gap the continuity test
//! suspected); only a motion back with a start that does not pass `p0` is asked along the line.

use emg_control::Tracking;
use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_planner::{
    DataDir, GapProbeOutcome, InPlaceConfig, Models, PlanRequest, Planner, PlannerConfig,
    ShippedRobot, gap_probes,
};

/// The line: task 22 of the UR5e's evaluation set.
const TASK: usize = 22;

#[test]
fn a_loose_bounds_motions_back_do_not_join_the_plan() {
    let data = DataDir::new(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data"));
    let arm = ShippedRobot::by_name("ur5e").expect("the UR5e is shipped");
    let robot = Robot::from_chain_file(arm.path(&data)).expect("robot loads");
    let models = Models::shipped(&robot, &arm.data_dir(&data)).expect("shipped models");
    let tasks = read_tasks(&arm.data_dir(&data).join("tasks/eval-v1.tasks"), &robot)
        .expect("the evaluation set loads");
    let mut config = PlannerConfig::default();
    config.rollout.constraints.line_tolerance_m = 0.5e-3;
    config.rollout.tracking = Tracking::Corrected;
    let planner = Planner::new(robot, models, config).expect("valid config");
    let task = &tasks[TASK];
    let plan = planner.plan(task, &PlanRequest::default()).expect("a plan");
    let note = planner.bound_note(task, &plan);
    let end_m = plan.trajectory.path_length_m;
    assert!(
        note.likely_loose,
        "plan {end_m} m of {} m",
        note.reachable_m
    );

    let probes = gap_probes(&planner, task, &plan, &InPlaceConfig::default());
    assert!(!probes.is_empty());
    let (mut not_joined, mut not_joined_along_line) = (0, 0);
    for probe in &probes {
        let asked = !matches!(
            probe.outcome,
            GapProbeOutcome::NoStart | GapProbeOutcome::PassesP0
        );
        assert_eq!(probe.joined_along_line.is_some(), asked, "{probe:?}");
        not_joined_along_line += usize::from(probe.joined_along_line == Some(false));
        assert!(
            probe.from_m > end_m && probe.from_m < note.reachable_m,
            "{probe:?}"
        );
        match probe.outcome {
            GapProbeOutcome::NoStart => assert_eq!(probe.back_to_m, probe.from_m),
            GapProbeOutcome::PassesP0 => assert!(probe.back_to_m <= 0.0, "{probe:?}"),
            GapProbeOutcome::StopsShort => assert!(probe.back_to_m >= end_m, "{probe:?}"),
            GapProbeOutcome::Overlaps {
                at_m,
                joined_in_place,
                ..
            } => {
                assert!(at_m >= probe.back_to_m && at_m <= end_m, "{probe:?}");
                assert!(
                    probe.back_to_m > 0.0 && probe.back_to_m < end_m,
                    "{probe:?}"
                );
                not_joined += usize::from(joined_in_place == Some(false));
            }
        }
    }
    assert!(not_joined > 0 && not_joined_along_line > 0, "{probes:?}");
}
