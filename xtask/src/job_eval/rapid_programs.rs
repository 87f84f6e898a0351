//! The IRB 120's job programs written as RAPID modules in memory, as `emg job --export rapid`
//! writes them (`emg_job::rapid_program`), and read back against the plan by the independent
//! reader `emg-rapid-check`.

use std::path::Path;

use emg_job::JobFile;
use emg_kinematics::Robot;
use emg_rapid_check::{RapidReport, read_rapid};
use emg_verify::ReferenceModel;
use serde::{Deserialize, Serialize};

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
    /// Largest distance (rad, any joint) of a target's solution by its configuration data from
    /// the plan's configuration.
    pub worst_target_rad: f64,
    /// Smallest distance (m) between consecutive Cartesian targets.
    pub least_spacing_m: f64,
    /// Largest distance (m) of the TCP from its stroke while the tool is on, as the reader
    /// interpolates the moves, and the tolerance.
    pub worst_deviation_m: f64,
    /// See `worst_deviation_m`.
    pub tolerance_m: f64,
    /// Largest angle (degrees) of the tool axis from its stroke's normal while the tool is on,
    /// and the cone.
    pub worst_tool_angle_deg: f64,
    /// See `worst_tool_angle_deg`.
    pub cone_deg: f64,
    /// Length (m) the TCP covers with the tool on, and the length the plan draws.
    pub covered_m: f64,
    /// See `covered_m`.
    pub drawn_m: f64,
    /// Why the module was not written or not read back; `None` where it was.
    pub failure: Option<String>,
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
    let mut row = RapidRow {
        job: name.to_string(),
        move_abs_j: 0,
        move_l: 0,
        declared_zones: 0,
        worst_target_rad: 0.0,
        least_spacing_m: 0.0,
        worst_deviation_m: 0.0,
        tolerance_m: file.constraints.line_tolerance_m,
        worst_tool_angle_deg: 0.0,
        cone_deg: file.constraints.theta_max_deg,
        covered_m: 0.0,
        drawn_m: 0.0,
        failure: None,
    };
    match module(arm, file) {
        Ok(report) => {
            row.move_abs_j = report.move_abs_j;
            row.move_l = report.move_l;
            row.declared_zones = report.declared_zones;
            row.worst_target_rad = report.worst_target_rad;
            row.least_spacing_m = report.least_spacing_m;
            row.worst_deviation_m = report.drawn.worst_deviation_m;
            row.worst_tool_angle_deg = report.drawn.worst_tool_angle_deg;
            row.covered_m = report.drawn.covered_m;
            row.drawn_m = report.drawn.drawn_m;
        }
        Err(why) => row.failure = Some(format!("{name}: {why}")),
    }
    row
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
    let read = rows.iter().filter(|r| r.failure.is_none()).count();
    let mut md = format!(
        "\n## RAPID modules\n\n\
         Each program above written as a RAPID module for the IRB 120, in memory (`emg job \
         --export rapid`: `MoveAbsJ` between strokes, `MoveL` runs with zones along them), and \
         read back by the independent reader (`emg-rapid-check`, which shares no code with the \
         writer) against the plan: every target solved by the arm's closed form \
         (`rs-opw-kinematics`) and its configuration data, the moves interpolated with each \
         zone's corner inside its triangle and at most half of either neighbouring line, every \
         configuration checked by the checker. **{read} of {} read back.**\n\n\
         | job | MoveAbsJ / MoveL | zones declared | worst target (rad) | least target spacing (mm) | worst TCP deviation (mm) / tolerance | worst tool angle (°) / cone | covered / drawn (m) | read back |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        rows.len()
    );
    for r in rows {
        md.push_str(&format!(
            "| {} | {} / {} | {} | {:.1e} | {:.3} | {:.4} / {:.1} | {:.2} / {:.0} | {:.3} / {:.3} | {} |\n",
            r.job,
            r.move_abs_j,
            r.move_l,
            r.declared_zones,
            r.worst_target_rad,
            r.least_spacing_m * 1e3,
            r.worst_deviation_m * 1e3,
            r.tolerance_m * 1e3,
            r.worst_tool_angle_deg,
            r.cone_deg,
            r.covered_m,
            r.drawn_m,
            r.failure.as_deref().map_or("yes", |_| "**no**"),
        ));
    }
    md
}
