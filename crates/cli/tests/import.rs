//! `emg import-robot` on descriptions nobody here wrote, from package registries:
//! - the KUKA LBR iiwa 14 R820 of PyPI's `rtb-data` (Peter Corke's Robotics Toolbox data), binary
//!   STL collision meshes behind `package://` paths (and its COLLADA visual meshes read in their
//!   place fit about the same capsules);
//! - the Franka Emika Panda of PyPI's `pybullet` (`pybullet_data`), OBJ collision meshes behind
//!   `package://meshes/...` read beside the file as pybullet does, fingers on prismatic joints;
//! - the six-joint UFactory xArm 6 of the same package, OBJ collision meshes behind
//!   `package://xarm_description/...`, under a fixed `world` link.
//!
//! Imported, each is read whole by urdfdom's `check_urdf`, comes with the SRDF of its
//! self-collision rule and a joint_limits.yaml, plans more than 10 cm with the default command
//! (`emg plan --robot imported.urdf --out x`, no other flag, no hand-written file), every written
//! file passes `emg check`, it is drawn by the viewer, and the learned controllers refuse it
//! naming the missing model and how to train one.
//!
//! The packages are found at `$EMG_RTB_DATA` (the unpacked wheel's `rtbdata` directory) and
//! `$EMG_PYBULLET_DATA` (its `pybullet_data` directory); `.ci/run` downloads both. Without them a
//! test prints a notice and passes, unless `EMG_REQUIRE_THIRD_PARTY_ROBOTS=1`.

mod common;

use std::path::{Path, PathBuf};

use common::{emg, read, read_json, temp_dir, text};

/// The unpacked package directory `$variable` names, if available (it must hold `inside`).
fn package(variable: &str, inside: &str) -> Option<PathBuf> {
    let dir = std::env::var_os(variable).map(PathBuf::from);
    match dir.filter(|d| d.join(inside).exists()) {
        Some(dir) => Some(dir),
        None if std::env::var("EMG_REQUIRE_THIRD_PARTY_ROBOTS").as_deref() == Ok("1") => {
            panic!("EMG_REQUIRE_THIRD_PARTY_ROBOTS=1 but ${variable} does not hold {inside}")
        }
        None => {
            eprintln!(
                "notice: skipping a third-party import test: set {variable} to the unpacked \
                 package (see .ci/run)"
            );
            None
        }
    }
}

/// One vendor description end to end: import with `import_args`, then plan with the default
/// command, check every written file, and view.
fn end_to_end(vendor: &Path, import_args: &[&str], base: &str, dir: &Path) {
    let robot = dir.join("robot.urdf");
    let output = emg(&[
        &[
            "import-robot",
            vendor.to_str().unwrap(),
            "--out",
            robot.to_str().unwrap(),
        ],
        import_args,
    ]
    .concat());
    let report = text(&output.stdout);
    assert!(output.status.success(), "{}", text(&output.stderr));
    assert!(report.contains("triangles"), "{report}");
    // The self-collision rule is printed and written beside the URDF, where both loaders read it.
    assert!(
        report.contains("self-collision rule: every two links"),
        "{report}"
    );
    let srdf = read(&robot.with_extension("srdf"));
    assert!(srdf.contains(r#"reason="Adjacent"/>"#), "{srdf}");
    // The written file is standard: capsules as capped cylinders, no collision mesh left.
    let urdf = read(&robot);
    assert!(
        !urdf.contains("<capsule") && urdf.contains("pen_tip"),
        "{urdf}"
    );
    let description = urdf_rs::read_from_string(&urdf).unwrap();
    for link in &description.links {
        for collision in &link.collision {
            assert!(
                !matches!(collision.geometry, urdf_rs::Geometry::Mesh { .. }),
                "{}",
                link.name
            );
        }
    }
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
    // The limits file written beside it: the vendor's velocities, assumed acceleration and jerk.
    let limits = read(&dir.join("robot.joint_limits.yaml"));
    assert!(
        limits.contains("ASSUMED") && limits.contains("max_jerk: 300.0"),
        "{limits}"
    );
    // The default command plans it, with no other flag and no hand-written file: the classical
    // controller (no policy is trained for it) said in one line, more than 10 cm of line.
    let stem = dir.join("x");
    let plain = [
        "plan",
        "--robot",
        robot.to_str().unwrap(),
        "--out",
        stem.to_str().unwrap(),
    ];
    let output = emg(&plain);
    let stdout = text(&output.stdout);
    assert!(output.status.success(), "{}", text(&output.stderr));
    assert!(stdout.contains("controller: classical"), "{stdout}");
    assert!(!stdout.contains("assumed acceleration"), "{stdout}");
    let record = read_json(&dir.join("x.json"));
    let length = record["path_length_m"].as_f64().unwrap();
    assert!(length > 0.1, "{stdout}");
    // Every written file passes the checker, told nothing but the file (the CSV takes its task
    // from the JSON beside it).
    for file in ["x.json", "x.csv", "x.joint_trajectory.json"] {
        let output = emg(&["check", dir.join(file).to_str().unwrap()]);
        assert!(output.status.success(), "{file}: {}", text(&output.stderr));
    }
    // The viewer draws the fitted capsules.
    let html = dir.join("line.html");
    let plan = [
        &plain[..],
        &[
            "--base-link",
            base,
            "--tip-link",
            "pen_tip",
            "--controller",
            "classical",
        ],
        &["--html", html.to_str().unwrap()],
    ]
    .concat();
    let output = emg(&plan);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let page = read(&html);
    assert!(
        page.contains(r#""link":"pen_tip""#),
        "the viewer draws the fitted capsules"
    );
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

#[test]
fn rtb_datas_iiwa_with_stl_meshes_plans_end_to_end() {
    let Some(rtb) = package("EMG_RTB_DATA", "xacro/kuka_description") else {
        return;
    };
    let tmp = temp_dir("import-iiwa");
    let dir = tmp.path();
    let kuka = rtb.join("xacro/kuka_description/kuka_lbr_iiwa");
    let vendor = kuka.join("urdf/lbr_iiwa_14_r820.urdf");
    // Without the package's directory, the missing mesh is named with where it was looked for.
    let output = emg(&[
        "import-robot",
        vendor.to_str().unwrap(),
        "--out",
        dir.join("x.urdf").to_str().unwrap(),
        "--tool-link",
        "tool0",
    ]);
    assert!(!output.status.success());
    let error = text(&output.stderr);
    assert!(
        error.contains("link 'base_link': mesh 'package://kuka_lbr_iiwa_support/"),
        "{error}"
    );
    assert!(error.contains("--package-path"), "{error}");
    let package = format!("kuka_lbr_iiwa_support={}", kuka.display());
    end_to_end(
        &vendor,
        &["--tool-link", "tool0", "--package-path", &package],
        "base_link",
        dir,
    );
    // The package's COLLADA visual meshes, read as collision meshes, fit about the same
    // capsules as its STL collision meshes: COLLADA is read in the right unit.
    let dae = dir.join("dae.urdf");
    let swapped = collada_collisions(&read(&vendor));
    std::fs::write(&dae, swapped).unwrap();
    let from_dae = dir.join("from_dae.urdf");
    let output = emg(&[
        "import-robot",
        dae.to_str().unwrap(),
        "--out",
        from_dae.to_str().unwrap(),
        "--tool-link",
        "tool0",
        "--package-path",
        &package,
    ]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    assert!(text(&output.stdout).contains("link_4.dae"));
    let radii = |path: &Path| -> Vec<(String, f64)> {
        let robot = urdf_rs::read_file(path).unwrap();
        robot
            .links
            .iter()
            .filter_map(|l| {
                l.collision.iter().find_map(|c| match c.geometry {
                    urdf_rs::Geometry::Sphere { radius } => Some((l.name.clone(), radius)),
                    _ => None,
                })
            })
            .collect()
    };
    let (stl, dae) = (radii(&dir.join("robot.urdf")), radii(&from_dae));
    assert_eq!(stl.len(), dae.len());
    for ((link, a), (_, b)) in stl.iter().zip(&dae) {
        assert!(
            (a - b).abs() < 0.1 * a,
            "{link}: {a} m from STL, {b} m from COLLADA"
        );
    }
}

/// The description with its collision meshes swapped for the visual COLLADA ones.
fn collada_collisions(text: &str) -> String {
    text.lines()
        .map(|line| {
            if line.contains("/collision/") {
                line.replace("/collision/", "/visual/")
                    .replace(".stl", ".dae")
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn pybullets_six_joint_xarm6_with_obj_meshes_plans_end_to_end() {
    let Some(data) = package("EMG_PYBULLET_DATA", "xarm/xarm6_robot.urdf") else {
        return;
    };
    let tmp = temp_dir("import-xarm6");
    let dir = tmp.path();
    let vendor = data.join("xarm/xarm6_robot.urdf");
    // The chain to the fifth link has five revolute joints: refused, naming the count and why.
    let five = dir.join("five.urdf");
    let output = emg(&[
        "import-robot",
        vendor.to_str().unwrap(),
        "--out",
        five.to_str().unwrap(),
        "--tool-link",
        "link5",
        "--pen-length",
        "0.2",
    ]);
    assert!(!output.status.success());
    let error = text(&output.stderr);
    assert!(
        error.contains("has 5 revolute joints; arms of 6 or 7 are supported")
            && error.contains("null space"),
        "{error}"
    );
    assert!(!five.exists());
    end_to_end(
        &vendor,
        &["--tool-link", "link6", "--pen-length", "0.2"],
        "world",
        dir,
    );
    // Every file names the arm's six joints and holds six values per joint vector.
    let joint = read_json(&dir.join("x.joint_trajectory.json"));
    let names: Vec<&str> = joint["joint_names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        ["joint1", "joint2", "joint3", "joint4", "joint5", "joint6"]
    );
    assert_eq!(joint["points"][0]["positions"].as_array().unwrap().len(), 6);
    let rollout = read_json(&dir.join("x.json"));
    for step in rollout["steps"].as_array().unwrap() {
        assert_eq!(step["q"].as_array().unwrap().len(), 6);
    }
    let csv = read(&dir.join("x.csv"));
    assert!(
        csv.starts_with("time_s,q1,q2,q3,q4,q5,q6,qd1,qd2,qd3,qd4,qd5,qd6,tcp_x"),
        "{}",
        csv.lines().next().unwrap_or_default()
    );
}

#[test]
fn pybullets_panda_with_obj_meshes_and_fingers_plans_end_to_end() {
    let Some(data) = package("EMG_PYBULLET_DATA", "franka_panda/panda.urdf") else {
        return;
    };
    let tmp = temp_dir("import-panda");
    let dir = tmp.path();
    let vendor = data.join("franka_panda/panda.urdf");
    // Planning with the vendor file itself says how to import it.
    let output = emg(&[
        "plan",
        "--robot",
        vendor.to_str().unwrap(),
        "--base-link",
        "panda_link0",
        "--tip-link",
        "panda_hand",
    ]);
    assert!(!output.status.success());
    let error = text(&output.stderr);
    assert!(
        error.contains("mesh is not supported") && error.contains("emg import-robot"),
        "{error}"
    );
    // A chain through a finger holds a prismatic joint: refused, naming it.
    let output = emg(&[
        "import-robot",
        vendor.to_str().unwrap(),
        "--out",
        dir.join("finger.urdf").to_str().unwrap(),
        "--tool-link",
        "panda_leftfinger",
    ]);
    assert!(!output.status.success());
    let error = text(&output.stderr);
    assert!(
        error.contains("joint 'panda_finger_joint1' is prismatic"),
        "{error}"
    );
    end_to_end(
        &vendor,
        &["--tool-link", "panda_hand", "--pen-length", "0.2"],
        "panda_link0",
        dir,
    );
}
