//! `emg export` and `emg plan --export`: a joint trajectory written for a robot's own stack (a
//! ROS 2 `JointTrajectory` in an MCAP bag, or a URScript program), by [`emg_io::export`].

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use emg_io::{DriverProfile, ExportFormat, ExportOptions, ExportRobot, PlanPaths};
use emg_kinematics::Robot;
use emg_planner::ShippedRobot;

use crate::args::PlanArgs;

/// Options of `emg export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The motion to export: a joint trajectory (`STEM.joint_trajectory.json`,
    /// emg-joint-trajectory/2) or a job's program (emg-job/3).
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// `ros2-mcap` (trajectory_msgs/msg/JointTrajectory in an MCAP file) or `urscript` (a
    /// program for a Universal Robots e-Series controller; six-joint UR arms only).
    #[arg(long, value_name = "FORMAT", value_parser = parse_format)]
    pub format: ExportFormat,
    /// The file to write (a URScript motion too long for one program is split where the arm
    /// rests: OUT without its extension, with -part1.script, -part2.script, ...; missing parent directories
    /// are created).
    #[arg(long, value_name = "PATH")]
    pub out: PathBuf,
    /// Robot: a shipped robot's name (`fr3`, `iiwa14`, `ur5e`) or a robot file (URDF). Default:
    /// the file's `robot` field.
    #[arg(long, value_name = "NAME|URDF", value_parser = crate::robot::parse_robot)]
    pub robot: Option<PathBuf>,
    /// ros2-mcap: the largest joint deviation (rad) of the controller's quintic spline through
    /// the points kept from any sample of the file.
    #[arg(long, value_name = "RAD", default_value_t = ExportOptions::default().tolerance_rad)]
    pub thinning_tolerance: f64,
    /// How a URScript export is written.
    #[command(flatten)]
    pub urscript: UrScriptArgs,
}

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
    ShippedRobot::by_path(robot_file, &crate::robot::data_dir())
        .and_then(|shipped| DriverProfile::for_shipped(shipped.name))
}

/// Runs `emg export`: reads the file, resolves its robot, exports, and prints what it wrote.
pub fn run_export(args: &ExportArgs) -> Result<()> {
    let job = crate::check::read_job_file(&args.file)?;
    let trajectory = match &job {
        Some(_) => None,
        None => Some(emg_io::read_joint_trajectory(&args.file)?),
    };
    let robot_field = match (&job, &trajectory) {
        (Some(job), _) => &job.robot,
        (None, Some(trajectory)) => &trajectory.robot,
        (None, None) => unreachable!("a file is read as one or the other"),
    };
    let robot_file = match &args.robot {
        Some(path) => path.clone(),
        None => crate::robot::resolve(robot_field, &args.file)?,
    };
    let robot = crate::robot::load_robot(&robot_file, None, None)?;
    let target = ExportTarget {
        format: args.format,
        out: &args.out,
        urscript: &args.urscript,
        thinning_tolerance: args.thinning_tolerance,
    };
    let text = match (&job, &trajectory) {
        (Some(job), _) => export_job(job, &target, &args.file, &robot_file, &robot)?,
        (None, Some(trajectory)) => {
            if args.urscript.urscript == Some(UrScriptForm::Native)
                && args.format == ExportFormat::UrScript
            {
                anyhow::bail!(
                    "--urscript native writes a job's program (emg-job/3, which `emg job` \
                     writes); {} is a joint trajectory: export it with --urscript servoj",
                    args.file.display()
                );
            }
            let options = ExportOptions {
                tolerance_rad: args.thinning_tolerance,
                max_servoj_lines: args.urscript.max_servoj,
            };
            export_to(
                trajectory.into(),
                args.format,
                &args.out,
                &robot_file,
                &robot,
                &options,
                ("joint trajectory", &args.file),
            )?
        }
        (None, None) => unreachable!("a file is read as one or the other"),
    };
    println!("{text}");
    Ok(())
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
    let reference = crate::robot::reference(robot_file)?.to_string();
    let target = ExportRobot {
        file: &file,
        reference: &reference,
        shipped: shipped_profile(robot_file),
        kinematics: Some(robot),
    };
    let export = emg_io::export(trajectory, format, out, &target, options)?;
    export.write(&[input, ("robot", robot_file)])?;
    let written: Vec<String> = export
        .files
        .iter()
        .map(|(path, _)| path.display().to_string())
        .collect();
    Ok(format!(
        "{}\n  wrote {}",
        export.summary,
        written.join(", ")
    ))
}

/// The file `--export FORMAT` of `emg job` and `emg place` writes beside the program `out`:
/// its extension `.mcap` or `.script`.
pub fn beside_program(out: &Path, format: ExportFormat) -> PathBuf {
    out.with_extension(format.extension())
}

/// Refuses, before anything is planned, `--export FORMAT` of a program for a robot it cannot run
/// on (URScript for an arm that is not a Universal Robots arm).
pub fn refuse_program_export(
    format: Option<ExportFormat>,
    urscript: &UrScriptArgs,
    robot_file: &Path,
) -> Result<()> {
    let Some(format) = format else {
        return Ok(());
    };
    let robot = crate::robot::load_robot(robot_file, None, None)?;
    refuse_format(format, robot_file, &robot)
        .context("--export urscript: nothing was planned or written")?;
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
struct ExportTarget<'a> {
    format: ExportFormat,
    out: &'a Path,
    urscript: &'a UrScriptArgs,
    thinning_tolerance: f64,
}

/// Exports the job's program `file` (read from `input`) for the robot of `robot_file`: a native
/// UR program unless `--urscript servoj` asks for the joint stream; returns what to print.
fn export_job(
    file: &emg_job::JobFile,
    target: &ExportTarget<'_>,
    input: &Path,
    robot_file: &Path,
    robot: &Robot,
) -> Result<String> {
    if target.format == ExportFormat::UrScript && writes_native(target.urscript, robot_file)? {
        return native_ur_program(file, target.out, input, robot_file, robot);
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

/// Writes the job's program `file` (read from `input`) as one native UR program to `out`;
/// returns what to print.
fn native_ur_program(
    file: &emg_job::JobFile,
    out: &Path,
    input: &Path,
    robot_file: &Path,
    robot: &Robot,
) -> Result<String> {
    let reference = crate::robot::reference(robot_file)?.to_string();
    let export = emg_job::ur_program::ur_program_export(file, robot, &reference, out)?;
    export.write(&[("job program", input), ("robot", robot_file)])?;
    Ok(format!("{}\n  wrote {}", export.summary, out.display()))
}

/// The file `emg plan --export` writes beside a task's files: `STEM.mcap` or `STEM.script`.
fn plan_output(paths: &PlanPaths, format: ExportFormat) -> PathBuf {
    paths.json.with_extension(format.extension())
}

/// Refuses, before anything is planned, an `emg plan --export` that cannot be done: URScript
/// for a robot that is not a Universal Robots arm, or an output replacing an input.
pub fn refuse_plan_export(args: &PlanArgs, robot: &Robot, tasks: usize) -> Result<()> {
    let Some(format) = args.export else {
        return Ok(());
    };
    refuse_format(format, &args.robot, robot)
        .context("--export urscript: nothing was planned or written")?;
    let indices: Vec<Option<usize>> = match tasks {
        1 => vec![None],
        many => (0..many).map(Some).collect(),
    };
    let outputs: Vec<PathBuf> = indices
        .iter()
        .map(|&index| plan_output(&PlanPaths::new(&args.out, index), format))
        .collect();
    let outputs: Vec<(&str, &Path)> = outputs.iter().map(|p| ("--export", p.as_path())).collect();
    Ok(emg_io::refuse_overwriting(
        &[("--robot", args.robot.as_path())],
        &outputs,
    )?)
}

/// Refuses URScript for a robot that is not a Universal Robots arm (by its driver profile when
/// shipped, else by its joint names).
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
    Ok(())
}

/// After `emg plan` wrote a task's files: exports its joint trajectory when `--export` asks;
/// returns the lines to print.
pub fn after_plan(args: &PlanArgs, robot: &Robot, paths: &PlanPaths) -> Result<String> {
    let Some(format) = args.export else {
        return Ok(String::new());
    };
    let input = &paths.joint_trajectory;
    let trajectory = emg_io::read_joint_trajectory(input)?;
    let text = export_to(
        (&trajectory).into(),
        format,
        &plan_output(paths, format),
        &args.robot,
        robot,
        &ExportOptions {
            max_servoj_lines: args.max_servoj,
            ..ExportOptions::default()
        },
        ("joint trajectory", input),
    )
    .with_context(|| {
        format!(
            "--export {format}: the plan's files were written, the export was not ({} {} --format \
             {format} --out FILE exports them)",
            "emg export",
            input.display()
        )
    })?;
    Ok(format!("\n  export: {text}"))
}
