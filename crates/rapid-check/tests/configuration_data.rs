//! The writer's configuration data (`emg_job::AbbConfiguration`, from the planner's kinematics of
//! the shipped IRB 120) select, through the reader's own closed form and definition, the very
//! joints they were written for.

use emg_job::AbbConfiguration;
use emg_kinematics::Robot;
use emg_rapid_check::{Irb120, Pose};
use nalgebra::{Rotation3, UnitQuaternion};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The shipped IRB 120.
fn irb120() -> Robot {
    let file =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/irb120_pen.urdf");
    Robot::from_chain_file(file).expect("the shipped IRB 120 loads")
}

#[test]
fn ten_thousand_configurations_written_are_solved_back_to_their_joints() {
    let robot = irb120();
    let arm = Irb120::default();
    let limits = robot.limits();
    let ranges: Vec<(f64, f64)> = (0..6).map(|j| (limits.lower[j], limits.upper[j])).collect();
    // The tool as the module's tooldata gives it: along the flange's z axis.
    let rest = robot.joint_vector(&[0.0; 6]);
    let tool_length = (robot.forward(&rest).tcp() - arm.flange(&[0.0; 6]).position).norm();
    let tool = Pose {
        position: nalgebra::Vector3::new(0.0, 0.0, tool_length),
        rotation: UnitQuaternion::identity(),
    };
    let mut rng = ChaCha8Rng::seed_from_u64(80);
    let (mut solved, mut worst) = (0, 0.0_f64);
    while solved < 10_000 {
        let values: [f64; 6] = std::array::from_fn(|j| rng.random_range(ranges[j].0..ranges[j].1));
        // At the wrist's singularity axes 4 and 6 trade off: no data tell their share.
        if values[4].abs() < 1e-3 {
            continue;
        }
        let q = robot.joint_vector(&values);
        let kinematics = robot.forward(&q);
        let tcp = Pose {
            position: kinematics.tcp(),
            rotation: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(
                kinematics.tcp_rotation(),
            )),
        };
        let written = AbbConfiguration::of(&robot, &q);
        let configuration = [written.cf1, written.cf4, written.cf6, written.cfx];
        let back = arm
            .solve(&tcp.then(&tool.inverse()), configuration, &ranges)
            .unwrap_or_else(|n| panic!("{values:?}: {n} solutions hold {configuration:?}"));
        let error = back
            .iter()
            .zip(&values)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        worst = worst.max(error);
        solved += 1;
    }
    assert!(worst < 1e-6, "worst joint error {worst} rad");
}
