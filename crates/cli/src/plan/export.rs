//! `emg plan --export`: each task's joint trajectory also written for a robot's own stack,
//! beside the task's files.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use emg_io::{ExportFormat, ExportOptions, PlanPaths};
use emg_kinematics::Robot;

use crate::exporting::{self, export_to, refuse_format};

/// The export options of `emg plan`.
#[derive(Debug, Args)]
pub struct PlanExportArgs {
    /// Also export each joint trajectory for a robot's own stack, as `emg export` does:
    /// `ros2-mcap` (STEM.mcap) or `urscript` (STEM.script).
    #[arg(long, value_name = "FORMAT", value_parser = exporting::parse_format)]
    pub export: Option<ExportFormat>,
    /// urscript: most servoj lines (2 ms each) per program.
    #[arg(long, value_name = "N", default_value_t = ExportOptions::default().max_servoj_lines)]
    pub max_servoj: usize,
}

impl PlanExportArgs {
    /// Refuses, before anything is planned, an `emg plan --export` that cannot be done: URScript
    /// for a robot that is not a Universal Robots arm, or an output replacing an input. The
    /// robot is `robot`, read from `robot_file`; `out` is `--out`, the tasks' files named with
    /// `indices`.
    pub fn refuse(
        &self,
        robot_file: &Path,
        robot: &Robot,
        out: &Path,
        indices: &[Option<usize>],
    ) -> Result<()> {
        let Some(format) = self.export else {
            return Ok(());
        };
        refuse_format(format, robot_file, robot)
            .context("--export urscript: nothing was planned or written")?;
        let outputs: Vec<PathBuf> = indices
            .iter()
            .map(|&index| beside_task(&PlanPaths::new(out, index), format))
            .collect();
        let outputs: Vec<(&str, &Path)> =
            outputs.iter().map(|p| ("--export", p.as_path())).collect();
        Ok(emg_io::refuse_overwriting(
            &[("--robot", robot_file)],
            &outputs,
        )?)
    }

    /// After `emg plan` wrote a task's files `paths`: exports its joint trajectory when
    /// `--export` asks, for `robot`, read from `robot_file`; returns the lines to print.
    pub fn after_plan(
        &self,
        robot_file: &Path,
        robot: &Robot,
        paths: &PlanPaths,
    ) -> Result<String> {
        let Some(format) = self.export else {
            return Ok(String::new());
        };
        let input = &paths.joint_trajectory;
        let trajectory = emg_io::read_joint_trajectory(input)?;
        let text = export_to(
            (&trajectory).into(),
            format,
            &beside_task(paths, format),
            robot_file,
            robot,
            &ExportOptions {
                max_servoj_lines: self.max_servoj,
                ..ExportOptions::default()
            },
            ("joint trajectory", input),
        )
        .with_context(|| {
            format!(
                "--export {format}: the plan's files were written, the export was not ({} {} \
                 --format {format} --out FILE exports them)",
                "emg export",
                input.display()
            )
        })?;
        Ok(format!("\n  export: {text}"))
    }
}

/// The file `emg plan --export` writes beside a task's files: `STEM.mcap` or `STEM.script`.
fn beside_task(paths: &PlanPaths, format: ExportFormat) -> PathBuf {
    paths.json.with_extension(format.extension())
}
