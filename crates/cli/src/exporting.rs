//! Writing a joint trajectory or a job's program for a robot's own stack (a ROS 2
//! `JointTrajectory` in an MCAP bag, a URScript program, or a job's program as a RAPID module
//! or a KRL program), by [`emg_io::export`], `emg_job::ur_program`, `emg_job::rapid_program`
//! and `emg_job::krl_program`: what
//! `emg export`, `emg plan --export`, `emg job --export` and `emg place --export` share.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use emg_io::{DriverProfile, ExportFormat, ExportOptions, ExportRobot};
use emg_kinematics::Robot;
use emg_planner::ShippedRobot;

use crate::robot;

/// The form of a URScript export.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum UrScriptForm {
    /// One program as UR integrators write it: movej between strokes, movel down and up, each
    /// stroke a blended movep run through the plan's poses, the tool switched by its output
    /// (a job's program on the shipped UR5e).
    Native,
    /// The plan's joint values streamed by servoj every 2 ms, split where the arm rests.
    Servoj,
}

/// How a URScript export is written; every command that exports takes these.
#[derive(Clone, Copy, Debug, Args)]
pub struct UrScriptArgs {
    /// urscript: `native` (one program of movej, movel and blended movep through the plan's
    /// targets, with the tool's output; a job's program on the shipped ur5e) or `servoj` (the
    /// joint values every 2 ms). Default: native for a job's program, servoj for a joint
    /// trajectory.
    #[arg(long, value_name = "FORM", value_enum)]
    pub urscript: Option<UrScriptForm>,
    /// urscript servoj: most servoj lines (2 ms each) per program.
    #[arg(long, value_name = "N", default_value_t = ExportOptions::default().max_servoj_lines)]
    pub max_servoj: usize,
}

/// Parses `--format` and `--export`.
pub fn parse_format(value: &str) -> Result<ExportFormat, String> {
    value
        .parse()
        .map_err(|e: emg_io::ExportError| e.to_string())
}

/// The driver profile of `robot_file` when it is a shipped robot's file.
fn shipped_profile(robot_file: &Path) -> Option<&'static DriverProfile> {
    ShippedRobot::by_path(robot_file, &robot::data_dir())
        .and_then(|shipped| DriverProfile::for_shipped(shipped.name))
}

/// Exports the timed motion `trajectory` (read from `input`, named by what it is: a joint
/// trajectory or a job's program) for the robot of `robot_file`; returns what to print.
pub fn export_to(
    trajectory: emg_io::TimedPoints<'_>,
    format: ExportFormat,
    out: &Path,
    robot_file: &Path,
    robot: &Robot,
    options: &ExportOptions,
    input: (&str, &Path),
) -> Result<String> {
    let file = robot_file.display().to_string();
    let reference = robot::reference(robot_file)?.to_string();
    let target = ExportRobot {
        file: &file,
        reference: &reference,
        shipped: shipped_profile(robot_file),
        kinematics: Some(robot),
    };
    let export = emg_io::export(trajectory, format, out, &target, options)?;
    export.write(&[input, ("robot", robot_file)])?;
    Ok(written(&export))
}

/// The file `--export FORMAT` of `emg job` and `emg place` writes beside the program `out`:
/// its extension `.mcap`, `.script` or `.mod`; a KRL program's `.src` (its `.dat` beside it)
/// named as KRL allows ([`emg_job::krl_program::krl_path_beside`]).
pub fn beside_program(out: &Path, format: ExportFormat) -> PathBuf {
    match format {
        ExportFormat::Krl => emg_job::krl_program::krl_path_beside(out),
        _ => out.with_extension(format.extension()),
    }
}

/// Refuses, before anything is planned, `--export FORMAT` of a program for a robot it cannot run
/// on (URScript for an arm that is not a Universal Robots arm, RAPID for one without six
/// joints).
pub fn refuse_program_export(
    format: Option<ExportFormat>,
    urscript: &UrScriptArgs,
    robot_file: &Path,
) -> Result<()> {
    let Some(format) = format else {
        return Ok(());
    };
    let robot = robot::load_robot(robot_file, None, None)?;
    refuse_format(format, robot_file, &robot)
        .with_context(|| format!("--export {format}: nothing was planned or written"))?;
    if format == ExportFormat::UrScript {
        writes_native(urscript, robot_file)
            .context("--export urscript: nothing was planned or written")?;
    }
    Ok(())
}

/// Exports a job's program `file`, written to `out`, as `format` beside it
/// ([`beside_program`]); returns what to print.
pub fn export_program(
    file: &emg_job::JobFile,
    format: ExportFormat,
    urscript: &UrScriptArgs,
    out: &Path,
    robot_file: &Path,
    robot: &Robot,
) -> Result<String> {
    let target = ExportTarget {
        format,
        out: &beside_program(out, format),
        urscript,
        thinning_tolerance: ExportOptions::default().tolerance_rad,
    };
    export_job(file, &target, out, robot_file, robot)
}

/// What a job's program is exported as, and where.
pub struct ExportTarget<'a> {
    /// The format written.
    pub format: ExportFormat,
    /// The file written (a split URScript stream: its parts beside it).
    pub out: &'a Path,
    /// How a URScript export is written.
    pub urscript: &'a UrScriptArgs,
    /// ros2-mcap: the largest joint deviation (rad) of the thinned trajectory.
    pub thinning_tolerance: f64,
}

/// Exports the job's program `file` (read from `input`) for the robot of `robot_file`: a native
/// UR program unless `--urscript servoj` asks for the joint stream; returns what to print.
pub fn export_job(
    file: &emg_job::JobFile,
    target: &ExportTarget<'_>,
    input: &Path,
    robot_file: &Path,
    robot: &Robot,
) -> Result<String> {
    let arm = (robot_file, robot);
    if target.format == ExportFormat::UrScript && writes_native(target.urscript, robot_file)? {
        let write = |file: &_, robot: &_, reference: &_, out: &_| {
            Ok(emg_job::ur_program::ur_program_export(
                file, robot, reference, out,
            )?)
        };
        return controller_program(&write, file, target.out, input, arm);
    }
    if target.format == ExportFormat::Rapid {
        let write = |file: &_, robot: &_, reference: &_, out: &_| {
            Ok(emg_job::rapid_program::rapid_program_export(
                file, robot, reference, out,
            )?)
        };
        return controller_program(&write, file, target.out, input, arm);
    }
    if target.format == ExportFormat::Krl {
        let tool = krl_tool(robot_file, robot)?;
        let write = |file: &_, robot: &_, reference: &_, out: &_| {
            Ok(emg_job::krl_program::krl_program_export(
                file, robot, &tool, reference, out,
            )?)
        };
        return controller_program(&write, file, target.out, input, arm);
    }
    let options = ExportOptions {
        tolerance_rad: target.thinning_tolerance,
        max_servoj_lines: target.urscript.max_servoj,
    };
    let (points, switches) = (file.points(), file.tool_switches());
    let output = file.settings.tool_output.to_string();
    let tool = emg_io::ToolSwitching {
        switches: &switches,
        output: &output,
    };
    export_to(
        file.timed_points(&points, tool),
        target.format,
        target.out,
        robot_file,
        robot,
        &options,
        ("job program", input),
    )
}

/// What an export says it wrote: its summary and its files.
fn written(export: &emg_io::Export) -> String {
    let files: Vec<String> = export
        .files
        .iter()
        .map(|(path, _)| path.display().to_string())
        .collect();
    format!("{}\n  wrote {}", export.summary, files.join(", "))
}

/// Whether a URScript export of a job's program is written native: where `--urscript` asks
/// (refused for a robot other than the shipped UR5e, the one whose base and flange frames are
/// known to be the controller's Base and tool flange), and by default on the shipped UR5e;
/// servoj on any other UR arm.
fn writes_native(urscript: &UrScriptArgs, robot_file: &Path) -> Result<bool> {
    let known = shipped_profile(robot_file).is_some_and(DriverProfile::has_ur_controller_frames);
    match urscript.urscript {
        Some(UrScriptForm::Servoj) => Ok(false),
        Some(UrScriptForm::Native) if !known => anyhow::bail!(
            "--urscript native writes poses in the controller's Base frame with the TCP on the \
             tool flange, frames known for the shipped ur5e only; robot {} is not it: export \
             --urscript servoj",
            robot_file.display()
        ),
        Some(UrScriptForm::Native) => Ok(true),
        None => Ok(known),
    }
}

/// The writer of a controller's own program from a job's program: the program `file` for the
/// arm `robot`, recorded as written for the robot reference, into `out`.
type ControllerProgram<'a> =
    &'a dyn Fn(&emg_job::JobFile, &Robot, &str, &Path) -> Result<emg_io::Export, anyhow::Error>;

/// The TCP of `robot` (read from `robot_file`) in the frame of its flange, ROS-Industrial's
/// `tool0`: where a KRL program's `TOOL_DATA` comes from.
pub fn krl_tool(robot_file: &Path, robot: &Robot) -> Result<nalgebra::Isometry3<f64>> {
    let flange =
        Robot::from_urdf_file(robot_file, robot.base_link(), "tool0").with_context(|| {
            format!(
                "a KRL program gives its tool in the flange's frame: robot {} has no chain from {} \
             to tool0 (ROS-Industrial's flange link)",
                robot_file.display(),
                robot.base_link()
            )
        })?;
    Ok(emg_job::krl_program::tool_in_flange(robot, &flange)?)
}

/// Writes the job's program `file` (read from `input`) as one controller's program by `write`
/// (a native UR program, a RAPID module, a KRL program) to `out`; returns what to print.
fn controller_program(
    write: ControllerProgram<'_>,
    file: &emg_job::JobFile,
    out: &Path,
    input: &Path,
    (robot_file, robot): (&Path, &Robot),
) -> Result<String> {
    let reference = robot::reference(robot_file)?.to_string();
    let export = write(file, robot, &reference, out)?;
    export.write(&[("job program", input), ("robot", robot_file)])?;
    Ok(written(&export))
}

/// Refuses URScript for a robot that is not a Universal Robots arm (by its driver profile when
/// shipped, else by its joint names), RAPID and KRL for an arm that has not six joints or is a
/// shipped arm of another vendor, and KRL for an arm without ROS-Industrial's flange link.
pub fn refuse_format(format: ExportFormat, robot_file: &Path, robot: &Robot) -> Result<()> {
    let names = robot.joint_names();
    let is_ur = match shipped_profile(robot_file) {
        Some(profile) => profile.joint_names == emg_io::UR_JOINT_NAMES,
        None => emg_io::is_universal_robots_arm(names),
    };
    if format == ExportFormat::UrScript && !is_ur {
        return Err(anyhow::Error::new(
            emg_io::ExportError::NotUniversalRobots {
                robot: robot_file.display().to_string(),
                joints: names.len(),
                names: names.join(", "),
            },
        ));
    }
    if format == ExportFormat::Rapid && robot.dof() != 6 {
        return Err(anyhow::Error::new(
            emg_job::rapid_program::RapidProgramError::Joints(robot.dof()),
        ));
    }
    if format == ExportFormat::Krl && robot.dof() != 6 {
        return Err(anyhow::Error::new(
            emg_job::krl_program::KrlProgramError::Joints(robot.dof()),
        ));
    }
    let vendor_arm = match format {
        ExportFormat::Rapid => Some(("ABB", "irb120")),
        ExportFormat::Krl => Some(("KUKA", "kr16")),
        _ => None,
    };
    if let Some((vendor, arm)) = vendor_arm
        && let Some(shipped) = robot::shipped(robot_file)
        && shipped.name != arm
    {
        anyhow::bail!(
            "{format} runs on {vendor} controllers, which drive {vendor} arms: robot {} is the \
             shipped {}",
            robot_file.display(),
            shipped.name
        );
    }
    if format == ExportFormat::Krl {
        krl_tool(robot_file, robot)?;
    }
    Ok(())
}
