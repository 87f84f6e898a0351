//! The checker's own reading of robot files: the chain's joint count, and `continuous` joints
//! read with the documented range of a full turn each way.

use emg_verify::{Joints, ModelError, ReferenceModel};

fn fr3_text() -> String {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
    std::fs::read_to_string(path).expect("the shipped robot file reads")
}

#[test]
fn a_continuous_joint_has_a_full_turn_each_way() {
    let text = fr3_text().replace(
        "<joint name=\"fr3_joint7\" type=\"revolute\">",
        "<joint name=\"fr3_joint7\" type=\"continuous\">",
    );
    let continuous = ReferenceModel::from_urdf_str(&text, "link0", "pen_tip").unwrap();
    let shipped = ReferenceModel::from_urdf_str(&fr3_text(), "link0", "pen_tip").unwrap();
    let tau = std::f64::consts::TAU;
    assert_eq!(continuous.limits()[6], (-tau, tau));
    assert_eq!(continuous.limits()[..6], shipped.limits()[..6]);
    assert_eq!(continuous.velocity_limits(), shipped.velocity_limits());
    let q = Joints::from_column_slice(&[0.1, -0.4, 0.2, -2.0, 0.1, 1.7, 4.0]);
    assert_eq!(continuous.tcp_pose(&q), shipped.tcp_pose(&q));
}

#[test]
fn a_chain_without_six_or_seven_revolute_joints_is_refused() {
    let text = fr3_text()
        .replace(
            "<joint name=\"fr3_joint7\" type=\"revolute\">",
            "<joint name=\"fr3_joint7\" type=\"fixed\">",
        )
        .replace(
            "<joint name=\"fr3_joint6\" type=\"revolute\">",
            "<joint name=\"fr3_joint6\" type=\"fixed\">",
        );
    let error = ReferenceModel::from_urdf_str(&text, "link0", "pen_tip")
        .err()
        .expect("five revolute joints are refused");
    assert!(matches!(error, ModelError::JointCount(5)), "{error}");
    assert!(error.to_string().contains("expected 6 or 7"), "{error}");
}

#[test]
fn a_loop_of_joints_and_unusable_numbers_are_refused() {
    let looped = fr3_text().replacen(
        "<parent link=\"link0\"/>\n    <child link=\"link1\"/>",
        "<parent link=\"link2\"/>\n    <child link=\"link1\"/>",
        1,
    );
    let result = ReferenceModel::from_urdf_str(&looped, "link0", "pen_tip");
    assert!(
        matches!(result, Err(ModelError::Loop(_))),
        "a loop must be refused"
    );
    for (from, to, named) in [
        (
            "xyz=\"0 0 0.333\"",
            "xyz=\"inf 0 0.333\"",
            "joint 'fr3_joint1' origin",
        ),
        (
            "<axis xyz=\"0 0 1\"/>",
            "<axis xyz=\"0 0 0\"/>",
            "joint 'fr3_joint1' axis",
        ),
        ("radius=\"0.06\"", "radius=\"NaN\"", "collision"),
    ] {
        let text = fr3_text().replacen(from, to, 1);
        assert_ne!(text, fr3_text(), "anchor {from} not found");
        match ReferenceModel::from_urdf_str(&text, "link0", "pen_tip") {
            Err(error @ ModelError::Value { .. }) => {
                assert!(error.to_string().contains(named), "{error}");
            }
            Err(other) => panic!("{to}: refused for another reason: {other}"),
            Ok(_) => panic!("{to}: accepted"),
        }
    }
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
fn a_capped_cylinder_is_the_capsule_it_stands_for_and_an_uncapped_one_is_refused() {
    let shipped_text = fr3_text();
    assert_eq!(shipped_text.matches(LINK6_CAPSULE).count(), 1);
    let as_capsule = shipped_text.replace(
        LINK6_CAPSULE,
        r#"    <collision>
      <origin xyz="0 0 -0.03" rpy="0 0 0"/>
      <geometry><capsule radius="0.05" length="0.08"/></geometry>
    </collision>
"#,
    );
    let shipped = ReferenceModel::from_urdf_str(&shipped_text, "link0", "pen_tip").unwrap();
    let capsule = ReferenceModel::from_urdf_str(&as_capsule, "link0", "pen_tip").unwrap();
    for k in 0..200 {
        let t = f64::from(k) * 0.05;
        let q = Joints::from_fn(|i, _| libm::sin(t * (1.0 + i as f64)) * 1.5);
        assert_eq!(shipped.min_clearance(&q), capsule.min_clearance(&q));
    }
    let uncapped = shipped_text.replace(
        LINK6_CAPSULE,
        &LINK6_CAPSULE.replace(r#"xyz="0 0 0.01""#, r#"xyz="0 0 0.02""#),
    );
    let error = ReferenceModel::from_urdf_str(&uncapped, "link0", "pen_tip")
        .err()
        .expect("a cylinder with one cap is refused");
    assert!(
        matches!(error, ModelError::UncappedCylinder(ref link) if link == "link6"),
        "{error}"
    );
}
