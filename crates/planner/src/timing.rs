//! How planned motions are timed for a robot: the joint limits a URDF cannot hold (a MoveIt
//! `joint_limits.yaml`, by default beside the robot file), the scaling and tool speed asked
//! for, and the output rate.

use std::path::{Path, PathBuf};

use emg_control::{ConstraintConfig, Task, Trajectory};
use emg_io::TimingLimits;
use emg_kinematics::{JointVector, Robot};
use emg_timing::{
    DynamicLimits, LimitsError, Scaling, TimedMotion, TimingError, TimingRequest, time_motion,
};

/// Output rate when none is asked for (Hz): libfranka's 1 kHz.
pub const DEFAULT_RATE_HZ: f64 = 1000.0;

/// The joint limits file of robot file `robot`: `<stem>.joint_limits.yaml` beside it
/// (`data/robots/fr3_pen.joint_limits.yaml` for `data/robots/fr3_pen.urdf`).
pub fn limits_file_beside(robot: &Path) -> PathBuf {
    let stem = robot.file_stem().unwrap_or_default().to_string_lossy();
    robot.with_file_name(format!("{stem}.joint_limits.yaml"))
}

/// The path of `file` relative to the directory of `anchor` (both after resolving links and
/// `..` in their directories; `fr3_pen.joint_limits.yaml` for a file beside `anchor`,
/// `../limits/arm.yaml` for one in a sibling directory); `file` as given where either directory
/// cannot be resolved or no relative path joins them (another drive).
fn relative_to_directory_of(file: &Path, anchor: &Path) -> String {
    let directory = |path: &Path| match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.canonicalize(),
        _ => Path::new(".").canonicalize(),
    };
    let (Some(name), Ok(from), Ok(to)) = (file.file_name(), directory(anchor), directory(file))
    else {
        return file.display().to_string();
    };
    let shared = from
        .components()
        .zip(to.components())
        .take_while(|(a, b)| a == b)
        .count();
    if shared == 0 {
        return file.display().to_string();
    }
    let mut relative: PathBuf = from.components().skip(shared).map(|_| "..").collect();
    relative.extend(to.components().skip(shared));
    relative.push(name);
    relative.display().to_string()
}

/// Why timing could not be set up: the limits file, or a request value.
#[derive(Debug, thiserror::Error)]
pub enum TimingSetupError {
    /// The joint limits file is missing or unusable.
    #[error("{0}")]
    Limits(#[from] LimitsError),
    /// A rate, speed or limit is unusable.
    #[error("{0}")]
    Request(#[from] TimingError),
}

/// Everything a plan's timing needs, resolved once for a robot.
#[derive(Clone, Debug, PartialEq)]
pub struct MotionTiming {
    /// How [`MotionTiming::record`] names the limits' file.
    limits_file: String,
    assumed: bool,
    /// The arm's joints (the entries of the limits a file records).
    joints: usize,
    scaling: Scaling,
    request: TimingRequest,
}

/// What [`MotionTiming::record`] names as the limits' file when they were assumed.
pub const ASSUMED_LIMITS: &str = "assumed";

impl MotionTiming {
    /// Timing for the robot read from `robot_file`, as [`MotionTiming::new`], with the limits
    /// of `limits` (a MoveIt joint_limits.yaml), else of the one beside the robot file
    /// ([`limits_file_beside`]), else assumed ([`DynamicLimits::assumed`]: the robot file's
    /// velocities with conservative acceleration and jerk limits; [`MotionTiming::assumed`]
    /// says so). Its record names the limits file by its path relative to the robot file's
    /// directory (`fr3_pen.joint_limits.yaml` for the one beside it): the files written name
    /// no directory of this machine.
    pub fn for_robot_file(
        robot: &Robot,
        robot_file: &Path,
        limits: Option<&Path>,
        scaling: Scaling,
        tool_speed_m_per_s: f64,
        rate_hz: f64,
        constraints: &ConstraintConfig,
    ) -> Result<Self, TimingSetupError> {
        let beside = limits_file_beside(robot_file);
        let (limits, origin, assumed) = match limits {
            Some(path) => (DynamicLimits::read(path, robot)?, path, false),
            None if beside.exists() => (
                DynamicLimits::read(&beside, robot)?,
                beside.as_path(),
                false,
            ),
            None => (
                DynamicLimits::assumed(robot),
                Path::new(ASSUMED_LIMITS),
                true,
            ),
        };
        let mut timing = Self::with_limits(
            robot,
            limits,
            origin,
            scaling,
            tool_speed_m_per_s,
            rate_hz,
            constraints,
        )?;
        timing.assumed = assumed;
        if !assumed {
            timing.limits_file = relative_to_directory_of(origin, robot_file);
        }
        Ok(timing)
    }

    /// Timing for `robot` with the limits of `limits_file` scaled by `scaling`, each velocity
    /// limit at most the robot file's times `constraints.velocity_limit_fraction` (the bound
    /// every planned step holds), the tool at most `tool_speed_m_per_s`, sampled at `rate_hz`.
    /// Its record names the limits file by its path as given.
    pub fn new(
        robot: &Robot,
        limits_file: &Path,
        scaling: Scaling,
        tool_speed_m_per_s: f64,
        rate_hz: f64,
        constraints: &ConstraintConfig,
    ) -> Result<Self, TimingSetupError> {
        let limits = DynamicLimits::read(limits_file, robot)?;
        Self::with_limits(
            robot,
            limits,
            limits_file,
            scaling,
            tool_speed_m_per_s,
            rate_hz,
            constraints,
        )
    }

    /// Timing with `limits` (read from `origin`), as [`MotionTiming::new`].
    fn with_limits(
        robot: &Robot,
        limits: DynamicLimits,
        origin: &Path,
        scaling: Scaling,
        tool_speed_m_per_s: f64,
        rate_hz: f64,
        constraints: &ConstraintConfig,
    ) -> Result<Self, TimingSetupError> {
        let fraction = constraints
            .velocity_limit_fraction
            .map_or(1.0, |fraction| fraction.get());
        let ceiling: JointVector = robot.limits().velocity * fraction;
        let limits = limits.scaled(scaling).with_velocity_ceiling(&ceiling);
        let request = TimingRequest {
            limits,
            tool_speed_m_per_s,
            rate_hz,
        };
        request.validate()?;
        Ok(Self {
            limits_file: origin.display().to_string(),
            assumed: false,
            joints: robot.dof(),
            scaling,
            request,
        })
    }

    /// The arm's number of joints (the entries of every limit and sample that are its).
    pub fn joints(&self) -> usize {
        self.joints
    }

    /// Whether the acceleration and jerk limits were assumed, no limits file being found.
    pub fn assumed(&self) -> bool {
        self.assumed
    }

    /// What the timing asks for (the effective limits, tool speed and rate).
    pub fn request(&self) -> &TimingRequest {
        &self.request
    }

    /// The rest-to-rest motion along `trajectory`'s steps.
    pub fn time(
        &self,
        robot: &Robot,
        task: &Task,
        constraints: &ConstraintConfig,
        trajectory: &Trajectory,
    ) -> Result<TimedMotion, TimingError> {
        let waypoints: Vec<JointVector> = trajectory.steps.iter().map(|s| s.q).collect();
        time_motion(robot, task, constraints, &waypoints, &self.request)
    }

    /// The limits as a joint-trajectory file records them.
    pub fn record(&self) -> TimingLimits {
        let limits = &self.request.limits;
        let joints = |values: &JointVector| values.as_slice()[..self.joints].to_vec();
        TimingLimits {
            joint_limits_file: self.limits_file.clone(),
            velocity_scaling: self.scaling.velocity,
            acceleration_scaling: self.scaling.acceleration,
            tool_speed_m_per_s: self.request.tool_speed_m_per_s,
            max_velocity: joints(&limits.velocity),
            max_acceleration: joints(&limits.acceleration),
            max_jerk: joints(&limits.jerk),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The timing `for_robot_file` sets up for the FR3 read from `robot_file`, with `limits`.
    fn timing(robot_file: &Path, limits: Option<&Path>) -> MotionTiming {
        let robot = crate::test_support::fr3();
        MotionTiming::for_robot_file(
            &robot,
            robot_file,
            limits,
            Scaling::default(),
            0.1,
            DEFAULT_RATE_HZ,
            &ConstraintConfig::default(),
        )
        .expect("the timing")
    }

    #[test]
    fn the_record_names_the_limits_file_from_the_robot_files_directory() {
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data");
        let shipped = data.join("robots/fr3_pen.urdf");
        let beside = "fr3_pen.joint_limits.yaml";
        // The file beside the robot file by its name, however the robot file is given.
        for robot_file in [
            shipped.clone(),
            shipped.canonicalize().unwrap(),
            PathBuf::from("../../data/robots/fr3_pen.urdf"),
        ] {
            let record = timing(&robot_file, None).record();
            assert_eq!(record.joint_limits_file, beside, "{}", robot_file.display());
        }
        // A file given elsewhere by its path from the robot file's directory.
        let dir = tempfile::tempdir().unwrap();
        let (robots, limits) = (dir.path().join("robots"), dir.path().join("limits"));
        std::fs::create_dir_all(&robots).unwrap();
        std::fs::create_dir_all(&limits).unwrap();
        let given = limits.join("arm.yaml");
        std::fs::copy(data.join("robots").join(beside), &given).unwrap();
        let robot_file = robots.join("arm.urdf");
        let elsewhere = timing(&robot_file, Some(&given));
        assert!(!elsewhere.assumed());
        let recorded = elsewhere.record().joint_limits_file;
        assert_eq!(
            recorded,
            Path::new("..")
                .join("limits/arm.yaml")
                .display()
                .to_string()
        );
        assert_eq!(
            robots.join(&recorded).canonicalize().unwrap(),
            given.canonicalize().unwrap()
        );
        // None found: assumed.
        let assumed = timing(&robot_file, None);
        assert!(assumed.assumed());
        assert_eq!(assumed.record().joint_limits_file, ASSUMED_LIMITS);
    }

    #[test]
    fn a_file_beside_its_anchor_is_named_by_its_name_and_a_bare_name_from_here() {
        assert_eq!(
            relative_to_directory_of(Path::new("a.yaml"), Path::new("arm.urdf")),
            "a.yaml"
        );
        assert_eq!(
            relative_to_directory_of(Path::new("src/a.yaml"), Path::new("arm.urdf")),
            Path::new("src/a.yaml").display().to_string()
        );
        assert_eq!(
            relative_to_directory_of(Path::new("a.yaml"), Path::new("src/arm.urdf")),
            Path::new("../a.yaml").display().to_string()
        );
        // A directory that does not exist cannot be resolved: the path as given.
        let missing = Path::new("/no/such/directory/a.yaml");
        assert_eq!(
            relative_to_directory_of(missing, Path::new("arm.urdf")),
            missing.display().to_string()
        );
    }
}
