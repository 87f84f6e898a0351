//! `emg import-robot` on a description nobody here wrote: the KUKA LBR iiwa 14 R820 of the
//! `rtb-data` package (PyPI; Peter Corke's Robotics Toolbox data), with binary STL collision
//! meshes behind `package://` paths. Imported, it loads in the planners and in the independent
//! checker and urdfdom's `check_urdf`, plans end to end with the classical controller, passes
//! `emg check`, is drawn by the viewer, comes with the SRDF of its self-collision rule, and the learned controllers refuse it naming the missing model and how to train one.
//!
//! The package is found at `$EMG_RTB_DATA` (the unpacked wheel's `rtbdata` directory; `.ci/run`
//! downloads it). Without it the test prints a notice and passes, unless `EMG_REQUIRE_RTB_DATA=1`.

mod common;

use std::path::{Path, PathBuf};

use common::{emg, read, read_json, temp_dir, text};

/// The unpacked `rtbdata` directory, if available.
fn rtb_data() -> Option<PathBuf> {
    let dir = std::env::var_os("EMG_RTB_DATA").map(PathBuf::from);
    match dir.filter(|d| d.join("xacro/kuka_description").is_dir()) {
        Some(dir) => Some(dir),
        None if std::env::var_os("EMG_REQUIRE_RTB_DATA").is_some_and(|v| v == "1") => panic!(
            "EMG_REQUIRE_RTB_DATA=1 but EMG_RTB_DATA does not name the unpacked rtb-data package \
             (its rtbdata directory)"
        ),
        None => {
            eprintln!(
                "notice: skipping the third-party import test: set EMG_RTB_DATA to the rtbdata \
                 directory of the rtb-data wheel (pip download rtb-data)"
            );
            None
        }
    }
}

/// MoveIt joint limits for the vendor file's joint names: the shipped iiwa's, renamed.
fn limits_for_vendor_joints(dir: &Path) -> PathBuf {
    let shipped = read(&common::data_dir().join("robots/iiwa14_pen.joint_limits.yaml"));
    let renamed = (1..=7).fold(shipped, |text, k| {
        text.replace(&format!("iiwa_joint_{k}:"), &format!("joint_a{k}:"))
    });
    let path = dir.join("iiwa.joint_limits.yaml");
    std::fs::write(&path, renamed).unwrap();
    path
}

#[test]
fn a_vendor_description_with_meshes_plans_end_to_end() {
    let Some(rtb) = rtb_data() else { return };
    let tmp = temp_dir("import");
    let dir = tmp.path();
    let kuka = rtb.join("xacro/kuka_description/kuka_lbr_iiwa");
    let vendor = kuka.join("urdf/lbr_iiwa_14_r820.urdf");
    let robot = dir.join("iiwa.urdf");
    let package = format!("kuka_lbr_iiwa_support={}", kuka.display());
    let args = [
        "import-robot",
        vendor.to_str().unwrap(),
        "--out",
        robot.to_str().unwrap(),
        "--tool-link",
        "tool0",
    ];
    // Without the package path, the missing mesh is named with where it was looked for.
    let output = emg(&args);
    assert!(!output.status.success());
    let error = text(&output.stderr);
    assert!(
        error.contains("link 'base_link': mesh 'package://kuka_lbr_iiwa_support/"),
        "{error}"
    );
    assert!(error.contains("--package-path"), "{error}");
    let output = emg(&[&args[..], &["--package-path", &package]].concat());
    let report = text(&output.stdout);
    assert!(output.status.success(), "{}", text(&output.stderr));
    for link in ["base_link", "link_1", "link_7"] {
        assert!(report.contains(link), "{report}");
    }
    assert!(report.contains("triangles"), "{report}");
    // The self-collision rule is printed and written beside the URDF, where both loaders read it.
    assert!(
        report.contains("self-collision rule: every two links"),
        "{report}"
    );
    let srdf = read(&robot.with_extension("srdf"));
    assert!(
        srdf.contains(r#"<disable_collisions link1="link_3" link2="link_4" reason="Adjacent"/>"#),
        "{srdf}"
    );
    assert!(!srdf.contains(r#"link1="link_1" link2="link_3""#), "{srdf}");
    // The written file is standard: capsules as capped cylinders; only the visual meshes are
    // left.
    let urdf = read(&robot);
    assert!(
        !urdf.contains("/collision/") && !urdf.contains("<capsule"),
        "{urdf}"
    );
    assert!(urdf.contains("pen_tip"));

    // urdfdom, the parser of ROS and MoveIt, reads it whole (when installed; CI installs it).
    let check_urdf =
        std::env::var_os("EMG_CHECK_URDF").map_or_else(|| "check_urdf".into(), PathBuf::from);
    match std::process::Command::new(&check_urdf).arg(&robot).output() {
        Ok(output) => {
            assert!(
                output.status.success(),
                "check_urdf: {}",
                text(&output.stderr)
            );
            assert!(text(&output.stdout).contains("child(1):  pen_tip"));
        }
        Err(_) => assert!(
            std::env::var("EMG_REQUIRE_URDFDOM").as_deref() != Ok("1"),
            "EMG_REQUIRE_URDFDOM=1 but check_urdf was not found"
        ),
    }
    let limits = limits_for_vendor_joints(dir);
    let stem = dir.join("line");
    let html = dir.join("line.html");
    let plan = [
        "plan",
        "--robot",
        robot.to_str().unwrap(),
        "--base-link",
        "base_link",
        "--tip-link",
        "pen_tip",
        "--controller",
        "classical",
        "--planner",
        "controller",
        "--surface",
        "off",
        "--limits",
        limits.to_str().unwrap(),
        "--html",
        html.to_str().unwrap(),
        "--out",
        stem.to_str().unwrap(),
    ];
    let output = emg(&plan);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let record = read_json(&dir.join("line.json"));
    let length = record["path_length_m"].as_f64().unwrap();
    assert!(length > 0.05, "{}", text(&output.stdout));
    let page = read(&html);
    assert!(
        page.contains(r#""link":"link_4""#),
        "the viewer draws the fitted capsules"
    );
    for file in ["line.json", "line.joint_trajectory.json"] {
        let output = emg(&[
            "check",
            dir.join(file).to_str().unwrap(),
            "--robot",
            robot.to_str().unwrap(),
            "--base-link",
            "base_link",
            "--tip-link",
            "pen_tip",
        ]);
        assert!(output.status.success(), "{file}: {}", text(&output.stderr));
    }
    // The learned controllers need models trained for this arm.
    let hybrid: Vec<&str> = plan
        .iter()
        .map(|a| if *a == "classical" { "hybrid" } else { a })
        .collect();
    let output = emg(&hybrid);
    assert!(!output.status.success());
    let error = text(&output.stderr);
    assert!(error.contains("no policy"), "{error}");
    assert!(error.contains("cargo xtask train-ppo --robot"), "{error}");
}
