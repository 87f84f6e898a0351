//! `emg check PROGRAM.mod`: a RAPID module exported for the ABB IRB 120 read back against the
//! job's program it was exported from by the independent reader ([`emg_rapid_check`]), which
//! shares no code with the writer: every target solved by its own inverse kinematics from its
//! configuration data, the moves interpolated as the controller does.

use std::path::Path;

use anyhow::{Result, anyhow};

use super::exported::{Exported, print_drawn, require_shipped};
use crate::options::ChainArgs;
use crate::output::count;

/// Runs `emg check` on a RAPID module `file`: prints what was read and `OK`, or fails naming the
/// line and what the arm would do wrong there. `program` and `robot` are `--program` and
/// `--robot`, `chain` the chain's ends.
pub fn check_module(
    file: &Path,
    program: Option<&Path>,
    robot: Option<&Path>,
    chain: &ChainArgs,
) -> Result<()> {
    let exported = Exported::read(
        file,
        &file.with_extension("json"),
        program,
        robot,
        "RAPID module",
    )?;
    require_shipped(&exported, "irb120", "RAPID module")?;
    let Exported {
        text,
        job,
        program_path,
        robot_path,
    } = exported;
    let (_, model) = chain.robot_and_checker(&robot_path)?;
    let report = emg_rapid_check::read_rapid(&text, &job, &model)
        .map_err(|e| anyhow!("{} does not hold up: {e}", file.display()))?;
    println!(
        "{}: RAPID read back against {}, robot {}",
        file.display(),
        program_path.display(),
        robot_path.display()
    );
    println!(
        "  {} moves ({} MoveAbsJ, {} MoveL), {} declared; every target the plan's \
         configuration by its configuration data (within {:.1e} rad), targets at least {:.3} mm \
         apart; {} switched on and off where they start and end",
        report.move_abs_j + report.move_l,
        report.move_abs_j,
        report.move_l,
        count(report.declared_zones, "zone"),
        report.worst_target_rad,
        report.least_spacing_m * 1e3,
        count(report.drawn.stroke_parts, "stroke part"),
    );
    print_drawn(&report.drawn, &job);
    Ok(())
}
