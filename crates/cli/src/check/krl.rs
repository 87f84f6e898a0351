//! `emg check PROGRAM.src`: a KRL program exported for the KUKA KR 16-2 (the `.src` and the
//! `.dat` beside it) read back against the job's program it was exported from by the
//! independent reader ([`emg_krl_check`]), which shares no code with the writer: every target
//! solved by its own inverse kinematics from its Status and Turn, the moves run as the
//! controller runs them.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};

use super::exported::{Exported, print_drawn, require_shipped};
use crate::options::ChainArgs;
use crate::output::count;

/// The job's program a KRL program `file` was written beside: `STEM.job.json` where there is
/// one, else the one job's program in its folder whose KRL program `--export krl` names so
/// (`pen-drag-house.job.json` → `pen_drag_house.src`).
fn job_beside(file: &Path) -> PathBuf {
    let beside = file.with_extension("job.json");
    if beside.exists() {
        return beside;
    }
    let folder = file
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let named_so: Vec<PathBuf> = std::fs::read_dir(folder)
        .into_iter()
        .flatten()
        .flatten()
        .map(|entry| entry.path())
        .filter(|path| path.extension().is_some_and(|e| e == "json"))
        .filter(|path| emg_job::krl_program::krl_path_beside(path).file_name() == file.file_name())
        .collect();
    match named_so.as_slice() {
        [only] => only.clone(),
        _ => beside,
    }
}

/// Runs `emg check` on a KRL program `file`: prints what was read and `OK`, or fails naming the
/// line and what the arm would do wrong there. `program` and `robot` are `--program` and
/// `--robot`, `chain` the chain's ends.
pub fn check_program(
    file: &Path,
    program: Option<&Path>,
    robot: Option<&Path>,
    chain: &ChainArgs,
) -> Result<()> {
    let exported = Exported::read(file, &job_beside(file), program, robot, "KRL program")?;
    require_shipped(&exported, "kr16", "KRL program")?;
    let Exported {
        text,
        job,
        program_path,
        robot_path,
    } = exported;
    let dat_path = file.with_extension("dat");
    let dat = std::fs::read_to_string(&dat_path).with_context(|| {
        format!(
            "a KRL program's points are in the .dat beside its .src: cannot read {}",
            dat_path.display()
        )
    })?;
    let (_, model) = chain.robot_and_checker(&robot_path)?;
    let report = emg_krl_check::read_krl(&text, &dat, &job, &model)
        .map_err(|e| anyhow!("{} does not hold up: {e}", file.display()))?;
    let drawn = &report.drawn;
    println!(
        "{}: KRL read back against {}, robot {}",
        file.display(),
        program_path.display(),
        robot_path.display()
    );
    println!(
        "  {} moves ({} PTP, {} LIN); every target the plan's configuration by its Status and \
         Turn (within {:.1e} rad), targets at least {:.3} mm apart; {} switched on and off \
         where they start and end",
        report.ptp + report.lin,
        report.ptp,
        report.lin,
        report.worst_target_rad,
        report.least_spacing_m * 1e3,
        count(drawn.stroke_parts, "stroke part"),
    );
    print_drawn(drawn, &job);
    Ok(())
}
