//! The README's table of search shares (`cargo xtask report`): per shipped arm, the MoveIt-style
//! Cartesian path of `cartesian-eval`, the paper's pipeline and the search at `emg plan`'s
//! default budget of `search-eval`, as `Σ length / Σ bound` per bucket of the bound.

use std::path::Path;

use emg_eval::BoundShare;
use emg_planner::SearchConfig;

use crate::cartesian_eval;
use crate::results::{SummaryPlace, read, shipped_results};
use crate::search_eval::{Record, Row};

/// Markers of the README's table of search shares by bucket of the bound ([`shares_table`]).
const README_START: &str = "<!-- search-shares:start -->";
/// The end marker of that table.
const README_END: &str = "<!-- search-shares:end -->";

/// Where the table of search shares ([`shares_table`]) is shown: the README.
pub const SUMMARY: SummaryPlace = SummaryPlace {
    page: "README.md",
    start: README_START,
    end: README_END,
    intro: "## Long lines: the share of the bound\n\nΣ path length / Σ reachability bound over the \
         unseen tasks whose bound lies in each bucket (`cargo xtask search-eval`; \
         `docs/results/search.md` per budget):\n\n",
};

/// For every shipped arm with a `search.json` under `results` (the FR3's top-level, the
/// others' in their sub-directories), the pipeline and the search at the default budget:
/// `Σ length / Σ bound` per bucket of the bound, the tasks below half their bound and the mean
/// time per plan.
pub fn shares_table(results: &Path) -> anyhow::Result<String> {
    let mut md = String::from(
        "| arm | planner | < 0.5 m | 0.5 – 1 m | ≥ 1 m | all | below ½ bound | mean ms per plan |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for (shipped, record) in shipped_results::<Record>(results, "search.json")? {
        let cartesian = results.join(shipped.data_subdir()).join("cartesian.json");
        if cartesian.exists() {
            let baseline: cartesian_eval::Record = read(&cartesian)?;
            md += &share_row(
                shipped.name,
                "MoveIt-style Cartesian path",
                &baseline.bound_shares,
                baseline.task_count,
                baseline.mean_ms,
            );
        }
        let pipeline = record.rows.iter().find(|r| r.budget_steps.is_none());
        for row in pipeline.into_iter().chain(record.default_budget_row()) {
            md += &share_row(
                shipped.name,
                &row_name(row, &record.search),
                &row.bound_shares,
                record.task_count,
                row.plan_ms.mean,
            );
        }
    }
    Ok(md)
}

/// One row of [`shares_table`]: the arm, the planner, its shares per bucket, the tasks below
/// half their bound and the mean time per plan.
fn share_row(
    arm: &str,
    planner: &str,
    shares: &[BoundShare],
    tasks: usize,
    mean_ms: f64,
) -> String {
    let mut row = format!("| {arm} | {planner} |");
    for bucket in shares {
        row += &format!(" {:.3} |", bucket.share);
    }
    let below = shares.last().map_or(0, |all| all.below_half.len());
    row + &format!(" {below} of {tasks} | {mean_ms:.1} |\n")
}

/// A row's planner for tables: the pipeline, or the search (`config`) with its budget, the
/// steps its widened pass adds where a plan ends short of its bound, and its beam stage.
fn row_name(row: &Row, config: &SearchConfig) -> String {
    let Some(budget) = row.budget_steps else {
        return "Hybrid + DP (the paper's pipeline)".into();
    };
    let mut name = format!("search ({budget} steps");
    if config.widened_budget_steps > 0 {
        name += &format!(", + {} where short", config.widened_budget_steps);
    }
    if !config.far_end_shares.is_empty() {
        name += ", then from the far end";
    }
    if config.beam_width > 0 {
        name += &format!(", then a beam of {}", config.beam_width);
    }
    name + ")"
}
