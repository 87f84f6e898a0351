//! The mirror augmentation is used only for arms that have the symmetry: the FR3 and the iiwa do;
//! the UR5e (its shoulder and wrist offsets run sideways), an arm with a sideways joint offset or
//! asymmetric limits on a mirrored joint do not.

use emg_diffusion::has_mirror_symmetry;
use emg_kinematics::Robot;
use emg_planner::{DataDir, SHIPPED_ROBOTS, ShippedRobot};

fn iiwa_text() -> String {
    let path = ShippedRobot::by_name("iiwa14").unwrap().path(&data());
    std::fs::read_to_string(path).unwrap()
}

#[test]
fn the_seven_joint_shipped_arms_are_mirror_symmetric_the_ur5e_is_not() {
    for shipped in SHIPPED_ROBOTS {
        let robot = Robot::from_chain_file(shipped.path(&data())).unwrap();
        assert_eq!(
            has_mirror_symmetry(&robot),
            shipped.name != "ur5e",
            "{}",
            shipped.name
        );
    }
}

#[test]
fn a_sideways_offset_or_asymmetric_limits_break_the_symmetry() {
    let sideways = iiwa_text().replace(
        "<origin xyz=\"0 0 0.2155\" rpy=\"0 0 0\"/>\n    <axis xyz=\"0 1 0\"/>",
        "<origin xyz=\"0 0.05 0.2155\" rpy=\"0 0 0\"/>\n    <axis xyz=\"0 1 0\"/>",
    );
    assert_ne!(sideways, iiwa_text(), "the edit must apply");
    assert!(!has_mirror_symmetry(
        &Robot::from_chain_str(&sideways).unwrap()
    ));
    let asymmetric = iiwa_text().replacen("lower=\"-2.9670597283903604\"", "lower=\"-2.5\"", 1);
    assert_ne!(asymmetric, iiwa_text());
    assert!(!has_mirror_symmetry(
        &Robot::from_chain_str(&asymmetric).unwrap()
    ));
}

/// The workspace's shipped data directory.
fn data() -> DataDir {
    DataDir::new(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data"))
}
