//! Loading robot files: the shipped FR3 file's structure (joint names, limits), every load error
//! (unreadable file, malformed XML, missing base/tip link, tip not below base, a branching
//! chain, a loop of joints, a prismatic joint, five or eight revolute joints, lower > upper, zero axis, bad
//! velocity, non-finite origins or capsules, unsupported geometry, a cylinder without its sphere
//! caps) with a message naming the offending field or link; a capsule written as a cylinder plus
//! two sphere caps reads back exactly as the `<capsule>` element it stands for; and the load-time axis alignment: joints given with a non-z axis and
//! a compensating origin rotation must give the same FK and collision geometry as the z-axis
//! original.

mod common;

use common::{random_q, rng, robot, robot_text};
use emg_kinematics::{JointVector, Robot, RobotError};

fn load(text: &str) -> Result<Robot, RobotError> {
    Robot::from_urdf_str(text, "link0", "pen_tip")
}

/// Replaces exactly one occurrence of `from` in the shipped file.
fn edited(from: &str, to: &str) -> String {
    let text = robot_text();
    assert_eq!(
        text.matches(from).count(),
        1,
        "edit anchor must be unique: {from}"
    );
    text.replace(from, to)
}

fn error_message(result: Result<Robot, RobotError>) -> (RobotError, String) {
    let error = result.expect_err("the file must be rejected");
    let message = error.to_string();
    (error, message)
}

#[test]
fn shipped_file_has_the_spec_chain_and_limits() {
    let robot = robot();
    assert_eq!(robot.name(), "fr3_pen");
    let names: Vec<String> = (1..=7).map(|i| format!("fr3_joint{i}")).collect();
    assert_eq!(robot.joint_names(), names.as_slice());
    let limits = robot.limits();
    let lower = [-2.7437, -1.7837, -2.9007, -3.0421, -2.8065, 0.5445, -3.0159];
    let upper = [2.7437, 1.7837, 2.9007, -0.1518, 2.8065, 4.5169, 3.0159];
    let velocity = [2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26];
    for i in 0..7 {
        assert_eq!(limits.lower[i], lower[i]);
        assert_eq!(limits.upper[i], upper[i]);
        assert_eq!(limits.velocity[i], velocity[i]);
    }
    assert!((robot.mid_range() - limits.mid()).norm() == 0.0);
    // Every reachable TCP lies in the reach sphere.
    let (centre, radius) = robot.reach_sphere();
    let mut rng = rng(40);
    for _ in 0..1000 {
        let q = random_q(&mut rng, &robot);
        assert!((robot.forward(&q).tcp() - centre).norm() <= radius);
    }
}

#[test]
fn unreadable_file_is_an_io_error_naming_the_path() {
    let (error, message) = error_message(Robot::from_urdf_file(
        "/nonexistent/robot.urdf",
        "link0",
        "pen_tip",
    ));
    assert!(matches!(error, RobotError::Io { .. }), "{error:?}");
    assert!(message.contains("/nonexistent/robot.urdf"), "{message}");
}

#[test]
fn malformed_xml_is_rejected() {
    let text = robot_text();
    let truncated = &text[..text.len() / 2];
    let (error, message) = error_message(load(truncated));
    assert!(matches!(error, RobotError::Malformed(_)), "{error:?}");
    assert!(message.contains("malformed URDF"), "{message}");
    let (error, _) = error_message(load("<robot name=\"x\"><link name=\"a\"></robot>"));
    assert!(matches!(error, RobotError::Malformed(_)), "{error:?}");
}

#[test]
fn missing_base_or_tip_link_is_named() {
    let text = robot_text();
    let (error, message) = error_message(Robot::from_urdf_str(&text, "world_base", "pen_tip"));
    assert!(
        matches!(error, RobotError::MissingLink { role: "base", .. }),
        "{error:?}"
    );
    assert!(
        message.contains("world_base") && message.contains("base"),
        "{message}"
    );
    let (error, message) = error_message(Robot::from_urdf_str(&text, "link0", "marker_tip"));
    assert!(
        matches!(error, RobotError::MissingLink { role: "tip", .. }),
        "{error:?}"
    );
    assert!(
        message.contains("marker_tip") && message.contains("tip"),
        "{message}"
    );
}

#[test]
fn tip_above_base_is_not_a_chain() {
    let (error, message) = error_message(Robot::from_urdf_str(&robot_text(), "link3", "link1"));
    assert!(matches!(error, RobotError::NotAChain { .. }), "{error:?}");
    assert!(
        message.contains("link1") && message.contains("link3"),
        "{message}"
    );
}

#[test]
fn branching_chain_is_rejected() {
    let text = edited(
        "<link name=\"link8\">",
        "<link name=\"camera\"/>\n  <joint name=\"camera_mount\" type=\"fixed\">\n    \
         <parent link=\"link3\"/>\n    <child link=\"camera\"/>\n  </joint>\n  <link name=\"link8\">",
    );
    let (error, message) = error_message(load(&text));
    assert!(
        matches!(error, RobotError::Branching { count: 2, .. }),
        "{error:?}"
    );
    assert!(
        message.contains("link3") && message.contains("camera_mount"),
        "{message}"
    );
}

#[test]
fn prismatic_joint_is_rejected() {
    let text = edited(
        "<joint name=\"fr3_joint4\" type=\"revolute\">",
        "<joint name=\"fr3_joint4\" type=\"prismatic\">",
    );
    let (error, message) = error_message(load(&text));
    assert!(
        matches!(error, RobotError::UnsupportedJoint { .. }),
        "{error:?}"
    );
    assert!(
        message.contains("fr3_joint4") && message.contains("prismatic"),
        "{message}"
    );
}

#[test]
fn continuous_joints_are_revolute_with_a_full_turn_each_way() {
    let text = edited(
        "<joint name=\"fr3_joint7\" type=\"revolute\">",
        "<joint name=\"fr3_joint7\" type=\"continuous\">",
    );
    let continuous = load(&text).expect("a continuous joint loads");
    let shipped = robot();
    let range = emg_kinematics::CONTINUOUS_JOINT_RANGE_RAD;
    assert_eq!(range, std::f64::consts::TAU);
    assert_eq!(
        (continuous.limits().lower[6], continuous.limits().upper[6]),
        (-range, range)
    );
    assert_eq!(
        continuous.limits().velocity[6],
        shipped.limits().velocity[6]
    );
    // Same kinematics, and a joint value past the shipped limit is now within range.
    let mut q = shipped.mid_range();
    q[6] = 4.0;
    assert!((continuous.forward(&q).tcp() - shipped.forward(&q).tcp()).norm() < 1e-15);
    assert!(continuous.limits().first_violation(&q, 0.0).is_none());
    assert!(shipped.limits().first_violation(&q, 0.0).is_some());
}

#[test]
fn five_or_eight_revolute_joints_are_rejected_six_accepted() {
    let text = edited(
        "<joint name=\"fr3_joint7\" type=\"revolute\">",
        "<joint name=\"fr3_joint7\" type=\"fixed\">",
    );
    let six = load(&text).expect("an arm of six joints loads");
    assert_eq!(six.dof(), 6);
    let five = text.replace(
        "<joint name=\"fr3_joint6\" type=\"revolute\">",
        "<joint name=\"fr3_joint6\" type=\"fixed\">",
    );
    let (error, message) = error_message(load(&five));
    assert!(
        matches!(error, RobotError::WrongDof { found: 5, .. }),
        "{error:?}"
    );
    assert!(
        message.contains("5 revolute joints")
            && message.contains("arms of 6 or 7 are supported")
            && message.contains("pen_tip")
            && message.contains("null space"),
        "{message}"
    );
    // The same with a shorter chain of the shipped file.
    let (error, _) = error_message(Robot::from_urdf_str(&robot_text(), "link0", "link5"));
    assert!(
        matches!(error, RobotError::WrongDof { found: 5, .. }),
        "{error:?}"
    );
    let eight = edited(
        "<joint name=\"fr3_flange\" type=\"fixed\">",
        "<joint name=\"fr3_flange\" type=\"revolute\">\n    <axis xyz=\"0 0 1\"/>\n    \
         <limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>",
    );
    let (error, message) = error_message(load(&eight));
    assert!(
        matches!(error, RobotError::WrongDof { found: 8, .. }),
        "{error:?}"
    );
    assert!(message.contains("at most seven"), "{message}");
}

#[test]
fn inverted_limits_are_rejected() {
    let text = edited(
        "lower=\"-1.7837\" upper=\"1.7837\"",
        "lower=\"1.7837\" upper=\"-1.7837\"",
    );
    let (error, message) = error_message(load(&text));
    assert!(
        matches!(error, RobotError::BadJoint { field: "limit", .. }),
        "{error:?}"
    );
    assert!(
        message.contains("fr3_joint2") && message.contains("limit"),
        "{message}"
    );
}

#[test]
fn zero_axis_and_bad_velocity_are_rejected() {
    let text = robot_text().replacen("<axis xyz=\"0 0 1\"/>", "<axis xyz=\"0 0 0\"/>", 1);
    let (error, message) = error_message(load(&text));
    assert!(
        matches!(error, RobotError::BadJoint { field: "axis", .. }),
        "{error:?}"
    );
    assert!(
        message.contains("fr3_joint1") && message.contains("axis"),
        "{message}"
    );
    let text = edited(
        "effort=\"87\" velocity=\"4.18\"",
        "effort=\"87\" velocity=\"0\"",
    );
    let (error, message) = error_message(load(&text));
    assert!(
        matches!(
            error,
            RobotError::BadJoint {
                field: "velocity",
                ..
            }
        ),
        "{error:?}"
    );
    assert!(
        message.contains("fr3_joint6") && message.contains("velocity"),
        "{message}"
    );
}

#[test]
fn box_geometry_is_rejected() {
    let text = edited(
        "<geometry><cylinder radius=\"0.05\" length=\"0.08\"/></geometry>",
        "<geometry><box size=\"0.1 0.1 0.1\"/></geometry>",
    );
    let (error, message) = error_message(load(&text));
    assert!(
        matches!(error, RobotError::UnsupportedGeometry { kind: "box", .. }),
        "{error:?}"
    );
    assert!(
        message.contains("link6") && message.contains("box"),
        "{message}"
    );
}

/// Largest difference between two robots' TCP pose, Jacobian, joint axes and capsule world
/// geometry, the second evaluated at `map_q(q)` (a sign flip per joint).
fn kinematics_difference(
    reference: &Robot,
    other: &Robot,
    map_q: impl Fn(&JointVector) -> JointVector,
) -> f64 {
    let mut rng = rng(41);
    let mut worst = 0.0f64;
    // A joint whose value is negated also has its axis (and Jacobian column) negated.
    let signs = map_q(&JointVector::from_element(1.0));
    assert_eq!(reference.capsules().len(), other.capsules().len());
    assert_eq!(reference.collision_pairs(), other.collision_pairs());
    for _ in 0..500 {
        let q = random_q(&mut rng, reference);
        let (a, b) = (reference.forward(&q), other.forward(&map_q(&q)));
        worst = worst
            .max((a.tcp() - b.tcp()).norm())
            .max((a.tcp_rotation() - b.tcp_rotation()).amax())
            .max((a.jacobian() - b.jacobian() * nalgebra::Matrix::from_diagonal(&signs)).amax());
        for i in 0..7 {
            worst = worst.max((a.joint_axis(i) - b.joint_axis(i) * signs[i]).norm());
        }
        for (ca, cb) in reference.capsules().iter().zip(other.capsules()) {
            let ends_a = [
                a.segment_point(ca.segment, &ca.start),
                a.segment_point(ca.segment, &ca.end),
            ];
            let ends_b = [
                b.segment_point(cb.segment, &cb.start),
                b.segment_point(cb.segment, &cb.end),
            ];
            let same = (ends_a[0] - ends_b[0])
                .norm()
                .max((ends_a[1] - ends_b[1]).norm());
            let swapped = (ends_a[0] - ends_b[1])
                .norm()
                .max((ends_a[1] - ends_b[0]).norm());
            worst = worst.max(same.min(swapped));
        }
    }
    worst
}

#[test]
fn non_z_joint_axis_is_aligned_at_load_time() {
    // Joint 1 about the local y axis of an origin turned +π/2 about x (which takes y onto z): the
    // same joint. Its child frame is then turned by Rx(π/2), so joint 2's origin and link1's
    // capsule (with its caps) are expressed in that turned frame: Rx(−π/2)·(old pose).
    let text = edited(
        "<origin xyz=\"0 0 0.333\" rpy=\"0 0 0\"/>\n    <axis xyz=\"0 0 1\"/>",
        "<origin xyz=\"0 0 0.333\" rpy=\"1.5707963267948966 0 0\"/>\n    <axis xyz=\"0 1 0\"/>",
    );
    let text = text.replacen(
        "<origin xyz=\"0 0 0\" rpy=\"-1.5707963267948966 0 0\"/>\n    <axis xyz=\"0 0 1\"/>",
        "<origin xyz=\"0 0 0\" rpy=\"-3.141592653589793 0 0\"/>\n    <axis xyz=\"0 0 1\"/>",
        1,
    );
    let text = text.replacen(
        "<origin xyz=\"0 0 -0.1915\" rpy=\"0 0 0\"/>",
        "<origin xyz=\"0 -0.1915 0\" rpy=\"-1.5707963267948966 0 0\"/>",
        1,
    );
    // ... and so are its two sphere caps.
    let text = text
        .replacen(
            "<origin xyz=\"0 0 -0.333\" rpy=\"0 0 0\"/>",
            "<origin xyz=\"0 -0.333 0\" rpy=\"0 0 0\"/>",
            1,
        )
        .replacen(
            "<origin xyz=\"0 0 -0.05\" rpy=\"0 0 0\"/>",
            "<origin xyz=\"0 -0.05 0\" rpy=\"0 0 0\"/>",
            1,
        );
    assert_ne!(text, robot_text());
    let reference = robot();
    let rotated = load(&text).expect("equivalent robot file loads");
    let worst = kinematics_difference(&reference, &rotated, |q| *q);
    println!("axis '0 1 0' with compensating origin: worst difference {worst:.3e}");
    assert!(worst < 1e-9, "FK differs by {worst:e}");
}

#[test]
fn negative_and_unnormalised_axes_are_aligned_at_load_time() {
    // Joint 3 about -z is joint 3 about +z with q₃ negated (its limits are symmetric); joint 5
    // about (0, 0, 2.5) is the same as about +z.
    let text = robot_text();
    let anchor3 =
        "<origin xyz=\"0 -0.316 0\" rpy=\"1.5707963267948966 0 0\"/>\n    <axis xyz=\"0 0 1\"/>";
    let anchor5 = "<origin xyz=\"-0.0825 0.384 0\" rpy=\"-1.5707963267948966 0 0\"/>\n    <axis xyz=\"0 0 1\"/>";
    assert_eq!(text.matches(anchor3).count(), 1);
    assert_eq!(text.matches(anchor5).count(), 1);
    let text = text
        .replace(
            anchor3,
            &anchor3.replace("<axis xyz=\"0 0 1\"/>", "<axis xyz=\"0 0 -1\"/>"),
        )
        .replace(
            anchor5,
            &anchor5.replace("<axis xyz=\"0 0 1\"/>", "<axis xyz=\"0 0 2.5\"/>"),
        );
    let reference = robot();
    let flipped = load(&text).expect("equivalent robot file loads");
    let worst = kinematics_difference(&reference, &flipped, |q| {
        let mut q = *q;
        q[2] = -q[2];
        q
    });
    println!("axis '0 0 -1' / '0 0 2.5': worst difference {worst:.3e}");
    assert!(worst < 1e-9, "FK differs by {worst:e}");
}

#[test]
fn non_finite_origins_and_capsules_are_rejected() {
    let text = edited("<origin xyz=\"0 0 0.333\"", "<origin xyz=\"inf 0 0.333\"");
    let (error, message) = error_message(load(&text));
    assert!(
        matches!(
            error,
            RobotError::BadJoint {
                field: "origin",
                ..
            }
        ),
        "{error:?}"
    );
    assert!(message.contains("fr3_joint1"), "{message}");
    let text = edited(
        "<geometry><cylinder radius=\"0.05\" length=\"0.08\"/></geometry>",
        "<geometry><cylinder radius=\"NaN\" length=\"0.08\"/></geometry>",
    );
    let (error, message) = error_message(load(&text));
    assert!(
        matches!(
            error,
            RobotError::BadGeometry {
                field: "radius",
                ..
            }
        ),
        "{error:?}"
    );
    assert!(message.contains("link6"), "{message}");
}

#[test]
fn a_loop_of_joints_is_not_a_chain() {
    // link1's joint names link2 as its parent, and link2's names link1: walking up from the tip
    // never reaches the base.
    let text = edited(
        "<parent link=\"link0\"/>\n    <child link=\"link1\"/>",
        "<parent link=\"link2\"/>\n    <child link=\"link1\"/>",
    );
    let (error, _) = error_message(load(&text));
    assert!(matches!(error, RobotError::NotAChain { .. }), "{error:?}");
}

/// link6 of the shipped file: one capsule written as a cylinder plus a sphere cap on each end.
const LINK6_CAPSULE: &str = r#"    <collision>
      <origin xyz="0 0 -0.03" rpy="0 0 0"/>
      <geometry><cylinder radius="0.05" length="0.08"/></geometry>
    </collision>
    <collision>
      <origin xyz="0 0 -0.07" rpy="0 0 0"/>
      <geometry><sphere radius="0.05"/></geometry>
    </collision>
    <collision>
      <origin xyz="0 0 0.01" rpy="0 0 0"/>
      <geometry><sphere radius="0.05"/></geometry>
    </collision>
"#;

#[test]
fn capped_cylinder_reads_back_as_the_capsule_it_stands_for() {
    let shipped = robot();
    assert_eq!(
        shipped.capsules().len(),
        13,
        "one capsule per cylinder with its caps"
    );
    let as_capsule = edited(
        LINK6_CAPSULE,
        r#"    <collision>
      <origin xyz="0 0 -0.03" rpy="0 0 0"/>
      <geometry><capsule radius="0.05" length="0.08"/></geometry>
    </collision>
"#,
    );
    let robot = load(&as_capsule).expect("a <capsule> element loads");
    assert_eq!(robot.capsules(), shipped.capsules());
    assert_eq!(robot.collision_pairs(), shipped.collision_pairs());
}

#[test]
fn cylinder_without_both_caps_is_rejected() {
    let one_cap = edited(
        LINK6_CAPSULE,
        &LINK6_CAPSULE.replace(
            r#"<origin xyz="0 0 0.01" rpy="0 0 0"/>"#,
            r#"<origin xyz="0 0 0.02" rpy="0 0 0"/>"#,
        ),
    );
    let (error, message) = error_message(load(&one_cap));
    assert!(
        matches!(error, RobotError::UncappedCylinder { .. }),
        "{error:?}"
    );
    assert!(
        message.contains("link6") && message.contains("sphere"),
        "{message}"
    );
    // A cap of another radius does not close the cylinder either.
    let wrong_radius = edited(
        LINK6_CAPSULE,
        &LINK6_CAPSULE.replacen(
            r#"<sphere radius="0.05"/>"#,
            r#"<sphere radius="0.04"/>"#,
            1,
        ),
    );
    let (error, _) = error_message(load(&wrong_radius));
    assert!(
        matches!(error, RobotError::UncappedCylinder { .. }),
        "{error:?}"
    );
}
