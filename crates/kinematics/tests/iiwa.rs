//! The second shipped arm, the KUKA LBR iiwa 14 R820 with the pen (`data/robots/iiwa14_pen.urdf`),
//! against answers derived by hand from its published parameters: base to shoulder 0.36 m,
//! shoulder to elbow 0.42 m, elbow to wrist 0.40 m, wrist to flange 0.126 m, the pen's TCP
//! 0.2034 m beyond the flange, joint axes z, y, z, y, z, y, z. At q = 0 the arm stands straight
//! up; a rotation by θ about y turns the part above that joint from +z towards +x
//! (`(0, 0, 1) ↦ (sin θ, 0, cos θ)`). Also: the chain's ends are found without naming them, and
//! every limit is the published one in radians; a file that is not one chain must name its ends.

use std::f64::consts::FRAC_PI_2;

use emg_kinematics::{JointVector, Robot, Vec3};

const SHOULDER_Z: f64 = 0.36;
const ELBOW_Z: f64 = SHOULDER_Z + 0.42;
const WRIST_Z: f64 = ELBOW_Z + 0.40;
const FLANGE_TO_TCP: f64 = 0.126 + 0.2034;

fn iiwa_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/iiwa14_pen.urdf")
}

fn iiwa() -> Robot {
    Robot::from_chain_file(iiwa_path()).expect("the shipped iiwa file loads")
}

fn q(values: [f64; 7]) -> JointVector {
    JointVector::from_column_slice(&values)
}

fn assert_pose(robot: &Robot, config: [f64; 7], tcp: Vec3, axis: Vec3) {
    let kin = robot.forward(&q(config));
    assert!(
        (kin.tcp() - tcp).norm() < 1e-12,
        "TCP at {config:?}: {} instead of {tcp}",
        kin.tcp()
    );
    assert!(
        (kin.tool_axis() - axis).norm() < 1e-12,
        "tool axis at {config:?}: {} instead of {axis}",
        kin.tool_axis()
    );
}

#[test]
fn stretched_out_pose_points_straight_up() {
    let robot = iiwa();
    let top = WRIST_Z + FLANGE_TO_TCP;
    assert_pose(&robot, [0.0; 7], Vec3::new(0.0, 0.0, top), Vec3::z());
    // Turning joints 1, 3, 5, 7 (all on the vertical axis) leaves the stretched arm where it is.
    assert_pose(
        &robot,
        [0.7, 0.0, -1.1, 0.0, 2.0, 0.0, 3.0],
        Vec3::new(0.0, 0.0, top),
        Vec3::z(),
    );
    assert!((top - 1.5094).abs() < 1e-12);
}

#[test]
fn bending_one_y_joint_swings_the_rest_of_the_arm_towards_x() {
    let robot = iiwa();
    let cases = [
        (1, SHOULDER_Z, 0.42 + 0.40 + FLANGE_TO_TCP),
        (3, ELBOW_Z, 0.40 + FLANGE_TO_TCP),
        (5, WRIST_Z, FLANGE_TO_TCP),
    ];
    for (joint, pivot_z, arm) in cases {
        let mut config = [0.0; 7];
        config[joint] = FRAC_PI_2;
        assert_pose(&robot, config, Vec3::new(arm, 0.0, pivot_z), Vec3::x());
        config[joint] = -0.5;
        let (sin, cos) = libm::sincos(-0.5);
        let swung = Vec3::new(sin, 0.0, cos);
        assert_pose(
            &robot,
            config,
            Vec3::new(0.0, 0.0, pivot_z) + swung * arm,
            swung,
        );
    }
    // Joint 1 then turns the bent arm about the vertical: +x goes to +y.
    assert_pose(
        &robot,
        [FRAC_PI_2, FRAC_PI_2, 0.0, 0.0, 0.0, 0.0, 0.0],
        Vec3::new(0.0, 0.42 + 0.40 + FLANGE_TO_TCP, SHOULDER_Z),
        Vec3::y(),
    );
    // Shoulder and elbow at +90° each: the forearm points down from the elbow at (0.42, 0, 0.36).
    assert_pose(
        &robot,
        [0.0, FRAC_PI_2, 0.0, FRAC_PI_2, 0.0, 0.0, 0.0],
        Vec3::new(0.42, 0.0, SHOULDER_Z - 0.40 - FLANGE_TO_TCP),
        -Vec3::z(),
    );
}

#[test]
fn chain_ends_names_and_published_limits() {
    let robot = iiwa();
    assert_eq!(robot.name(), "iiwa14_pen");
    assert_eq!(robot.base_link(), "iiwa_link_0");
    assert_eq!(robot.tip_link(), "pen_tip");
    let names: Vec<String> = (1..=7).map(|i| format!("iiwa_joint_{i}")).collect();
    assert_eq!(robot.joint_names(), names.as_slice());
    let limits_deg = [170.0, 120.0, 170.0, 120.0, 170.0, 120.0, 175.0];
    let velocity_deg = [85.0, 85.0, 100.0, 75.0, 130.0, 135.0, 135.0];
    let limits = robot.limits();
    for i in 0..7 {
        let limit = f64::to_radians(limits_deg[i]);
        assert!(
            (limits.upper[i] - limit).abs() < 1e-12,
            "upper limit of joint {}",
            i + 1
        );
        assert!(
            (limits.lower[i] + limit).abs() < 1e-12,
            "lower limit of joint {}",
            i + 1
        );
        let velocity = f64::to_radians(velocity_deg[i]);
        assert!(
            (limits.velocity[i] - velocity).abs() < 1e-12,
            "velocity limit of joint {}",
            i + 1
        );
    }
    // Explicit ends give the same robot.
    let named = Robot::from_urdf_file(iiwa_path(), "iiwa_link_0", "pen_tip").unwrap();
    let config = q([0.3, -0.7, 0.2, 1.1, -0.4, 0.9, 0.5]);
    assert_eq!(named.forward(&config).tcp(), robot.forward(&config).tcp());
}

#[test]
fn stretched_and_folded_poses_are_collision_free_and_a_folded_back_wrist_collides() {
    let robot = iiwa();
    assert!(
        robot
            .first_collision(&robot.forward(&q([0.0; 7])), 0.0)
            .is_none()
    );
    let bent = q([0.0, 1.0, 0.0, -1.5, 0.0, 1.2, 0.0]);
    assert!(robot.first_collision(&robot.forward(&bent), 0.0).is_none());
    // Elbow and wrist folded the same way as far as they go: the pen comes back into the upper arm.
    let folded = q([0.0, 0.0, 0.0, 2.09, 0.0, 2.09, 0.0]);
    assert!(
        robot
            .first_collision(&robot.forward(&folded), 0.0)
            .is_some()
    );
}

#[test]
fn a_file_with_a_loose_link_must_name_its_ends() {
    let text = std::fs::read_to_string(iiwa_path())
        .unwrap()
        .replace("</robot>", "<link name=\"table\"/></robot>");
    let message = Robot::from_chain_str(&text).unwrap_err().to_string();
    assert!(
        message.contains("iiwa_link_0") && message.contains("table"),
        "{message}"
    );
    assert!(message.contains("name the base and tip"), "{message}");
    Robot::from_urdf_str(&text, "iiwa_link_0", "pen_tip").expect("named ends still load");
}
