//! `emg export`: a joint trajectory or a job's program, read from its file, written for a robot's
//! own stack.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use emg_io::{ExportFormat, ExportOptions};

use crate::exporting::{self, ExportTarget, UrScriptArgs, UrScriptForm, export_job, export_to};
use crate::program::read_job_file;
use crate::robot;

/// Options of `emg export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The motion to export: a joint trajectory (`STEM.joint_trajectory.json`,
    /// emg-joint-trajectory/2) or a job's program (emg-job/3).
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// `ros2-mcap` (trajectory_msgs/msg/JointTrajectory in an MCAP file), `urscript` (a
    /// program for a Universal Robots e-Series controller; six-joint UR arms only), `rapid`
    /// (a module for an ABB controller; a job's program on a six-joint ABB arm only) or `krl`
    /// (a KUKA controller's program, OUT the `.src` named as KRL names programs, its `.dat`
    /// beside it; a job's program on a six-joint KUKA arm only).
    #[arg(long, value_name = "FORMAT", value_parser = exporting::parse_format)]
    pub format: ExportFormat,
    /// The file to write (a URScript motion too long for one program is split where the arm
    /// rests: OUT without its extension, with -part1.script, -part2.script, ...; missing parent directories
    /// are created).
    #[arg(long, value_name = "PATH")]
    pub out: PathBuf,
    /// Robot: a shipped robot's name (`fr3`, `iiwa14`, `ur5e`, `irb120`, `kr16`) or a robot file (URDF). Default:
    /// the file's `robot` field.
    #[arg(long, value_name = "NAME|URDF", value_parser = robot::parse_robot)]
    pub robot: Option<PathBuf>,
    /// ros2-mcap: the largest joint deviation (rad) of the controller's quintic spline through
    /// the points kept from any sample of the file.
    #[arg(long, value_name = "RAD", default_value_t = ExportOptions::default().tolerance_rad)]
    pub thinning_tolerance: f64,
    /// How a URScript export is written.
    #[command(flatten)]
    pub urscript: UrScriptArgs,
}

/// Runs `emg export`: reads the file, resolves its robot, exports, and prints what it wrote.
pub fn run(args: &ExportArgs) -> Result<()> {
    let job = read_job_file(&args.file)?;
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
        None => robot::resolve(robot_field, &args.file)?,
    };
    let robot = robot::load_robot(&robot_file, None, None)?;
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
