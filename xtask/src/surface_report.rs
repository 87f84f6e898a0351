//! The work-surface section of `cargo xtask report` (not in the paper): Table 1 on the tasks a
//! real cell can pose, with the surface ignored and kept, and the whole evaluation set with it on.

use std::path::Path;

use emg_eval::{EvalRecord, MIN_REFERENCE_M, SetResult, four};
use emg_planner::ControllerKind;

use crate::results::{dp, read};

/// The three evaluations the section reads, by file name and the command that writes each.
const CELL_OFF: (&str, &str) = (
    "eval-cell-surface-off.json",
    "cargo xtask eval --surface-clearance 0.01 --name eval-cell-surface-off --seen-count 0",
);
const CELL_ON: (&str, &str) = (
    "eval-cell-surface-on.json",
    "cargo xtask eval --surface-clearance 0.01 --surface on --name eval-cell-surface-on --seen-count 0",
);
const ALL_ON: (&str, &str) = (
    "eval-surface-on.json",
    "cargo xtask eval --surface on --name eval-surface-on --seen-count 0",
);

/// The unseen set of one of the section's evaluations, or why it is missing.
fn unseen(results: &Path, (file, command): (&str, &str)) -> Result<(EvalRecord, usize), String> {
    let record: EvalRecord =
        read(&results.join(file)).map_err(|_| format!("`{file}` is missing (`{command}`)"))?;
    let index = record
        .sets
        .iter()
        .position(|s| s.name == "unseen")
        .ok_or_else(|| format!("`{file}` holds no unseen set (`{command}`)"))?;
    Ok((record, index))
}

/// Mean path length of Hybrid + DP over all tasks of `set`.
fn hybrid_mean(set: &SetResult) -> f64 {
    set.cell(dp(), ControllerKind::Hybrid, "all")
        .map_or(f64::NAN, |c| c.stats.length_m.mean)
}

/// The section's markdown.
pub fn section(results: &Path) -> String {
    let mut md = String::from(
        "## Beyond the paper: the work surface\n\nThe work surface of a task is the plane through \
         p0 with normal n, the material beyond it; only the pen may touch it (`docs/scene.md`). \
         The paper's protocol ignores it, and about a quarter of its tasks have the surface \
         cutting the arm already at q0_seed.\n\n",
    );
    let cell = unseen(results, CELL_OFF).and_then(|off| Ok((off, unseen(results, CELL_ON)?)));
    match cell {
        Ok(((off, i), (on, j))) => {
            let (off_set, on_set) = (&off.sets[i], &on.sets[j]);
            md += &format!(
                "**Table 1 on the tasks a cell can pose**: the {} of the 10,000 evaluation tasks \
                 whose work surface clears the arm (all but the pen) by {:.0} mm at q0_seed, DP \
                 seeds, with the surface ignored (`{}`) and kept at every step (`{}`). Each \
                 setting buckets the tasks by its own ℓ_ref (under the surface, a start must hold \
                 it too); ratios leave out the tasks whose ℓ_ref is under {:.0} cm.\n\n\
                 | tasks | π | surface off: path length (m) | ratio to ℓ_ref (%) | surface on: path length (m) | ratio to ℓ_ref (%) |\n\
                 |---|---|---|---|---|---|\n",
                off_set.task_count,
                off.surface_clearance_m.unwrap_or(f64::NAN) * 1e3,
                CELL_OFF.0,
                CELL_ON.0,
                MIN_REFERENCE_M * 100.0,
            );
            for group in ["all", "easy", "medium", "difficult"] {
                for controller in ControllerKind::ALL {
                    let (Some(a), Some(b)) = (
                        off_set.cell(dp(), controller, group),
                        on_set.cell(dp(), controller, group),
                    ) else {
                        continue;
                    };
                    md += &format!(
                        "| {group} (n = {} / {}) | {} | {} | {} | {} | {} |\n",
                        a.stats.length_m.count,
                        b.stats.length_m.count,
                        controller.name(),
                        four(&a.stats.length_m, 3),
                        four(&a.stats.ratio_percent, 1),
                        four(&b.stats.length_m, 3),
                        four(&b.stats.ratio_percent, 1),
                    );
                }
            }
            md += &format!(
                "\nKeeping the surface costs Hybrid + DP {:.1} % of its mean path length on these \
                 tasks ({:.3} m → {:.3} m).\n\n",
                100.0 * (1.0 - hybrid_mean(on_set) / hybrid_mean(off_set)),
                hybrid_mean(off_set),
                hybrid_mean(on_set),
            );
        }
        Err(why) => md += &format!("No cell rows: {why}.\n\n"),
    }
    match unseen(results, ALL_ON) {
        Ok((all, i)) => {
            let set = &all.sets[i];
            let count = |limit: f64| set.references_m.iter().filter(|r| **r < limit).count();
            md += &format!(
                "**All {} evaluation tasks with the surface on** (`{}`): Hybrid + DP {:.3} m mean \
                 path length; {} tasks have no labelled start that holds the surface (ℓ_ref = 0), \
                 {} none that gets {:.0} cm along the line. Every trajectory of the run (3 \
                 controllers × 4 seed sources, and the references) passed the independent \
                 checker, the work surface included.\n\n",
                set.task_count,
                ALL_ON.0,
                hybrid_mean(set),
                count(f64::MIN_POSITIVE),
                count(MIN_REFERENCE_M),
                MIN_REFERENCE_M * 100.0,
            );
        }
        Err(why) => md += &format!("No whole-set row: {why}.\n\n"),
    }
    md
}
