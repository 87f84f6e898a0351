//! The KR 16's job programs written as KRL programs in memory, as `emg job --export krl` writes
//! them (`emg_job::krl_program`), and read back against the plan by the independent reader
//! `emg-krl-check`.

use std::path::Path;

use emg_job::JobFile;
use emg_kinematics::Robot;
use emg_krl_check::{KrlReport, read_krl};
use emg_verify::ReferenceModel;
use nalgebra::Isometry3;
use serde::{Deserialize, Serialize};

use super::industrial_programs::ReadBack;

/// One job's KRL program on the KR 16, read back.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct KrlRow {
    /// The job, as its row names it.
    pub job: String,
    /// The program's `PTP` and `LIN` instructions.
    pub ptp: usize,
    /// See `ptp`.
    pub lin: usize,
    /// How it read back.
    #[serde(flatten)]
    pub read: ReadBack,
}

/// The KR 16 as the program needs it.
pub struct KrlArm<'a> {
    /// Its kinematics.
    pub robot: &'a Robot,
    /// Its robot file.
    pub robot_file: &'a Path,
    /// The TCP in its flange's (`tool0`'s) frame.
    pub tool_in_flange: Isometry3<f64>,
    /// The independent checker.
    pub checker: &'a ReferenceModel,
}

/// `file` (the job `name`'s program) written as a KRL program and read back.
pub fn read_back(arm: &KrlArm<'_>, name: &str, file: &JobFile) -> KrlRow {
    let report = program(arm, file);
    let counts = report.as_ref().map_or((0, 0), |r| (r.ptp, r.lin));
    KrlRow {
        job: name.to_string(),
        ptp: counts.0,
        lin: counts.1,
        read: ReadBack::of(
            name,
            file,
            report.map(|r| (r.worst_target_rad, r.least_spacing_m, r.drawn)),
        ),
    }
}

/// The program written and read back.
fn program(arm: &KrlArm<'_>, file: &JobFile) -> anyhow::Result<KrlReport> {
    let reference = arm.robot_file.display().to_string();
    let export = emg_job::krl_program::krl_program_export(
        file,
        arm.robot,
        &arm.tool_in_flange,
        &reference,
        Path::new("job.src"),
    )?;
    let [(_, src), (_, dat)] = export.files.as_slice() else {
        anyhow::bail!("{} files, not a .src and its .dat", export.files.len());
    };
    Ok(read_krl(
        std::str::from_utf8(src)?,
        std::str::from_utf8(dat)?,
        file,
        arm.checker,
    )?)
}

/// The section of `jobs.md`: per program what was written and how it read back.
pub fn markdown(rows: &[KrlRow]) -> String {
    let read = rows.iter().filter(|r| r.read.failure.is_none()).count();
    let mut md = format!(
        "\n## KRL programs\n\n\
         Each program above (and the 500-stroke drawing's, on all threads) written as a \
         KRL program for the KR 16, in memory (`emg job \
         --export krl`: `PTP` between strokes, `LIN` runs approximated by `C_DIS` along them), \
         and read back by the independent reader (`emg-krl-check`, which shares no code with \
         the writer) against the plan: every target solved by the arm's closed form \
         (`rs-opw-kinematics`) and its Status and Turn, every value as the controller holds it \
         (single precision), the moves interpolated with each approximated corner inside its \
         triangle and at most half of either neighbouring line, every configuration checked by \
         the checker. **{read} of {} read back.**\n\n\
         | job | PTP / LIN | {}\n\
         |---|---|---|---|---|---|---|---|\n",
        rows.len(),
        ReadBack::HEADER
    );
    for r in rows {
        md.push_str(&format!(
            "| {} | {} / {} | {}\n",
            r.job,
            r.ptp,
            r.lin,
            r.read.cells()
        ));
    }
    md
}
