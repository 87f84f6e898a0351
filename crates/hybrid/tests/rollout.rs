//! The hybrid controller in a real rollout: a scripted learned controller drives the arm toward a
//! joint limit, so `ρ` crosses the thresholds; at every step the acting controller is the one the
//! hysteresis rule gives for the recorded `ρ`, hand-overs really happen, and the trajectory passes
//! the independent checker.

use emg_control::{
    ActingController, CheckRollout, ClassicalController, NullAction, NullSpaceController,
    RolloutConfig, StepContext, Task, rollout,
};
use emg_hybrid::{
    BoundaryMeasure, HybridController, HysteresisSwitch, Regime, SwitchConfig, count_switches,
};
use emg_kinematics::{JointVector, Robot, Vec3};
use emg_verify::ReferenceModel;

/// A "learned" controller that pushes the joint nearest its limit further toward it.
#[derive(Clone)]
struct TowardLimit;

impl NullSpaceController for TowardLimit {
    fn reset(&mut self, _: &StepContext<'_>) {}

    fn act(&mut self, step: &StepContext<'_>) -> (NullAction, ActingController) {
        let q = &step.q_normalised;
        let joint = q.iamax();
        let mut xi = JointVector::zeros();
        xi[joint] = 10.0 * q[joint].signum();
        (step.action_from_secondary(&xi), ActingController::Learned)
    }
}

fn fr3_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf")
}

/// From the mid-range configuration along +y made perpendicular to its tool axis.
fn task(robot: &Robot) -> Task {
    let seed = robot.mid_range();
    let kinematics = robot.forward(&seed);
    let n = kinematics.tool_axis();
    let d = (Vec3::y() - n * n.y).normalize();
    Task::new(robot, kinematics.tcp(), d, n, Some(seed)).expect("valid task")
}

#[test]
fn the_acting_controller_follows_the_hysteresis_rule_on_the_recorded_rho() {
    let robot = Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").expect("robot loads");
    let task = task(&robot);
    let config = RolloutConfig::default();
    let thresholds = SwitchConfig {
        tau_enter: 0.3,
        tau_exit: 0.2,
    };
    let mut hybrid = HybridController::new(
        TowardLimit,
        ClassicalController::default(),
        HysteresisSwitch::new(thresholds.clone()).expect("valid thresholds"),
        BoundaryMeasure::JointLimits,
    );
    let seed = task.q0_seed.expect("seeded");
    let trajectory = rollout(&robot, &task, &seed, &mut hybrid, &config);

    let mut replay = HysteresisSwitch::new(thresholds.clone()).expect("valid thresholds");
    replay.start(trajectory.steps[0].rho);
    let mut acted = 0;
    for (k, step) in trajectory.steps.iter().enumerate() {
        let Some(acting) = step.controller else {
            continue;
        };
        let expected = match replay.update(step.rho) {
            Regime::Learned => ActingController::Learned,
            Regime::Classical => ActingController::Classical,
        };
        assert_eq!(acting, expected, "step {k}: ρ = {}", step.rho);
        acted += 1;
    }
    assert!(acted > 10, "the rollout ran {acted} steps");
    let peak = trajectory.steps.iter().map(|s| s.rho).fold(0.0, f64::max);
    assert!(
        peak >= thresholds.tau_enter,
        "the scripted controller drives ρ into the shell (peak {peak})"
    );
    assert!(
        count_switches(&trajectory) >= 1,
        "the classical controller took over at least once"
    );
    assert_eq!(count_switches(&trajectory), replay.switches());

    let checker = ReferenceModel::from_urdf_file(&fr3_path(), "link0", "pen_tip").unwrap();
    checker
        .check(&task, &trajectory, &config.constraints)
        .expect("the hybrid rollout holds every constraint");
}
