//! The IRB 120's job programs written as RAPID modules in memory, as `emg job --export rapid`
//! writes them (`emg_job::rapid_program`), and read back against the plan by the independent
//! reader `emg-rapid-check`.

use std::path::Path;

use emg_job::JobFile;
use emg_kinematics::Robot;
use emg_rapid_check::{RapidReport, read_rapid};
use emg_verify::ReferenceModel;
use serde::{Deserialize, Serialize};

use super::industrial_programs::ReadBack;

/// One job's module on the IRB 120, read back.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RapidRow {
    /// The job, as its row names it.
    pub job: String,
    /// The module's `MoveAbsJ` and `MoveL` instructions.
    pub move_abs_j: usize,
    /// See `move_abs_j`.
    pub move_l: usize,
    /// Zones the module declares.
    pub declared_zones: usize,
    /// How it read back.
    #[serde(flatten)]
    pub read: ReadBack,
}

/// The IRB 120 as the module needs it.
pub struct RapidArm<'a> {
    /// Its kinematics.
    pub robot: &'a Robot,
    /// Its robot file.
    pub robot_file: &'a Path,
    /// The independent checker.
    pub checker: &'a ReferenceModel,
}

/// `file` (the job `name`'s program) written as a module and read back.
pub fn read_back(arm: &RapidArm<'_>, name: &str, file: &JobFile) -> RapidRow {
    let report = module(arm, file);
    let counts = report
        .as_ref()
        .map_or((0, 0, 0), |r| (r.move_abs_j, r.move_l, r.declared_zones));
    RapidRow {
        job: name.to_string(),
        move_abs_j: counts.0,
        move_l: counts.1,
        declared_zones: counts.2,
        read: ReadBack::of(
            name,
            file,
            report.map(|r| (r.worst_target_rad, r.least_spacing_m, r.drawn)),
        ),
    }
}

/// The module written and read back.
fn module(arm: &RapidArm<'_>, file: &JobFile) -> anyhow::Result<RapidReport> {
    let reference = arm.robot_file.display().to_string();
    let export = emg_job::rapid_program::rapid_program_export(
        file,
        arm.robot,
        &reference,
        Path::new("job.mod"),
    )?;
    let [(_, bytes)] = export.files.as_slice() else {
        anyhow::bail!("{} files, not one module", export.files.len());
    };
    Ok(read_rapid(std::str::from_utf8(bytes)?, file, arm.checker)?)
}

/// The section of `jobs.md`: per module what was written and how it read back.
pub fn markdown(rows: &[RapidRow]) -> String {
    let read = rows.iter().filter(|r| r.read.failure.is_none()).count();
    let mut md = format!(
        "\n## RAPID modules\n\n\
         Each program above (and the 500-stroke drawing's, on all threads) written as a \
         RAPID module for the IRB 120, in memory (`emg job \
         --export rapid`: `MoveAbsJ` between strokes, `MoveL` runs with zones along them), and \
         read back by the independent reader (`emg-rapid-check`, which shares no code with the \
         writer) against the plan: every target solved by the arm's closed form \
         (`rs-opw-kinematics`) and its configuration data, the moves interpolated with each \
         zone's corner inside its triangle and at most half of either neighbouring line, every \
         configuration checked by the checker. **{read} of {} read back.**\n\n\
         | job | MoveAbsJ / MoveL | zones declared | {}\n\
         |---|---|---|---|---|---|---|---|---|\n",
        rows.len(),
        ReadBack::HEADER
    );
    for r in rows {
        md.push_str(&format!(
            "| {} | {} / {} | {} | {}\n",
            r.job,
            r.move_abs_j,
            r.move_l,
            r.declared_zones,
            r.read.cells()
        ));
    }
    md
}
