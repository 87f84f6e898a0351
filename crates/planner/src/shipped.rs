//! The robots shipped with the workspace, and where the shipped data are found.
//!
//! A library never guesses where the data live: a binary names the data directory (the
//! `data/` next to its workspace, or the `EMG_DATA` directory when that variable is set) and
//! hands it over as a [`DataDir`].

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use std::path::{Path, PathBuf};

/// The directory of the shipped data: `robots/`, and per robot its `tasks/`, `labels/` and
/// `models/` (the FR3's at the top, others' in a sub-directory).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DataDir(PathBuf);

impl DataDir {
    /// The environment variable that, when set, names the data directory.
    pub const ENV: &'static str = "EMG_DATA";

    /// The data directory at `path`.
    pub fn new(path: impl Into<PathBuf>) -> Self {
        Self(path.into())
    }

    /// The directory itself.
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// The robot file `value` selects: a shipped robot's name (`fr3`, `iiwa14`, `ur5e`,
    /// `irb120`, `kr16`) gives its file here, anything else is a path to a robot file.
    pub fn robot_file(&self, value: &str) -> PathBuf {
        ShippedRobot::by_name(value).map_or_else(|| PathBuf::from(value), |r| r.path(self))
    }

    /// Model file `name` (e.g. [`crate::POLICY_WEIGHTS_FILE`]) shipped here for the robot file
    /// `robot`, when that file is one of the shipped robots with trained models
    /// ([`SHIPPED_ROBOTS`]; an [`INDUSTRIAL_ROBOTS`] arm plans by search alone).
    pub fn shipped_model(&self, robot: &Path, name: &str) -> Option<PathBuf> {
        ShippedRobot::by_path(robot, self)
            .filter(|r| r.trained)
            .map(|r| r.data_dir(self).join("models").join(name))
    }
}

/// A robot file shipped in `robots/` of the data directory, with the sub-directory that holds
/// its task sets, labels and models.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShippedRobot {
    /// Selection name (`--robot fr3`).
    pub name: &'static str,
    file: &'static str,
    data_subdir: &'static str,
    /// The vendor's home or ready pose (rad, one value per joint, base to tip): where a job's
    /// program starts and ends unless it is given another home.
    pub home: &'static [f64],
    /// Whether trained models and published results ship for it ([`SHIPPED_ROBOTS`]), else
    /// it plans by search alone ([`INDUSTRIAL_ROBOTS`]).
    pub trained: bool,
}

/// The shipped robots with trained models and published results: the paper's Franka FR3 (whose
/// data keep the top level of the data directory), the KUKA LBR iiwa 14 R820 (`iiwa14/`) and
/// the six-joint Universal Robots UR5e (`ur5e/`), all holding the same pen.
pub const SHIPPED_ROBOTS: [ShippedRobot; 3] = [
    ShippedRobot {
        name: "fr3",
        file: "fr3_pen.urdf",
        data_subdir: "",
        // Franka's "ready" pose: (0, −π/4, 0, −3π/4, 0, π/2, π/4), the start of franka_ros's
        // and franka_ros2's controllers and the `ready` state of the Franka MoveIt configuration.
        home: &[
            0.0,
            -FRAC_PI_4,
            0.0,
            -3.0 * FRAC_PI_4,
            0.0,
            FRAC_PI_2,
            FRAC_PI_4,
        ],
        trained: true,
    },
    ShippedRobot {
        name: "iiwa14",
        file: "iiwa14_pen.urdf",
        data_subdir: "iiwa14",
        // KUKA's home position of the LBR iiwa: every axis at zero, the arm upright (the
        // "candle" pose Sunrise's HOME frame holds by default).
        home: &[0.0; 7],
        trained: true,
    },
    ShippedRobot {
        name: "ur5e",
        file: "ur5e_pen.urdf",
        data_subdir: "ur5e",
        // Universal Robots' default Home position in PolyScope: the arm upright, shoulder lift
        // and wrist 1 at −π/2, every other joint at zero.
        home: &[0.0, -FRAC_PI_2, 0.0, -FRAC_PI_2, 0.0, 0.0],
        trained: true,
    },
];

/// The industrial arms shipped for their controllers' own programs, planned by search alone
/// (no trained models), each holding a straight tool 0.1 m beyond its flange (`cargo xtask
/// import-arms`): the ABB IRB 120-3/0.58 and the KUKA KR 16-2.
pub const INDUSTRIAL_ROBOTS: [ShippedRobot; 2] = [
    ShippedRobot {
        name: "irb120",
        file: "irb120_pen.urdf",
        data_subdir: "irb120",
        // ABB's calibration position: every axis at zero, the upper arm level and the flange
        // facing forward.
        home: &[0.0; 6],
        trained: false,
    },
    ShippedRobot {
        name: "kr16",
        file: "kr16_pen.urdf",
        data_subdir: "kr16",
        // KUKA's HOME position: A2 at −90° (the lower arm upright), A3 at +90° (the forearm
        // level), the others at zero.
        home: &[0.0, -FRAC_PI_2, FRAC_PI_2, 0.0, 0.0, 0.0],
        trained: false,
    },
];

impl ShippedRobot {
    /// Every shipped robot: [`SHIPPED_ROBOTS`], then [`INDUSTRIAL_ROBOTS`].
    pub fn all() -> impl Iterator<Item = Self> {
        SHIPPED_ROBOTS.into_iter().chain(INDUSTRIAL_ROBOTS)
    }

    /// The shipped robot called `name`.
    pub fn by_name(name: &str) -> Option<Self> {
        Self::all().find(|r| r.name == name)
    }

    /// The shipped robot whose file in `data` is `path` (compared after resolving links and
    /// `..`).
    pub fn by_path(path: &Path, data: &DataDir) -> Option<Self> {
        let path = canonical(path);
        Self::all().find(|r| r.path(data) == path)
    }

    /// Its robot file in `data` (canonical when it exists).
    pub fn path(self, data: &DataDir) -> PathBuf {
        canonical(&data.path().join("robots").join(self.file))
    }

    /// The directory of its task sets, labels and models in `data` (`data/` itself or
    /// `data/<name>/`).
    pub fn data_dir(self, data: &DataDir) -> PathBuf {
        canonical(&data.path().join(self.data_subdir))
    }

    /// The sub-directory name of its data and results (empty for the FR3).
    pub fn data_subdir(self) -> &'static str {
        self.data_subdir
    }
}

fn canonical(path: &Path) -> PathBuf {
    path.canonicalize().unwrap_or_else(|_| path.to_path_buf())
}
