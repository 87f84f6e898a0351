//! A joint trajectory (`emg-joint-trajectory/2`) exported for a robot's own stack
//! (`docs/robot-export.md`):
//!
//! * [`ExportFormat::Ros2Mcap`]: one `trajectory_msgs/msg/JointTrajectory` message in an MCAP
//!   file (`ros2 bag play`), joint names as the vendor's ROS 2 driver names them
//!   ([`DriverProfile`]), its points thinned so that the controller's quintic spline through them
//!   stays within a tolerance of every sample ([`ThinningReport`]);
//! * [`ExportFormat::UrScript`]: a URScript program for a six-joint Universal Robots arm on an
//!   e-Series controller, `movej` to the start, then a `servoj` target every 2 ms.
//!
//! A job's program is also written as a controller's own program ([`ExportFormat::Rapid`],
//! [`ExportFormat::Krl`], and URScript's native form) by `emg_job`, from its targets rather than
//! its samples.

mod drivers;
mod ros2_mcap;
mod thinning;
mod tool;
mod urscript;

use std::collections::BTreeMap;
use std::ffi::OsString;
use std::path::{Path, PathBuf};

use emg_kinematics::Robot;

pub use drivers::{DRIVER_PROFILES, DriverProfile, UR_JOINT_NAMES, is_universal_robots_arm};
pub use ros2_mcap::{JOINT_TRAJECTORY_TYPE, TOOL_OUTPUT_TOPIC, TOOL_OUTPUT_TYPE};
pub use thinning::ThinningReport;
pub use tool::{ToolSwitch, ToolSwitching};
pub use urscript::{home_check, joint_list};

use thinning::{DEFAULT_TOLERANCE_RAD, SplineLimits, measure, thin};
use urscript::{
    DEFAULT_MAX_SERVOJ_LINES, GAIN, LOOKAHEAD_TIME_S, MOVEJ_ACCELERATION_RAD_S2, MOVEJ_SPEED_RAD_S,
    SERVO_PERIOD_S, START_TOLERANCE_RAD, resample,
};

use crate::joint_trajectory::{JointTrajectory, JointTrajectoryPoint, TimingLimits};
use crate::paths::OutputClash;

/// What a joint trajectory is exported as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExportFormat {
    /// `ros2-mcap`: a ROS 2 `trajectory_msgs/msg/JointTrajectory` in an MCAP file.
    Ros2Mcap,
    /// `urscript`: a URScript program for a Universal Robots e-Series controller.
    UrScript,
    /// `rapid`: a RAPID module for an ABB controller, written from a job's program only
    /// (`emg_job::rapid_program`).
    Rapid,
    /// `krl`: a KRL program (`.src` and `.dat`) for a KUKA controller, written from a job's
    /// program only (`emg_job::krl_program`).
    Krl,
}

impl ExportFormat {
    /// Every format, by name.
    pub const ALL: [ExportFormat; 4] = [
        ExportFormat::Ros2Mcap,
        ExportFormat::UrScript,
        ExportFormat::Rapid,
        ExportFormat::Krl,
    ];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ExportFormat::Ros2Mcap => "ros2-mcap",
            ExportFormat::UrScript => "urscript",
            ExportFormat::Rapid => "rapid",
            ExportFormat::Krl => "krl",
        }
    }

    /// The file extension of its output.
    pub fn extension(self) -> &'static str {
        match self {
            ExportFormat::Ros2Mcap => "mcap",
            ExportFormat::UrScript => "script",
            ExportFormat::Rapid => "mod",
            ExportFormat::Krl => "src",
        }
    }
}

impl std::fmt::Display for ExportFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ExportFormat {
    type Err = ExportError;

    fn from_str(s: &str) -> Result<Self, ExportError> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| ExportError::UnknownFormat(s.to_string()))
    }
}

/// Why a joint trajectory cannot be exported; nothing was written.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The format's name is none of [`ExportFormat::ALL`].
    #[error("unknown export format '{0}': give ros2-mcap, urscript or rapid")]
    UnknownFormat(String),
    /// The input cannot be read.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The input is not an `emg-joint-trajectory/2` file.
    #[error(
        "{path} is not a joint trajectory (emg-joint-trajectory/2, which `emg plan` writes as \
         STEM.joint_trajectory.json): {source}"
    )]
    NotJointTrajectory {
        /// The file.
        path: PathBuf,
        /// What the reader found wrong, naming the field.
        source: crate::error::FormatError,
    },
    /// The file's joint names are not the robot's.
    #[error("field 'joint_names' is {file:?}, but robot {robot} has the joints {expected:?}")]
    Joints {
        /// The robot file.
        robot: String,
        /// The file's names.
        file: Vec<String>,
        /// The robot's.
        expected: Vec<String>,
    },
    /// URScript asked for a robot that is not a six-joint Universal Robots arm.
    #[error(
        "urscript runs on Universal Robots controllers only: robot {robot} has {joints} joints \
         ({names}), not a UR arm's six (shoulder_pan_joint ... wrist_3_joint); export it with \
         --format ros2-mcap"
    )]
    NotUniversalRobots {
        /// The robot file.
        robot: String,
        /// Its number of joints.
        joints: usize,
        /// Its joint names, joined.
        names: String,
    },
    /// A format written from a job's program only, asked for a joint trajectory.
    #[error(
        "{0} is written from a job's program (emg-job/3, which `emg job` writes), through \
         targets the controller interpolates: a joint trajectory has no strokes to write it from; \
         export it with --format ros2-mcap"
    )]
    ProgramOnly(ExportFormat),
    /// A stretch between rests needs more `servoj` lines than one program holds.
    #[error(
        "urscript: the motion runs without rest from t = {from_s:.3} s to {to_s:.3} s, {lines} \
         servoj targets of {SERVO_PERIOD_S} s, more than the {max_lines} one program holds (a \
         program can only be split where the arm rests): raise --max-servoj if your controller \
         runs longer programs, or export ros2-mcap"
    )]
    TooLong {
        /// Start of the stretch (s).
        from_s: f64,
        /// Its end (s).
        to_s: f64,
        /// `servoj` lines it needs.
        lines: usize,
        /// The limit per program.
        max_lines: usize,
    },
    /// An option holds a value that cannot be used.
    #[error("{option} is {value}: {problem}")]
    Option {
        /// The option's name.
        option: &'static str,
        /// Its value.
        value: String,
        /// What is wrong with it.
        problem: &'static str,
    },
    /// The encoders failed (a bug, not the input's fault).
    #[error("{0}")]
    Encoding(String),
    /// An output would replace the input or another output.
    #[error(transparent)]
    Clash(#[from] OutputClash),
    /// An output cannot be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
}

/// The robot a joint trajectory is exported for.
#[derive(Clone, Copy, Debug, Default)]
pub struct ExportRobot<'a> {
    /// The robot file's path, as the export's messages name it.
    pub file: &'a str,
    /// The robot as the exported files record it (their metadata and header comments): a
    /// [`crate::RobotRef`]'s text, which names no directory of this machine for a shipped robot.
    pub reference: &'a str,
    /// The shipped robot's driver profile, when it is a shipped robot (its driver's joint names
    /// and frames); `None` for any other robot, whose file's joint names are kept.
    pub shipped: Option<&'static DriverProfile>,
    /// Its kinematics, to measure the thinned spline's deviation at the tool.
    pub kinematics: Option<&'a Robot>,
}

/// Settings of an export.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExportOptions {
    /// Largest joint deviation (rad) of the ROS 2 controller's quintic spline through the kept
    /// points from any sample.
    pub tolerance_rad: f64,
    /// Most `servoj` lines per URScript program.
    pub max_servoj_lines: usize,
}

impl Default for ExportOptions {
    fn default() -> Self {
        Self {
            tolerance_rad: DEFAULT_TOLERANCE_RAD,
            max_servoj_lines: DEFAULT_MAX_SERVOJ_LINES,
        }
    }
}

/// An export made in memory: its files and what it did, written by [`Export::write`].
#[derive(Clone, Debug)]
pub struct Export {
    /// The format.
    pub format: ExportFormat,
    /// Each file and its bytes.
    pub files: Vec<(PathBuf, Vec<u8>)>,
    /// The thinning of a ROS 2 export.
    pub thinning: Option<ThinningReport>,
    /// `servoj` targets of a URScript export (all programs together).
    pub servoj_targets: usize,
    /// What was exported, in words.
    pub summary: String,
}

impl Export {
    /// Writes every file atomically, after refusing, before anything is written, outputs that
    /// would replace `inputs` or one another.
    pub fn write(&self, inputs: &[(&str, &Path)]) -> Result<(), ExportError> {
        let outputs: Vec<(&str, &Path)> = self
            .files
            .iter()
            .map(|(path, _)| ("--out", path.as_path()))
            .collect();
        crate::paths::refuse_overwriting(inputs, &outputs)?;
        for (path, bytes) in &self.files {
            crate::atomic::write_atomically(path, bytes).map_err(|source| ExportError::Write {
                path: path.clone(),
                source,
            })?;
        }
        Ok(())
    }
}

/// What an export reads from a timed motion, a joint trajectory file's or a job's program: the
/// joint names, the limits it holds and its samples.
#[derive(Clone, Copy, Debug)]
pub struct TimedPoints<'a> {
    /// The arm's joints, base to tip.
    pub joint_names: &'a [String],
    /// The joint limits every sample holds.
    pub limits: &'a TimingLimits,
    /// The samples, from rest to rest.
    pub points: &'a [JointTrajectoryPoint],
    /// The arm's home, where the motion starts (a job's program): an export that starts the
    /// arm checks that it stands there, rather than moving it to the start from wherever it
    /// stands.
    pub home: Option<&'a [f64]>,
    /// The tool switched on and off along the motion (a job's program), which a ROS 2 export
    /// writes beside the trajectory.
    pub tool: Option<ToolSwitching<'a>>,
}

impl<'a> From<&'a JointTrajectory> for TimedPoints<'a> {
    fn from(trajectory: &'a JointTrajectory) -> Self {
        Self {
            joint_names: &trajectory.joint_names,
            limits: &trajectory.limits,
            points: &trajectory.points,
            home: None,
            tool: None,
        }
    }
}

/// Reads a joint-trajectory file, with an error naming the file and the field.
pub fn read_joint_trajectory(path: &Path) -> Result<JointTrajectory, ExportError> {
    let text = std::fs::read_to_string(path).map_err(|source| ExportError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    JointTrajectory::from_json(&text).map_err(|source| ExportError::NotJointTrajectory {
        path: path.to_path_buf(),
        source,
    })
}

/// Exports the timed motion `trajectory` for `robot` as `format` to `out` (a URScript motion
/// longer than one program: `out` without its extension, with `-part1.script`,
/// `-part2.script`, ...), in memory.
pub fn export(
    trajectory: TimedPoints<'_>,
    format: ExportFormat,
    out: &Path,
    robot: &ExportRobot<'_>,
    options: &ExportOptions,
) -> Result<Export, ExportError> {
    if let Some(kinematics) = robot.kinematics
        && kinematics.joint_names() != trajectory.joint_names
    {
        return Err(ExportError::Joints {
            robot: robot.file.to_string(),
            file: trajectory.joint_names.to_vec(),
            expected: kinematics.joint_names().to_vec(),
        });
    }
    if let Some(profile) = robot.shipped
        && profile.file_joint_names != trajectory.joint_names
    {
        return Err(ExportError::Joints {
            robot: robot.file.to_string(),
            file: trajectory.joint_names.to_vec(),
            expected: profile
                .file_joint_names
                .iter()
                .map(|s| s.to_string())
                .collect(),
        });
    }
    match format {
        ExportFormat::Ros2Mcap => ros2(trajectory, out, robot, options),
        ExportFormat::UrScript => ur_script(trajectory, out, robot, options),
        ExportFormat::Rapid | ExportFormat::Krl => Err(ExportError::ProgramOnly(format)),
    }
}

fn ros2(
    trajectory: TimedPoints<'_>,
    out: &Path,
    robot: &ExportRobot<'_>,
    options: &ExportOptions,
) -> Result<Export, ExportError> {
    let tolerance = options.tolerance_rad;
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(ExportError::Option {
            option: "--thinning-tolerance",
            value: tolerance.to_string(),
            problem: "expected a positive number of radians",
        });
    }
    let limits = SplineLimits {
        velocity: &trajectory.limits.max_velocity,
        acceleration: &trajectory.limits.max_acceleration,
    };
    let kept = thin(trajectory.points, tolerance, &limits);
    let report = measure(trajectory.points, &kept, tolerance, robot.kinematics);
    let (joint_names, topic, frame_id, driver, relation) = match robot.shipped {
        Some(p) => (
            p.joint_names.iter().map(|s| s.to_string()).collect(),
            p.topic,
            p.base_frame,
            p.driver,
            p.base_relation,
        ),
        None => (
            trajectory.joint_names.to_vec(),
            "/joint_trajectory_controller/joint_trajectory",
            "base_link",
            "none known: the robot file's joint names are kept",
            "the robot file's base frame as it is",
        ),
    };
    let tool = report
        .max_tool_deviation_m
        .map_or("not measured (no robot kinematics)".to_string(), |m| {
            format!("{m:.2e} m")
        });
    let mut notes = BTreeMap::from([
        ("source_robot".to_string(), robot.reference.to_string()),
        ("driver".to_string(), driver.to_string()),
        (
            "file_joint_names".to_string(),
            trajectory.joint_names.join(","),
        ),
        ("base_frame".to_string(), relation.to_string()),
        (
            "thinning_tolerance_rad".to_string(),
            format!("{tolerance:e}"),
        ),
        (
            "points_before".to_string(),
            report.points_before.to_string(),
        ),
        ("points_after".to_string(), report.points_after.to_string()),
        (
            "max_joint_deviation_rad".to_string(),
            format!("{:e}", report.max_joint_deviation_rad),
        ),
    ]);
    // A number, like every other value; absent when not measured.
    if let Some(m) = report.max_tool_deviation_m {
        notes.insert("max_tool_deviation_m".to_string(), format!("{m:e}"));
    }
    if let Some(tool) = &trajectory.tool {
        notes.insert("tool_output".to_string(), tool.output.to_string());
        notes.insert(
            "tool_output_topic".to_string(),
            format!(
                "{TOOL_OUTPUT_TOPIC} ({TOOL_OUTPUT_TYPE}: true switches the tool on), each \
                 message logged at its time from the trajectory's start"
            ),
        );
    }
    let message = ros2_mcap::Ros2Message {
        joint_names: &joint_names,
        frame_id,
        topic,
        notes,
        tool: trajectory.tool.map(|tool| tool.switches),
    };
    let bytes =
        ros2_mcap::mcap_bytes(trajectory.points, &kept, &message).map_err(ExportError::Encoding)?;
    let tool_line = trajectory.tool.map_or(String::new(), |tool| {
        format!(
            "\n  the tool ({}) switched {} times on {TOOL_OUTPUT_TOPIC} ({TOOL_OUTPUT_TYPE})",
            tool.output,
            tool.switches.len()
        )
    });
    let summary = format!(
        "{JOINT_TRAJECTORY_TYPE} on {topic} (joint names of {driver}; frame_id {frame_id}: \
         {relation})\n  {} of {} points kept: the quintic spline through them stays within \
         {tolerance:e} rad of every sample and within the file's velocity and acceleration \
         limits at their times (worst deviations {:.2e} rad, {:.2e} rad/s, {:.2e} rad/s²; at \
         the tool {tool})",
        report.points_after,
        report.points_before,
        report.max_joint_deviation_rad,
        report.max_velocity_deviation_rad_s,
        report.max_acceleration_deviation_rad_s2,
    ) + &tool_line;
    Ok(Export {
        format: ExportFormat::Ros2Mcap,
        files: vec![(out.to_path_buf(), bytes)],
        thinning: Some(report),
        servoj_targets: 0,
        summary,
    })
}

fn ur_script(
    trajectory: TimedPoints<'_>,
    out: &Path,
    robot: &ExportRobot<'_>,
    options: &ExportOptions,
) -> Result<Export, ExportError> {
    let names = &trajectory.joint_names;
    let shipped_ur = robot
        .shipped
        .is_some_and(|p| p.joint_names == UR_JOINT_NAMES);
    if !(shipped_ur || (robot.shipped.is_none() && is_universal_robots_arm(names))) {
        return Err(ExportError::NotUniversalRobots {
            robot: robot.file.to_string(),
            joints: names.len(),
            names: names.join(", "),
        });
    }
    if options.max_servoj_lines < 2 {
        return Err(ExportError::Option {
            option: "--max-servoj",
            value: options.max_servoj_lines.to_string(),
            problem: "expected at least 2 lines per program",
        });
    }
    let targets = resample(trajectory.points);
    let parts = urscript::split(&targets, options.max_servoj_lines).map_err(|(from, to)| {
        ExportError::TooLong {
            from_s: from,
            to_s: to,
            lines: ((to - from) / SERVO_PERIOD_S).round() as usize,
            max_lines: options.max_servoj_lines,
        }
    })?;
    let base = match robot.shipped {
        Some(p) => p.base_relation,
        None => "the robot file's base frame as it is",
    };
    let count = parts.len();
    let files = parts
        .iter()
        .enumerate()
        .map(|(i, &range)| {
            let path = if count == 1 {
                out.to_path_buf()
            } else {
                part_path(out, i + 1)
            };
            let header = vec![
                format!(
                    "written by emg export from a joint trajectory of robot {}",
                    robot.reference
                ),
                "for a Universal Robots e-Series controller (servo period 2 ms); joint values \
                 in the pendant's order and zero"
                    .to_string(),
                format!("base frame: {base}"),
                format!(
                    "program {} of {count}: t = {:.3} s to {:.3} s of the motion, {} servoj \
                     targets",
                    i + 1,
                    targets[range.0].time_s,
                    targets[range.1].time_s,
                    range.1 - range.0
                ),
                format!(
                    "servoj: t = {SERVO_PERIOD_S} s (one target per controller cycle), \
                     lookahead_time = {LOOKAHEAD_TIME_S} s, gain = {GAIN}"
                ),
                match (i, trajectory.home) {
                    (0, Some(_)) => format!(
                        "the motion starts at the arm's home, where the arm must stand: the \
                         program checks that every joint is within {START_TOLERANCE_RAD} rad \
                         of it and halts otherwise"
                    ),
                    _ => format!(
                        "the first target is reached by movej (a = \
                         {MOVEJ_ACCELERATION_RAD_S2} rad/s², v = {MOVEJ_SPEED_RAD_S} rad/s) \
                         from wherever the arm stands: clear that way"
                    ),
                },
            ];
            let start = if i == 0 && trajectory.home.is_some() {
                urscript::Start::Check
            } else {
                urscript::Start::Move
            };
            let text = urscript::program(&targets, range, "emg_motion", &header, start);
            (path, text.into_bytes())
        })
        .collect();
    let lines = targets.len() - 1;
    let summary = format!(
        "URScript for a Universal Robots e-Series controller: movej to the start, then {lines} \
         servoj targets every {SERVO_PERIOD_S} s ({:.3} s; lookahead_time {LOOKAHEAD_TIME_S} \
         s, gain {GAIN}){}",
        targets.last().map_or(0.0, |t| t.time_s),
        if count > 1 {
            format!(", in {count} programs split where the arm rests")
        } else {
            String::new()
        }
    );
    Ok(Export {
        format: ExportFormat::UrScript,
        files,
        thinning: None,
        servoj_targets: lines,
        summary,
    })
}

/// `out` without its extension, with `-part<n>.script`: a URScript program's part.
fn part_path(out: &Path, n: usize) -> PathBuf {
    let mut name = OsString::from(out.with_extension("").as_os_str());
    name.push(format!("-part{n}.script"));
    PathBuf::from(name)
}
