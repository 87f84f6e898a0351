//! What job-eval records of a program written for an industrial controller (an ABB RAPID
//! module, a KUKA KRL program) and read back by its independent reader: the figures both
//! readers report, one row layout and one table's columns for both.

use emg_job::JobFile;
use emg_program_check::Drawn;
use serde::{Deserialize, Serialize};

/// One job's program read back: what every industrial reader reports.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ReadBack {
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
    /// Why the program was not written or not read back; `None` where it was.
    pub failure: Option<String>,
}

impl ReadBack {
    /// The record of `file` (the job `name`'s program): the reader's `worst_target_rad`,
    /// `least_spacing_m` and what it drew, or why it was not written or read.
    pub fn of(name: &str, file: &JobFile, read: anyhow::Result<(f64, f64, Drawn)>) -> Self {
        let mut row = Self {
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
        match read {
            Ok((worst_target_rad, least_spacing_m, drawn)) => {
                row.worst_target_rad = worst_target_rad;
                row.least_spacing_m = least_spacing_m;
                row.worst_deviation_m = drawn.worst_deviation_m;
                row.worst_tool_angle_deg = drawn.worst_tool_angle_deg;
                row.covered_m = drawn.covered_m;
                row.drawn_m = drawn.drawn_m;
            }
            Err(why) => row.failure = Some(format!("{name}: {why}")),
        }
        row
    }

    /// The table's header cells of these figures.
    pub const HEADER: &'static str = "worst target (rad) | least target spacing (mm) | worst \
         TCP deviation (mm) / tolerance | worst tool angle (°) / cone | covered / drawn (m) | \
         read back |";

    /// The table's cells of these figures, as [`ReadBack::HEADER`] names them.
    pub fn cells(&self) -> String {
        format!(
            "{:.1e} | {:.3} | {:.4} / {:.1} | {:.2} / {:.0} | {:.3} / {:.3} | {} |",
            self.worst_target_rad,
            self.least_spacing_m * 1e3,
            self.worst_deviation_m * 1e3,
            self.tolerance_m * 1e3,
            self.worst_tool_angle_deg,
            self.cone_deg,
            self.covered_m,
            self.drawn_m,
            self.failure.as_deref().map_or("yes", |_| "**no**"),
        )
    }
}
