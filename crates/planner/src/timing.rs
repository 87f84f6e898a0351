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
    /// says so).
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
        Ok(timing)
    }

    /// Timing for `robot` with the limits of `limits_file` scaled by `scaling`, each velocity
    /// limit at most the robot file's times `constraints.velocity_limit_fraction` (the bound
    /// every planned step holds), the tool at most `tool_speed_m_per_s`, sampled at `rate_hz`.
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
