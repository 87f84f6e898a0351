//! `--robot`: a shipped robot by name or any robot file of six or seven joints, its chain ends,
//! and the models shipped for it.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use emg_io::RobotRef;
use emg_kinematics::{Robot, RobotError};
use emg_planner::{DataDir, SHIPPED_ROBOTS, ShippedRobot};
use emg_verify::ReferenceModel;

/// The shipped data: `$EMG_DATA` when set, else the `data/` directory of the workspace this
/// binary was built in while it is there, else the copy compiled into the binary
/// ([`emg_planner::embedded::extracted`]): an installed `emg` plans from anywhere.
pub fn data_dir() -> DataDir {
    static FOUND: std::sync::OnceLock<DataDir> = std::sync::OnceLock::new();
    FOUND
        .get_or_init(|| {
            let checkout = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data");
            match std::env::var_os(DataDir::ENV) {
                Some(dir) if !dir.is_empty() => DataDir::new(dir),
                _ if checkout.join("robots").is_dir() => DataDir::new(checkout),
                _ => emg_planner::embedded::extracted().unwrap_or_else(|error| {
                    eprintln!(
                        "warning: cannot write the shipped robots and models to the cache \
                         directory ({error}); set XDG_CACHE_HOME to a writable directory, or \
                         EMG_DATA to a copy of data/"
                    );
                    DataDir::new(checkout)
                }),
            }
        })
        .clone()
}

/// The FR3's robot file, the default robot.
pub fn default_robot() -> PathBuf {
    SHIPPED_ROBOTS[0].path(&data_dir())
}

/// Parses `--robot`: a shipped robot's name (`fr3`, `iiwa14`, `ur5e`, `irb120`, `kr16`) gives its file,
/// anything else is a path to an existing robot file.
pub fn parse_robot(value: &str) -> Result<PathBuf, String> {
    let names: Vec<_> = ShippedRobot::all().map(|r| r.name).collect();
    let path = data_dir().robot_file(value);
    if value.is_empty() || !path.exists() {
        return Err(format!(
            "no shipped robot is named '{value}' and no file {} exists: give one of the shipped \
             robots ({}) or a robot file (URDF; a vendor description with meshes is imported \
             first with `emg import-robot`)",
            path.display(),
            names.join(", ")
        ));
    }
    Ok(path)
}

/// Loads the robot file: the chain from `base` (default: the file's only root link) to `tip`
/// (default: its only leaf link).
pub fn load_robot(path: &Path, base: Option<&str>, tip: Option<&str>) -> Result<Robot> {
    let robot = Robot::from_file_between(path, base, tip);
    robot.map_err(|error| {
        let hint = match error {
            RobotError::UnsupportedGeometry { .. } | RobotError::UncappedCylinder { .. } => {
                format!(
                    " (a vendor description: fit capsules to it first with `emg import-robot {} \
                 --out robot.urdf`, see docs/robot-import.md)",
                    path.display()
                )
            }
            _ => String::new(),
        };
        anyhow::Error::new(error).context(format!("cannot load robot {}{hint}", path.display()))
    })
}

/// The independent checker's model of the same chain, read again from the file.
pub fn load_checker(path: &Path, robot: &Robot) -> Result<ReferenceModel> {
    ReferenceModel::from_urdf_file(path, robot.base_link(), robot.tip_link())
        .with_context(|| format!("the checker cannot load robot {}", path.display()))
}

/// The shipped robot whose file `robot` is, if it is one.
pub fn shipped(robot: &Path) -> Option<emg_planner::ShippedRobot> {
    emg_planner::ShippedRobot::by_path(robot, &data_dir())
}

/// Whether `robot` is the file of one of the shipped robots whose capsules were written by hand
/// ([`SHIPPED_ROBOTS`]; an industrial arm's were fitted by `emg import-robot`).
pub fn is_shipped(robot: &Path) -> bool {
    let data = data_dir();
    SHIPPED_ROBOTS
        .iter()
        .any(|shipped| shipped.path(&data) == robot)
}

/// How the files written for the robot file `robot` (as given to `--robot`) name it: a shipped
/// robot by name, any other by its path as given, each with its file's digest.
pub fn reference(robot: &Path) -> Result<RobotRef> {
    let reference = match ShippedRobot::by_path(robot, &data_dir()) {
        Some(shipped) => RobotRef::shipped(shipped.name, robot),
        None => RobotRef::file(robot),
    };
    Ok(reference?)
}

/// The robot file that the `robot` field of `file` names: a shipped robot's in the shipped data,
/// another's at its path as given (from the working directory, else from `file`'s directory);
/// refused when that file is not the robot the motion was planned for.
pub fn resolve(field: &str, file: &Path) -> Result<PathBuf> {
    let reference =
        RobotRef::parse(field).with_context(|| format!("cannot read {}", file.display()))?;
    let data = data_dir();
    let shipped = |name: &str| ShippedRobot::by_name(name).map(|robot| robot.path(&data));
    Ok(reference.resolve(shipped, file)?)
}

/// Model file `name` (e.g. `ppo-v1.weights`) shipped for the robot file `robot`, when that file
/// is one of the shipped robots.
pub fn shipped_model(robot: &Path, name: &str) -> Option<PathBuf> {
    data_dir().shipped_model(robot, name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_select_shipped_files_and_paths_pass_through() {
        for robot in SHIPPED_ROBOTS {
            let path = parse_robot(robot.name).unwrap();
            assert_eq!(path, robot.path(&data_dir()));
            assert!(path.exists(), "{}", path.display());
            let model = shipped_model(&path, "ppo-v1.weights").unwrap();
            assert!(model.starts_with(robot.data_dir(&data_dir())));
        }
        let file = SHIPPED_ROBOTS[1].path(&data_dir());
        assert_eq!(parse_robot(file.to_str().unwrap()).unwrap(), file);
        let error = parse_robot("ur5").unwrap_err();
        assert!(
            error.contains("fr3, iiwa14") && error.contains("'ur5'"),
            "{error}"
        );
        assert_eq!(
            shipped_model(Path::new("my/arm.urdf"), "ppo-v1.weights"),
            None
        );
        assert!(parse_robot("").unwrap_err().contains("iiwa14"));
        // An industrial arm is shipped by name, without trained models.
        let irb120 = parse_robot("irb120").unwrap();
        assert!(irb120.ends_with("data/robots/irb120_pen.urdf"));
        assert_eq!(shipped_model(&irb120, "ppo-v1.weights"), None);
    }

    #[test]
    fn chain_ends_are_found_or_named_together() {
        let path = parse_robot("iiwa14").unwrap();
        let found = load_robot(&path, None, None).unwrap();
        assert_eq!(
            (found.base_link(), found.tip_link()),
            ("iiwa_link_0", "pen_tip")
        );
        let tip_only = load_robot(&path, None, Some("iiwa_link_7")).unwrap();
        assert_eq!(
            (tip_only.base_link(), tip_only.tip_link()),
            ("iiwa_link_0", "iiwa_link_7")
        );
    }
}
