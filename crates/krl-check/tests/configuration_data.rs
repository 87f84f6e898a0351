//! The writer's Status and Turn (`emg_job::KukaConfiguration`, from the planner's kinematics of
//! the shipped KR 16-2) select, through the reader's own closed form and definition, the very
//! joints they were written for; and the reader's closed form is the shipped description's
//! arm.

use emg_job::KukaConfiguration;
use emg_kinematics::Robot;
use emg_krl_check::{Kr16, Pose, StatusTurn};
use nalgebra::{Rotation3, UnitQuaternion};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The shipped KR 16-2 between `base_link` and `tip`.
fn kr16(tip: &str) -> Robot {
    let file =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/kr16_pen.urdf");
    Robot::from_urdf_file(file, "base_link", tip).expect("the shipped KR 16-2 loads")
}

/// The TCP pose of `robot` at `q`.
fn tcp(robot: &Robot, q: &[f64; 6]) -> Pose {
    let kinematics = robot.forward(&robot.joint_vector(q));
    Pose {
        position: kinematics.tcp(),
        rotation: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(
            kinematics.tcp_rotation(),
        )),
    }
}

/// Random configurations within the shipped arm's limits, away from the wrist's singularity
/// (where A4 and A6 trade off and no data tell their share).
fn configurations(robot: &Robot, count: usize) -> Vec<[f64; 6]> {
    let limits = robot.limits();
    let mut rng = ChaCha8Rng::seed_from_u64(80);
    let mut out = Vec::with_capacity(count);
    while out.len() < count {
        let q: [f64; 6] =
            std::array::from_fn(|j| rng.random_range(limits.lower[j]..limits.upper[j]));
        if q[4].abs() >= 1e-3 {
            out.push(q);
        }
    }
    out
}

#[test]
fn the_readers_closed_form_is_the_shipped_arms_flange() {
    let (robot, arm) = (kr16("tool0"), Kr16::default());
    for q in configurations(&robot, 1000) {
        let (shipped, solved) = (tcp(&robot, &q), arm.flange(&q));
        let (distance, angle) = shipped.difference(&solved);
        assert!(
            distance < 1e-9 && angle < 1e-9,
            "{q:?}: {distance} m, {angle} rad"
        );
    }
}

#[test]
fn ten_thousand_configurations_written_are_solved_back_to_their_joints() {
    let robot = kr16("pen_tip");
    let arm = Kr16::default();
    let limits = robot.limits();
    let ranges: Vec<(f64, f64)> = (0..6).map(|j| (limits.lower[j], limits.upper[j])).collect();
    // The tool: the pen's tip 0.1 m out of the flange.
    let tool = Pose {
        position: nalgebra::Vector3::new(0.0, 0.0, 0.1),
        rotation: UnitQuaternion::identity(),
    };
    let mut worst = 0.0_f64;
    for q in configurations(&robot, 10_000) {
        let written = KukaConfiguration::of(&robot, &robot.joint_vector(&q));
        let configuration = StatusTurn {
            status: written.status,
            turn: written.turn,
        };
        assert_eq!(configuration, arm.status_turn(&q), "{q:?}");
        let back = arm
            .solve(
                &tcp(&robot, &q).then(&tool.inverse()),
                configuration,
                &ranges,
            )
            .unwrap_or_else(|n| panic!("{q:?}: {n} solutions hold {configuration:?}"));
        worst = worst.max(emg_program_check::largest_change(&back, &q));
    }
    assert!(worst < 1e-6, "worst joint error {worst} rad");
}
