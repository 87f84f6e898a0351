//! Importing a description with every kind of collision geometry: boxes, cylinders, spheres, a
//! binary STL behind `package://` (found through a `package.xml`), an OBJ beside the file, and a
//! link hanging off the chain by a fixed joint. The fitted capsules contain every element; the
//! written URDF keeps the kinematics (the TCP is the tool link's origin moved along its z by the
//! pen), and the planners' loader and the independent checker read the same capsules from it.
//! The self-collision rule (adjacent links, links overlapping at mid-range, a given SRDF's pairs)
//! is written as an SRDF that both loaders follow when it lies beside the robot file. Missing
//! meshes are refused with their names; of several leaf links, REP 199's `flange` is the tool
//! link; a side link on a moving joint is merged with the joint at 0.

use std::path::Path;

use emg_io::{DisabledBecause, ImportOptions, PEN_LINK, PackagePath, ToolLinkChoice, import_robot};
use emg_kinematics::{
    JointVector, PairRule, Robot, Vec3, rotation_from_rpy, segment_distance, srdf_beside,
};
use emg_verify::ReferenceModel;
use rand::{RngExt, SeedableRng};

const HALF_PI: &str = "1.5707963267948966";

/// A 7-DoF description: links `l0`..`l7`, a fixed `flange` after `l7`, and `extra` (a side link
/// of `l7`, joined by `side_joint`), each joint 0.15 m along the previous z, turned by ±90°.
fn description(geometry: &[(&str, &str)], side_joint: &str) -> String {
    let mut text = String::from("<robot name=\"vendor\">\n");
    let names = [
        "l0", "l1", "l2", "l3", "l4", "l5", "l6", "l7", "flange", "extra",
    ];
    for name in names {
        text += &format!("  <link name=\"{name}\">\n");
        for (link, element) in geometry {
            if *link == name {
                text += &format!("    <collision>{element}</collision>\n");
            }
        }
        text += "  </link>\n";
    }
    for k in 1..=7 {
        let sign = if k % 2 == 0 { "" } else { "-" };
        text += &format!(
            "  <joint name=\"j{k}\" type=\"revolute\"><parent link=\"l{}\"/><child link=\"l{k}\"/>\
             <origin xyz=\"0 0 0.15\" rpy=\"{sign}{HALF_PI} 0 0\"/><axis xyz=\"0 0 1\"/>\
             <limit lower=\"-2.8\" upper=\"2.8\" effort=\"1\" velocity=\"2\"/></joint>\n",
            k - 1
        );
    }
    text += "  <joint name=\"to_flange\" type=\"fixed\"><parent link=\"l7\"/><child link=\"flange\"/>\
             <origin xyz=\"0 0 0.1\" rpy=\"0 0 0\"/></joint>\n";
    text += &format!(
        "  <joint name=\"to_extra\" type=\"{side_joint}\"><parent link=\"l7\"/><child link=\"extra\"/>\
         <origin xyz=\"0.05 0 0.02\" rpy=\"0 0.3 0\"/><axis xyz=\"1 0 0\"/>\
         <limit lower=\"0\" upper=\"0.01\" effort=\"1\" velocity=\"1\"/></joint>\n"
    );
    text + "</robot>\n"
}

/// Triangles of a box of half extents `h` centred at `c`, wound outwards.
fn box_mesh(c: Vec3, h: Vec3) -> Vec<[Vec3; 3]> {
    let corner = |i: usize| {
        c + Vec3::new(
            if i & 1 != 0 { h.x } else { -h.x },
            if i & 2 != 0 { h.y } else { -h.y },
            if i & 4 != 0 { h.z } else { -h.z },
        )
    };
    let faces = [
        [0, 1, 3, 2],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 3, 7, 5],
    ];
    let outwards = |[a, b, d]: [Vec3; 3]| {
        if (b - a).cross(&(d - a)).dot(&(a - c)) < 0.0 {
            [a, d, b]
        } else {
            [a, b, d]
        }
    };
    faces
        .iter()
        .flat_map(|f| {
            [
                outwards([corner(f[0]), corner(f[1]), corner(f[2])]),
                outwards([corner(f[0]), corner(f[2]), corner(f[3])]),
            ]
        })
        .collect()
}

fn write_stl(path: &Path, triangles: &[[Vec3; 3]]) {
    let vertex = |p: &Vec3| stl_io::Vector::new([p.x as f32, p.y as f32, p.z as f32]);
    let stl: Vec<stl_io::Triangle> = triangles
        .iter()
        .map(|t| stl_io::Triangle {
            normal: stl_io::Vector::new([0.0, 0.0, 0.0]),
            vertices: [vertex(&t[0]), vertex(&t[1]), vertex(&t[2])],
        })
        .collect();
    let mut file = std::fs::File::create(path).unwrap();
    stl_io::write_stl(&mut file, stl.iter()).unwrap();
}

fn write_obj(path: &Path, triangles: &[[Vec3; 3]]) {
    let mut text = String::new();
    for t in triangles {
        for p in t {
            text += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
    }
    for k in 0..triangles.len() {
        text += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    std::fs::write(path, text).unwrap();
}

/// The geometry of every link, and points each fitted capsule set must contain (link frame).
struct Fixture {
    dir: tempfile::TempDir,
    geometry: Vec<(&'static str, String)>,
    must_contain: Vec<(&'static str, Vec3, f64)>,
}

fn fixture() -> Fixture {
    let dir = tempfile::tempdir().unwrap();
    let package = dir.path().join("src/vendor_support");
    std::fs::create_dir_all(package.join("meshes")).unwrap();
    std::fs::write(
        package.join("package.xml"),
        "<package><name>vendor_description</name></package>",
    )
    .unwrap();
    let stl = box_mesh(Vec3::new(0.0, 0.0, 0.07), Vec3::new(0.04, 0.05, 0.07));
    write_stl(&package.join("meshes/l2.stl"), &stl);
    std::fs::create_dir_all(dir.path().join("urdf/meshes")).unwrap();
    let obj = box_mesh(Vec3::new(0.02, 0.0, 0.05), Vec3::new(0.06, 0.03, 0.05));
    write_obj(&dir.path().join("urdf/meshes/l3.obj"), &obj);
    let mut must_contain: Vec<(&str, Vec3, f64)> = Vec::new();
    for t in &stl {
        must_contain.extend(t.iter().map(|p| ("l2", *p * 1.0, 1e-6)));
    }
    for t in &obj {
        // The OBJ is scaled by 2 along x in the description.
        must_contain.extend(
            t.iter()
                .map(|p| ("l3", Vec3::new(2.0 * p.x, p.y, p.z), 1e-6)),
        );
    }
    // Box corners, cylinder rims, sphere poles, the side link's box in l7's frame.
    for i in 0..8 {
        let s = |bit: usize| if i & (1 << bit) != 0 { 1.0 } else { -1.0 };
        must_contain.push((
            "l0",
            Vec3::new(0.1 * s(0), 0.1 * s(1), 0.05 + 0.05 * s(2)),
            1e-9,
        ));
    }
    for k in 0..16 {
        let a = std::f64::consts::TAU * k as f64 / 16.0;
        for z in [-0.06, 0.06] {
            let (sin, cos) = libm::sincos(a);
            must_contain.push(("l1", Vec3::new(0.04 * cos, 0.04 * sin, z), 1e-9));
        }
    }
    must_contain.push(("l4", Vec3::new(0.0, 0.0, 0.11), 1e-9));
    must_contain.push(("l4", Vec3::new(0.0, 0.05, 0.06), 1e-9));
    let side = nalgebra::Isometry3::from_parts(
        nalgebra::Translation3::new(0.05, 0.0, 0.02),
        nalgebra::UnitQuaternion::from_rotation_matrix(&rotation_from_rpy(0.0, 0.3, 0.0)),
    );
    for i in 0..8 {
        let s = |bit: usize| if i & (1 << bit) != 0 { 0.02 } else { -0.02 };
        let p = side
            .transform_point(&nalgebra::Point3::new(s(0), s(1), s(2)))
            .coords;
        must_contain.push(("l7", p, 1e-9));
    }
    let geometry = vec![
        (
            "l0",
            "<origin xyz=\"0 0 0.05\"/><geometry><box size=\"0.2 0.2 0.1\"/></geometry>".into(),
        ),
        (
            "l1",
            "<geometry><cylinder radius=\"0.04\" length=\"0.12\"/></geometry>".into(),
        ),
        (
            "l2",
            "<geometry><mesh filename=\"package://vendor_description/meshes/l2.stl\"/></geometry>"
                .into(),
        ),
        (
            "l3",
            "<geometry><mesh filename=\"meshes/l3.obj\" scale=\"2 1 1\"/></geometry>".into(),
        ),
        (
            "l4",
            "<origin xyz=\"0 0 0.06\"/><geometry><sphere radius=\"0.05\"/></geometry>".into(),
        ),
        (
            "l5",
            format!(
                "<origin xyz=\"0 0 0.05\" rpy=\"{HALF_PI} 0 0\"/><geometry><cylinder radius=\"0.03\" length=\"0.1\"/></geometry>"
            ),
        ),
        (
            "l6",
            "<geometry><box size=\"0.06 0.06 0.12\"/></geometry>".into(),
        ),
        (
            "l7",
            "<geometry><cylinder radius=\"0.03\" length=\"0.05\"/></geometry>".into(),
        ),
        (
            "extra",
            "<geometry><box size=\"0.04 0.04 0.04\"/></geometry>".into(),
        ),
    ];
    Fixture {
        dir,
        geometry,
        must_contain,
    }
}

impl Fixture {
    fn write(&self, side_joint: &str) -> std::path::PathBuf {
        let geometry: Vec<(&str, &str)> = self
            .geometry
            .iter()
            .map(|(l, g)| (*l, g.as_str()))
            .collect();
        let path = self.dir.path().join("urdf/vendor.urdf");
        std::fs::write(&path, description(&geometry, side_joint)).unwrap();
        path
    }

    fn options(&self) -> ImportOptions {
        ImportOptions {
            package_paths: vec![PackagePath::Search(self.dir.path().join("src"))],
            tool_link: Some("flange".into()),
            ..ImportOptions::default()
        }
    }
}

#[test]
fn every_kind_of_geometry_is_fitted_and_read_back_by_both_loaders() {
    let fixture = fixture();
    let path = fixture.write("fixed");
    let imported = import_robot(&path, &fixture.options()).expect("imports");
    assert_eq!(
        (imported.base_link.as_str(), imported.tool_link.as_str()),
        ("l0", "flange")
    );
    let links: Vec<&str> = imported.fits.iter().map(|f| f.link.as_str()).collect();
    assert_eq!(links, ["l0", "l1", "l2", "l3", "l4", "l5", "l6", "l7"]);
    for (link, point, slack) in &fixture.must_contain {
        let fit = imported.fits.iter().find(|f| f.link == *link).unwrap();
        let inside = fit
            .capsules
            .iter()
            .any(|c| segment_distance(&c.start, &c.end, point, point) <= c.radius + slack);
        assert!(inside, "{link}: {point} outside {:?}", fit.capsules);
    }
    for fit in &imported.fits {
        let ratio = fit.capsule_volume_m3() / fit.source_volume_m3;
        assert!(ratio > 0.99 && ratio < 4.0, "{}: ratio {ratio}", fit.link);
    }
    let l7 = imported.fits.iter().find(|f| f.link == "l7").unwrap();
    assert_eq!(l7.elements.len(), 2, "the side link's box moved onto l7");
    assert!(
        !imported.urdf.contains("extra"),
        "frames off the chain are dropped"
    );

    let robot = Robot::from_urdf_str(&imported.urdf, "l0", PEN_LINK).expect("the planners read it");
    let flange = Robot::from_urdf_str(&imported.urdf, "l0", "flange").unwrap();
    let checker =
        ReferenceModel::from_urdf_str(&imported.urdf, "l0", PEN_LINK).expect("so does the checker");
    // The description's own chain, without geometry and without the side link.
    let bare: String = description(&[], "fixed")
        .lines()
        .filter(|line| !line.contains("to_extra"))
        .map(|line| format!("{line}\n"))
        .collect();
    let source = Robot::from_urdf_str(&bare, "l0", "flange").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    for _ in 0..50 {
        let q = JointVector::from_fn(|_, _| rng.random_range(-2.8..2.8));
        let (tip, tool, original) = (robot.forward(&q), flange.forward(&q), source.forward(&q));
        assert!(
            (tool.tcp() - original.tcp()).norm() < 1e-12,
            "the kinematics are kept"
        );
        let expected = tool.tcp() + tool.tool_axis() * 0.1;
        assert!((tip.tcp() - expected).norm() < 1e-12);
        let (ours, theirs) = (
            robot.min_clearance(&robot.forward(&q)),
            checker.min_clearance(&q),
        );
        let ours = ours.expect("pairs exist").clearance;
        assert!((ours - theirs.0).abs() < 1e-9, "{ours} vs {theirs:?}");
    }
}

#[test]
fn a_link_off_the_chain_by_a_moving_joint_is_merged_at_position_zero() {
    let fixture = fixture();
    let fixed = import_robot(&fixture.write("fixed"), &fixture.options()).unwrap();
    let moving = import_robot(&fixture.write("prismatic"), &fixture.options()).unwrap();
    assert!(fixed.held_joints.is_empty());
    assert_eq!(moving.held_joints, ["to_extra"]);
    assert_eq!(fixed.fits, moving.fits);
}

#[test]
fn the_self_collision_rule_is_written_beside_and_both_loaders_follow_it() {
    let fixture = fixture();
    let path = fixture.write("fixed");
    let srdf_in = fixture.dir.path().join("given.srdf");
    std::fs::write(
        &srdf_in,
        r#"<robot name="vendor"><disable_collisions link1="l0" link2="l6" reason="Never"/></robot>"#,
    )
    .unwrap();
    let options = ImportOptions {
        srdf: Some(srdf_in),
        ..fixture.options()
    };
    let imported = import_robot(&path, &options).unwrap();
    let because = |a: &str, b: &str| {
        imported
            .disabled
            .iter()
            .find(|(x, y, _)| (x == a && y == b) || (x == b && y == a))
            .map(|d| d.2)
    };
    assert_eq!(because("l2", "l3"), Some(DisabledBecause::Adjacent));
    assert_eq!(because("l0", "l6"), Some(DisabledBecause::Given));
    assert_eq!(because("l1", "l5"), None);
    let out = fixture.dir.path().join("imported.urdf");
    std::fs::write(&out, &imported.urdf).unwrap();
    std::fs::write(srdf_beside(&out), &imported.srdf).unwrap();
    let robot = Robot::from_urdf_file(&out, "l0", PEN_LINK).unwrap();
    let PairRule::AllExcept(pairs) = robot.pair_rule() else {
        panic!("the SRDF beside the file sets the rule");
    };
    assert_eq!(pairs.len(), imported.disabled.len());
    let capsules = robot.capsules();
    let expected = (0..capsules.len())
        .flat_map(|i| (i + 1..capsules.len()).map(move |j| (i, j)))
        .filter(|&(i, j)| {
            let (a, b) = (&capsules[i], &capsules[j]);
            a.segment != b.segment && because(&a.link, &b.link).is_none()
        })
        .count();
    assert_eq!(robot.collision_pairs().len(), expected);
    // Pairs two links apart are checked now, as the rule of the shipped robots would not.
    let plain = Robot::from_urdf_str(&imported.urdf, "l0", PEN_LINK).unwrap();
    assert!(robot.collision_pairs().len() > plain.collision_pairs().len());
    let checker = ReferenceModel::from_urdf_file(&out, "l0", PEN_LINK).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
    let mut touching = 0;
    for _ in 0..300 {
        let q = JointVector::from_fn(|_, _| rng.random_range(-2.8..2.8));
        let ours = robot.min_clearance(&robot.forward(&q)).unwrap().clearance;
        let theirs = checker.min_clearance(&q).0;
        // The checker also checks links that never move relative to each other; those keep
        // the clearance they have at mid-range, which the rule leaves positive.
        assert!(theirs <= ours + 1e-9, "{theirs} vs {ours}");
        if ours < 0.0 {
            assert!((ours - theirs).abs() < 1e-9, "{ours} vs {theirs}");
        }
        touching += usize::from(ours < 0.0);
    }
    assert!(touching > 10, "{touching} of 300 configurations collide");
    // A malformed SRDF is named.
    std::fs::write(
        srdf_beside(&out),
        "<robot><disable_collisions link1=\"l0\"/></robot>",
    )
    .unwrap();
    let error = Robot::from_urdf_file(&out, "l0", PEN_LINK)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("imported.srdf") && error.contains("link2"),
        "{error}"
    );
    assert!(ReferenceModel::from_urdf_file(&out, "l0", PEN_LINK).is_err());
}

#[test]
fn what_cannot_be_imported_is_named() {
    let fixture = fixture();
    let path = fixture.write("fixed");
    let no_packages = ImportOptions {
        package_paths: Vec::new(),
        ..fixture.options()
    };
    let error = import_robot(&path, &no_packages).unwrap_err().to_string();
    assert!(
        error.contains("link 'l2': mesh 'package://vendor_description/meshes/l2.stl' not found"),
        "{error}"
    );
    let named = ImportOptions {
        package_paths: vec!["vendor_description=/nowhere".parse().unwrap()],
        ..fixture.options()
    };
    let error = import_robot(&path, &named).unwrap_err().to_string();
    assert!(error.contains("/nowhere/meshes/l2.stl"), "{error}");
    // Of the leaf links [flange, extra], REP 199's flange is the tool link when none is named
    // (a file with neither tool0 nor flange is refused, listing its leaves: the unit tests of
    // robot_import.rs).
    let untold = ImportOptions {
        tool_link: None,
        ..fixture.options()
    };
    let imported = import_robot(&path, &untold).unwrap();
    assert_eq!(imported.tool_link, "flange");
    assert_eq!(
        imported.tool_link_choice,
        ToolLinkChoice::Rep199 {
            leaves: vec!["flange".into(), "extra".into()]
        }
    );
}
