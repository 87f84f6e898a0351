//! Option groups and value parsers more than one command takes: the kinematic chain's ends, a
//! task line, joint-limit scaling, and the numbers and vectors typed on the command line.

use std::path::Path;

use anyhow::Result;
use clap::Args;
use emg_kinematics::Robot;
use emg_verify::ReferenceModel;

use crate::robot;

/// The ends of the kinematic chain read from a robot file.
#[derive(Debug, Args)]
pub struct ChainArgs {
    /// Base link of the kinematic chain (default: the file's root link).
    #[arg(long)]
    pub base_link: Option<String>,
    /// Tip link of the chain, the TCP whose z-axis is the tool axis (default: the file's only
    /// leaf link).
    #[arg(long)]
    pub tip_link: Option<String>,
}

impl ChainArgs {
    /// The robot of `robot_file`, its chain between the ends these options name.
    pub fn load_robot(&self, robot_file: &Path) -> Result<Robot> {
        robot::load_robot(
            robot_file,
            self.base_link.as_deref(),
            self.tip_link.as_deref(),
        )
    }

    /// The robot of `robot_file` (as [`ChainArgs::load_robot`]) and its independent checker.
    pub fn robot_and_checker(&self, robot_file: &Path) -> Result<(Robot, ReferenceModel)> {
        let robot = self.load_robot(robot_file)?;
        let model = robot::load_checker(robot_file, &robot)?;
        Ok((robot, model))
    }
}

/// Velocity and acceleration scaling of joint limits, as MoveIt and Pilz take them.
#[derive(Debug, Args)]
pub struct ScalingArgs {
    /// Factor in (0, 1] on the joint velocity limits.
    #[arg(long, value_name = "F", default_value_t = 1.0)]
    pub velocity_scaling: f64,
    /// Factor in (0, 1] on the joint acceleration and jerk limits.
    #[arg(long, value_name = "F", default_value_t = 1.0)]
    pub acceleration_scaling: f64,
}

impl ScalingArgs {
    /// The factors, checked to lie in (0, 1].
    pub fn scaling(&self) -> Result<emg_timing::Scaling, emg_timing::LimitsError> {
        emg_timing::Scaling::new(self.velocity_scaling, self.acceleration_scaling)
    }
}

/// A task line on the command line: all three of `--p0`, `--d` and `--n`, or none.
#[derive(Debug, Args)]
pub struct TaskLineArgs {
    /// Task start position p0 (m), as x,y,z. Needs --d and --n.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true,
          requires_all = ["d", "n"])]
    pub p0: Option<[f64; 3]>,
    /// Task motion direction d, as x,y,z (normalised; must be perpendicular to n).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true,
          requires_all = ["p0", "n"])]
    pub d: Option<[f64; 3]>,
    /// Task-plane normal n, as x,y,z (normalised; the tool axis must stay near it).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true,
          requires_all = ["p0", "d"])]
    pub n: Option<[f64; 3]>,
}

/// Parses `--tolerance`: the line tolerance in millimetres, a number > 0 (a negative one is read
/// as a value, not as a flag, and refused in the flag's unit).
pub fn tolerance_mm(s: &str) -> Result<f64, String> {
    bounded(s, "> 0 mm", |mm| mm > 0.0)
}

/// Parses `--cone`: the tool cone's half-angle in degrees, in (0, 90).
pub fn cone_deg(s: &str) -> Result<f64, String> {
    bounded(s, "in (0, 90)°", |deg| deg > 0.0 && deg < 90.0)
}

/// Parses `--scale`: metres per unit of an SVG drawing, a number > 0, or `physical` for its own
/// physical size ([`emg_io::SVG_PX_M`] per CSS pixel).
pub fn parse_scale(s: &str) -> Result<f64, String> {
    match s.trim() {
        "physical" => Ok(emg_io::SVG_PX_M),
        _ => bounded(s, "> 0 m per unit, or 'physical'", |scale| scale > 0.0),
    }
}

/// A finite number for which `holds` is true; else an error saying what it must be
/// (`wanted`) and what it is.
fn bounded(s: &str, wanted: &str, holds: impl Fn(f64) -> bool) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(value) if value.is_finite() && holds(value) => Ok(value),
        Ok(_) => Err(format!("must be {wanted}, got {s}")),
        Err(_) => Err(format!("must be a number {wanted}, got '{s}'")),
    }
}

/// Parses `x,y,z`.
pub fn parse_vec3(s: &str) -> Result<[f64; 3], emg_planner::ParseError> {
    emg_planner::parse::numbers(s)
}
