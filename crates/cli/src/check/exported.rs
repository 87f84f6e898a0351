//! What `emg check` reads a controller's program against: the job's program it was exported
//! from, and that program's robot.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};

use crate::program::read_job_file;
use crate::robot;

/// A controller's program, with the job's program it was exported from and the robot file.
pub struct Exported {
    /// The controller's program's text.
    pub text: String,
    /// The job's program.
    pub job: emg_job::JobFile,
    /// Where it was read.
    pub program_path: PathBuf,
    /// The robot file: `--robot`, else the job's program's `robot` field.
    pub robot_path: PathBuf,
}

impl Exported {
    /// Reads the controller's program `file` (a `kind`), the job's program `program` (default
    /// `beside`) and resolves its robot (`robot`, else the program's own).
    pub fn read(
        file: &Path,
        beside: &Path,
        program: Option<&Path>,
        robot: Option<&Path>,
        kind: &str,
    ) -> Result<Self> {
        let text = std::fs::read_to_string(file)
            .with_context(|| format!("cannot read {}", file.display()))?;
        let program_path = program.map_or_else(|| beside.to_path_buf(), Path::to_path_buf);
        let job = read_job_file(&program_path)
            .with_context(|| {
                format!(
                    "a {kind} is read back against the job's program it was exported from: name \
                     it with --program JOB (default {})",
                    beside.display()
                )
            })?
            .ok_or_else(|| {
                anyhow!(
                    "{} is not a job's program (emg-job/3): name the one {} was exported from \
                     with --program JOB",
                    program_path.display(),
                    file.display()
                )
            })?;
        let robot_path = match robot {
            Some(path) => path.to_path_buf(),
            None => robot::resolve(&job.robot, &program_path)?,
        };
        Ok(Self {
            text,
            job,
            program_path,
            robot_path,
        })
    }
}

/// Refuses a controller's program (a `kind`) whose robot is not the shipped arm `name`, the one
/// whose closed form its reader solves.
pub fn require_shipped(exported: &Exported, name: &str, kind: &str) -> Result<()> {
    let shipped = emg_planner::ShippedRobot::by_path(&exported.robot_path, &robot::data_dir())
        .is_some_and(|shipped| shipped.name == name);
    anyhow::ensure!(
        shipped,
        "{} is a program for robot {}: {kind}s are read back for the shipped {name} only (its \
         closed-form kinematics)",
        exported.program_path.display(),
        exported.robot_path.display()
    );
    Ok(())
}

/// Prints what the arm drew as a reader ran a controller's program against `job`, then `OK`.
pub fn print_drawn(drawn: &emg_program_check::Drawn, job: &emg_job::JobFile) {
    let constraints = &job.constraints;
    println!(
        "  while the tool is on the TCP stays within {:.3} mm of its stroke (line {} mm) and the \
         tool axis within {:.1}° of its normal (cone {}°); {} configurations checked, clear of \
         the arm and the part (least self-clearance {:.1} mm)",
        drawn.worst_deviation_m * 1e3,
        constraints.line_tolerance_m * 1e3,
        drawn.worst_tool_angle_deg,
        constraints.theta_max_deg,
        drawn.samples,
        drawn.least_clearance_m * 1e3,
    );
    println!(
        "  the strokes covered {:.4} m of the {:.4} m the program draws",
        drawn.covered_m, drawn.drawn_m
    );
    println!("OK");
}
