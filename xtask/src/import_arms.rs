//! `cargo xtask import-arms`: the industrial arms shipped for their controllers' own programs,
//! imported from their vendors' descriptions by `emg import-robot`'s library
//! (`emg_io::import_robot`), each checked against its vendor's data sheet before it is written
//! to `data/robots/`:
//!
//! * the ABB IRB 120-3/0.58: ROS-Industrial's `abb_irb120_support` as PyPI's `compas-fab` 2.0.1
//!   ships it (`compas_fab/data/robot_library/abb_irb120_3_58/`);
//! * the KUKA KR 16-2: ROS-Industrial's `kuka_kr16_support` as PyPI's `rtb-data` 2.0.0 ships it
//!   (`rtbdata/xacro/kuka_description/kuka_kr16/`).
//!
//! Each wheel is fetched with pip into target/third-party unless `--compas-fab` or `--rtb-data`
//! names its unpacked directory.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::Context;
use emg_io::{ImportOptions, PackagePath, import_robot};
use emg_kinematics::{PairRule, Robot, Vec3};

use crate::workspace;

/// Options of `import-arms`.
#[derive(clap::Args)]
pub struct Args {
    /// compas_fab's robot library (`.../compas_fab/data/robot_library`); default: fetched from
    /// PyPI into target/third-party.
    #[arg(long, value_name = "DIR")]
    compas_fab: Option<PathBuf>,
    /// rtb-data's package directory (`.../rtbdata`); default: fetched from PyPI into
    /// target/third-party.
    #[arg(long, value_name = "DIR")]
    rtb_data: Option<PathBuf>,
    /// Where the robot files are written.
    #[arg(long, value_name = "DIR", default_value_os_t = workspace::root().join("data/robots"))]
    out: PathBuf,
}

/// A vendor's published figures for one arm: where its axes stand at the zero pose, how far
/// each axis turns and how fast.
pub struct DataSheet {
    /// The product and the document the figures come from.
    pub source: &'static str,
    /// Each axis's origin at the zero pose (m, base frame), from the data sheet's dimensions.
    pub origins_m: [[f64; 3]; 6],
    /// Each axis's working range (degrees).
    pub range_deg: [(f64, f64); 6],
    /// Each axis's top speed (degrees per second).
    pub speed_deg_s: [f64; 6],
}

/// ABB's product specification of the IRB 120 (3HAC035960-001): axis 2 290 mm above the base,
/// the lower arm 270 mm, 70 mm up to the forearm axis, 302 mm to the wrist centre, 72 mm to the
/// flange; its axes' working ranges and maximum speeds.
pub const IRB120_DATA_SHEET: DataSheet = DataSheet {
    source: "ABB IRB 120-3/0.58, product specification 3HAC035960-001 (dimensions, axis working \
             range, axis max speed)",
    origins_m: [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 0.290],
        [0.0, 0.0, 0.560],
        [0.0, 0.0, 0.630],
        [0.302, 0.0, 0.630],
        [0.374, 0.0, 0.630],
    ],
    range_deg: [
        (-165.0, 165.0),
        (-110.0, 110.0),
        (-110.0, 70.0),
        (-160.0, 160.0),
        (-120.0, 120.0),
        (-400.0, 400.0),
    ],
    speed_deg_s: [250.0, 250.0, 250.0, 320.0, 320.0, 420.0],
};

/// KUKA's specification of the KR 16-2 (KR 16 arc HW, KR 16-2: the dimensions of its working
/// envelope figure, axis data): axis 2 675 mm above the floor and 260 mm in front of axis 1, the
/// lower arm 680 mm, the forearm 670 mm long and 35 mm below it, the wrist's three axes meeting
/// at its end; its axes' ranges and speeds.
pub const KR16_DATA_SHEET: DataSheet = DataSheet {
    source: "KUKA KR 16-2, specification (dimensions of the working envelope, axis data: range \
             of motion and speed with rated payload)",
    origins_m: [
        [0.0, 0.0, 0.675],
        [0.260, 0.0, 0.675],
        [0.940, 0.0, 0.675],
        [1.610, 0.0, 0.640],
        [1.610, 0.0, 0.640],
        [1.610, 0.0, 0.640],
    ],
    range_deg: [
        (-185.0, 185.0),
        (-155.0, 35.0),
        (-130.0, 154.0),
        (-350.0, 350.0),
        (-130.0, 130.0),
        (-350.0, 350.0),
    ],
    speed_deg_s: [156.0, 156.0, 156.0, 330.0, 330.0, 615.0],
};

/// The straight tool the shipped industrial arms hold (a dispensing needle, a pen): its length
/// beyond the flange (m) and its radius (m).
pub const TOOL: (f64, f64) = (0.1, 0.005);

/// Where one arm's description comes from and what it is checked against.
pub struct Recipe {
    /// The arm, as its files' headers name it.
    pub product: &'static str,
    /// The shipped files' stem (`irb120_pen`).
    pub stem: &'static str,
    /// The wheel (name, version) and, inside the directory it is unpacked to, the
    /// description's directory.
    pub wheel: (&'static str, &'static str),
    /// The description's directory within the unpacked source.
    pub dir: &'static str,
    /// Within it: the URDF, the package its meshes name and that package's directory, and the
    /// SRDF if there is one.
    pub urdf: &'static str,
    pub package: (&'static str, &'static str),
    pub srdf: Option<&'static str>,
    /// The data sheet.
    pub sheet: &'static DataSheet,
    /// The home, in words.
    pub home: &'static str,
    /// The vendor, as the limits' header names it.
    pub vendor: &'static str,
}

/// The IRB 120 of compas_fab's robot library.
pub const IRB120: Recipe = Recipe {
    product: "ABB IRB 120-3/0.58",
    stem: "irb120_pen",
    wheel: ("compas-fab", "2.0.1"),
    dir: "abb_irb120_3_58",
    urdf: "urdf/robot_description.urdf",
    package: ("abb_irb120_support", "abb_irb120_support"),
    srdf: Some("robot_description_semantic.srdf"),
    sheet: &IRB120_DATA_SHEET,
    home: "ABB's calibration position (every axis at 0)",
    vendor: "ABB",
};

/// The KR 16-2 of rtb-data.
pub const KR16: Recipe = Recipe {
    product: "KUKA KR 16-2",
    stem: "kr16_pen",
    wheel: ("rtb-data", "2.0.0"),
    dir: "xacro/kuka_description/kuka_kr16",
    urdf: "urdf/kr16_2.urdf",
    package: ("kuka_kr16_support", ""),
    srdf: None,
    sheet: &KR16_DATA_SHEET,
    home: "KUKA's HOME position (A2 at −90°, A3 at +90°, the others at 0)",
    vendor: "KUKA",
};

/// The files of one imported arm: each file's name and text.
pub struct ArmFiles {
    pub files: Vec<(String, String)>,
}

/// Imports the arm of `recipe` from `source` (the unpacked directory its `dir` lies in), checks
/// it against its data sheet and returns its files (`<stem>.urdf`, `.srdf`,
/// `.joint_limits.yaml`).
pub fn import(recipe: &Recipe, source: &Path) -> anyhow::Result<ArmFiles> {
    let dir = source.join(recipe.dir);
    let (package, package_dir) = recipe.package;
    let options = ImportOptions {
        package_paths: vec![PackagePath::Named {
            name: package.to_string(),
            dir: dir.join(package_dir),
        }],
        srdf: recipe.srdf.map(|srdf| dir.join(srdf)),
        pen_length_m: Some(TOOL.0),
        pen_radius_m: TOOL.1,
        ..ImportOptions::default()
    };
    let urdf_file = dir.join(recipe.urdf);
    let imported = import_robot(&urdf_file, &options)
        .with_context(|| format!("cannot import {}", urdf_file.display()))?;
    let rule = PairRule::AllExcept(
        imported
            .disabled
            .iter()
            .map(|(a, b, _)| (a.clone(), b.clone()))
            .collect(),
    );
    let robot = Robot::from_urdf_str_with_rule(
        &imported.urdf,
        &imported.base_link,
        emg_io::PEN_LINK,
        rule,
    )?;
    check_data_sheet(&robot, recipe.sheet)?;
    let (wheel, version) = recipe.wheel;
    let provenance = format!(
        "{} holding a straight tool {} m long (radius {} m), its TCP on axis 6: the description \
         PyPI's {wheel} {version} ships ({}), imported by `cargo xtask import-arms` (emg \
         import-robot's capsules). Checked against {}: joint origins, ranges and speeds as \
         published; the joint values and frames are the controller's (ROS-Industrial keeps \
         them); the home is {}.",
        recipe.product, TOOL.0, TOOL.1, recipe.dir, recipe.sheet.source, recipe.home
    );
    let header = format!(
        "Joint limits of the {} ({}.urdf), in MoveIt's joint_limits.yaml layout.\n\
         max_velocity: {}.\nmax_acceleration {} rad/s² and max_jerk {} rad/s³: chosen, as {} \
         publishes no axis accelerations or jerks (its controller's motion model limits them \
         from the load).",
        recipe.product,
        recipe.stem,
        recipe.sheet.source,
        emg_timing::ASSUMED_ACCELERATION_RAD_S2,
        emg_timing::ASSUMED_JERK_RAD_S3,
        recipe.vendor
    );
    let limits = emg_timing::DynamicLimits::assumed(&robot).to_yaml(&robot, &header);
    Ok(ArmFiles {
        files: vec![
            (
                format!("{}.urdf", recipe.stem),
                format!("<!-- {provenance} -->\n{}", imported.urdf),
            ),
            (format!("{}.srdf", recipe.stem), imported.srdf),
            (format!("{}.joint_limits.yaml", recipe.stem), limits),
        ],
    })
}

/// Refuses a description whose axes stand elsewhere at the zero pose, turn further or less
/// far, or faster or slower, than `sheet` publishes (to 0.1 mm, 0.01°, 0.01°/s).
pub fn check_data_sheet(robot: &Robot, sheet: &DataSheet) -> anyhow::Result<()> {
    let kinematics = robot.forward(&robot.joint_vector(&[0.0; 6]));
    for (j, published) in sheet.origins_m.iter().enumerate() {
        let found = kinematics.joint_origin(j);
        anyhow::ensure!(
            (found - Vec3::from(*published)).norm() < 1e-4,
            "axis {} stands at {:?} m at the zero pose, the data sheet's {published:?} m ({})",
            j + 1,
            found.as_slice(),
            sheet.source
        );
    }
    let limits = robot.limits();
    for j in 0..6 {
        let (lower, upper) = sheet.range_deg[j];
        let found = (limits.lower[j].to_degrees(), limits.upper[j].to_degrees());
        anyhow::ensure!(
            (found.0 - lower).abs() < 0.01 && (found.1 - upper).abs() < 0.01,
            "axis {} turns {found:?}°, the data sheet's ({lower}, {upper})° ({})",
            j + 1,
            sheet.source
        );
    }
    let velocities = emg_timing::DynamicLimits::assumed(robot).velocity;
    for (j, published) in sheet.speed_deg_s.iter().enumerate() {
        let found = velocities[j].to_degrees();
        anyhow::ensure!(
            (found - published).abs() < 0.01,
            "axis {} runs {found}°/s, the data sheet's {published}°/s ({})",
            j + 1,
            sheet.source
        );
    }
    Ok(())
}

/// The wheel `name==version` unpacked into target/third-party unless there already, with
/// `inner` (the part of it used) inside.
fn fetched((name, version): (&str, &str), inner: &str) -> anyhow::Result<PathBuf> {
    let dir = workspace::root().join(format!("target/third-party/{name}-{version}"));
    if !dir.join(inner).exists() {
        std::fs::create_dir_all(&dir)?;
        let status = Command::new("python3")
            .args(["-m", "pip", "download", "--quiet", "--no-deps", "--dest"])
            .arg(&dir)
            .arg(format!("{name}=={version}"))
            .status()
            .context("cannot run python3 -m pip")?;
        anyhow::ensure!(status.success(), "pip download {name}=={version} failed");
        let wheel = std::fs::read_dir(&dir)?
            .filter_map(|entry| entry.ok().map(|e| e.path()))
            .find(|path| path.extension().is_some_and(|ext| ext == "whl"))
            .context("pip downloaded no wheel")?;
        let status = Command::new("python3")
            .args(["-m", "zipfile", "-e"])
            .arg(&wheel)
            .arg(&dir)
            .status()
            .context("cannot run python3 -m zipfile")?;
        anyhow::ensure!(status.success(), "cannot unpack {}", wheel.display());
    }
    Ok(dir)
}

/// Imports every industrial arm and writes its files.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let compas_fab = match &args.compas_fab {
        Some(dir) => dir.clone(),
        None => fetched(IRB120.wheel, "compas_fab")?.join("compas_fab/data/robot_library"),
    };
    let rtb_data = match &args.rtb_data {
        Some(dir) => dir.clone(),
        None => fetched(KR16.wheel, "rtbdata")?.join("rtbdata"),
    };
    std::fs::create_dir_all(&args.out)?;
    for (recipe, source) in [(&IRB120, &compas_fab), (&KR16, &rtb_data)] {
        for (name, text) in import(recipe, source)?.files {
            let path = args.out.join(&name);
            emg_io::write_atomically(&path, text.as_bytes())
                .with_context(|| format!("writing {}", path.display()))?;
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wheel's unpacked directory as `.ci/run` unpacks it (the variable `variable`).
    fn source(variable: &str) -> Option<PathBuf> {
        match std::env::var_os(variable) {
            Some(dir) => Some(PathBuf::from(dir)),
            None => {
                assert!(
                    std::env::var_os("EMG_REQUIRE_THIRD_PARTY_ROBOTS").is_none(),
                    "{variable} is not set"
                );
                None
            }
        }
    }

    #[test]
    #[ignore = "needs compas_fab's robot library and rtb-data (EMG_COMPAS_FAB_DATA, EMG_RTB_DATA; .ci/run downloads them): `cargo test -- --include-ignored` runs it, as .ci/run does"]
    fn the_shipped_industrial_arms_are_imported_again_byte_for_byte() {
        for (recipe, variable) in [(&IRB120, "EMG_COMPAS_FAB_DATA"), (&KR16, "EMG_RTB_DATA")] {
            let Some(dir) = source(variable) else { return };
            for (name, text) in import(recipe, &dir).unwrap().files {
                let shipped = workspace::root().join("data/robots").join(&name);
                assert_eq!(
                    std::fs::read_to_string(&shipped).unwrap(),
                    text,
                    "{name} differs from what `cargo xtask import-arms` writes"
                );
            }
        }
    }

    #[test]
    fn the_shipped_arms_match_their_data_sheets_and_a_longer_arm_is_refused() {
        for recipe in [&IRB120, &KR16] {
            let file = workspace::root()
                .join("data/robots")
                .join(format!("{}.urdf", recipe.stem));
            let robot = Robot::from_chain_file(&file).unwrap();
            check_data_sheet(&robot, recipe.sheet).unwrap();
        }
        let file = workspace::root().join("data/robots/irb120_pen.urdf");
        let text = std::fs::read_to_string(&file)
            .unwrap()
            .replace("xyz=\"0 0 0.27\"", "xyz=\"0 0 0.28\"");
        let longer = Robot::from_chain_str(&text).unwrap();
        let error = check_data_sheet(&longer, &IRB120_DATA_SHEET).unwrap_err();
        assert!(error.to_string().contains("axis 3 stands"), "{error}");
    }
}
