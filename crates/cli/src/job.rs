//! `emg job`: a job file or an SVG drawing planned as one program (`emg_job::plan_job`), with a
//! progress bar and a summary; writes the `emg-job/3` file.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use emg_job::JobPlanError;

use crate::exporting;
use crate::interrupt::{Interrupt, Watched};
use crate::job_input::{JobInput, Ready};
use crate::output::{progress_bar, write_text};
use crate::program::{ProgramOutput, write_program};

/// Options of `emg job`.
#[derive(Debug, Args)]
pub struct JobArgs {
    /// The job and how it is planned.
    #[command(flatten)]
    pub input: JobInput,
    /// The program to write (an emg-job/3 file; missing parent directories are created).
    #[arg(long, value_name = "FILE", default_value = "job.json")]
    pub out: PathBuf,
    /// Also export the program for a robot's own stack: `ros2-mcap`, `urscript`, `rapid` (an
    /// ABB controller's module) or `krl` (a KUKA controller's `.src` and `.dat`), written beside
    /// `--out` (its extension `.mcap`, `.script` or `.mod`; a KRL program named as KRL allows,
    /// `house.job.json` → `house.src`; see docs/robot-export.md).
    #[arg(long, value_name = "FORMAT", value_parser = exporting::parse_format)]
    pub export: Option<emg_io::ExportFormat>,
    /// How a URScript export is written.
    #[command(flatten)]
    pub urscript: exporting::UrScriptArgs,
    /// Also write the program's viewer page (self-contained HTML): the arm playing the whole
    /// program, every stroke on the part (drawn stretches solid, the rest faint), the pen-up
    /// moves dashed, the segment under way named.
    #[arg(long, value_name = "FILE")]
    pub html: Option<PathBuf>,
}

/// Reads the job, plans it, prints its summary and writes its program; `interrupt` stops the
/// planning, and then nothing is written.
pub fn run(args: &JobArgs, interrupt: &Interrupt) -> Result<()> {
    let input = &args.input;
    let program = ProgramOutput::new(&args.out, args.export, &args.urscript);
    program.refuse(
        input,
        &[program.exported(), ("--html", args.html.as_deref())],
    )?;
    let Ready { job, planner } = input.ready()?;
    let watch = Watched::new(progress_bar(job.strokes.len() as u64, "strokes"), interrupt);
    let planned = planner.plan(&job, &watch);
    let file = watch.outcome(planned, |e| matches!(e, JobPlanError::Stopped(_)))?;
    write_program(&file, &program, &input.robot, planner.robot())?;
    if let Some(path) = &args.html {
        write_text(
            path,
            &emg_job::viewer_page(
                &file,
                &job,
                planner.robot(),
                &input
                    .file
                    .file_stem()
                    .unwrap_or(input.file.as_os_str())
                    .to_string_lossy(),
            ),
        )?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
