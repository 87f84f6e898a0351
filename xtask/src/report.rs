//! `cargo xtask report`: regenerates `docs/results.md` from the result files of `eval` and
//! `ablate`, beside the paper's numbers (`data/paper/tables.json`), with its figures. Every file
//! is read into its typed record.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use emg_control::{Task, Trajectory, rollout};
use emg_eval::{
    BucketConfig, CellStats, EvalRecord, SetResult, Setup, bucket_members, cell_stats, four,
};
use emg_hybrid::count_switches;
use emg_io::read_tasks;
use emg_planner::{
    ControllerKind, Executor, SHIPPED_ROBOTS, SearchConfig, SeedSource, ShippedRobot,
};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use serde::Deserialize;

use crate::ablate_control::{SwitchingAblation, WeightsAblation};
use crate::results::{dp, read};
use crate::search_eval::{self, BUDGET_FIGURE};
use crate::{
    figure, gap_eval, limit, path_eval, precision_eval, protocol, search_shares, surface_report,
    timing, workspace,
};

/// Options of `report`.
#[derive(clap::Args)]
pub struct Args {
    /// Directory holding the result files.
    #[arg(long, default_value_os_t = workspace::results_dir())]
    results: PathBuf,
    /// The report to write.
    #[arg(long, default_value_os_t = workspace::root().join("docs/results.md"))]
    out: PathBuf,
    /// Directory of the figures.
    #[arg(long, default_value_os_t = workspace::root().join("docs/figures"))]
    figures: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
}

/// `[mean, std, min, max]` as the paper's tables give them.
type Four = [f64; 4];

/// The paper's tables, transcribed once (`data/paper/tables.json`).
#[derive(Deserialize)]
struct PaperTables {
    /// Table 1: by bucket, by controller, `[length, ratio]`.
    table1: BTreeMap<String, BTreeMap<String, [Four; 2]>>,
    /// Table 1's task count per bucket.
    table1_counts: BTreeMap<String, usize>,
    /// Table 2: by controller, by seed, `(t_ms, length, ratio)`.
    table2: BTreeMap<String, BTreeMap<String, (f64, Four, Four)>>,
    /// Table 3's representative rows.
    table3: Vec<PaperGains>,
    /// Table 4: guidance scales.
    table4: Vec<PaperDpRow>,
    /// Table 5: DDIM steps.
    table5: Vec<PaperDpRow>,
    /// Table 6: switch thresholds.
    table6: Vec<PaperSwitchRow>,
}

/// A row of the paper's Table 3.
#[derive(Deserialize)]
struct PaperGains {
    k_mu: f64,
    k_jl: f64,
    k_theta: f64,
    length: Four,
    ratio: Four,
}

/// A row of the paper's Tables 4 and 5.
#[derive(Deserialize)]
struct PaperDpRow {
    /// The guidance scale `w` or the DDIM step count.
    #[serde(alias = "w", alias = "steps")]
    value: f64,
    t_ms: f64,
    length: Four,
    ratio: Four,
}

/// A row of the paper's Table 6.
#[derive(Deserialize)]
struct PaperSwitchRow {
    tau_enter: f64,
    tau_exit: f64,
    switches: f64,
    length: Four,
    ratio: Four,
}

/// `mean / std / min / max` of one of the paper's entries.
fn paper_four(values: &Four, decimals: usize) -> String {
    values
        .iter()
        .map(|v| format!("{v:.decimals$}"))
        .collect::<Vec<_>>()
        .join(" / ")
}

/// Writes the report and its figures.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let paper: PaperTables = read(&workspace::root().join("data/paper/tables.json"))?;
    let eval: EvalRecord = read(&args.results.join("eval.json"))?;
    std::fs::create_dir_all(&args.figures)?;
    let unseen = eval
        .set("unseen")
        .context("eval.json lacks the unseen set")?;
    let mut md = String::from(
        "# Results\n\nWritten by `cargo xtask report` from the files in `docs/results/` (themselves written by \
         `cargo xtask eval` and `cargo xtask ablate …`) and the paper's tables (`data/paper/tables.json`). \
         Do not edit by hand. Ours: FR3 with pen, 10,000 evaluation tasks never seen in training; every \
         trajectory behind every table passed the independent constraint checker.\n\n",
    );
    let search = SearchRows::read(
        &args.results,
        &args.figures,
        SHIPPED_ROBOTS[0],
        unseen,
        &eval.buckets,
    )?;
    md += &table1(unseen, &paper, &search);
    md += &table2(unseen, &paper, &search);
    md += &figures(args, unseen)?;
    md += &table3(&args.results, &paper)?;
    md += &included(
        &args.results,
        "ablate-cfg-scale.md",
        "Table 4: guidance scale",
        &paper.table4,
        "w",
    )?;
    md += &included(
        &args.results,
        "ablate-ddim-steps.md",
        "Table 5: DDIM steps",
        &paper.table5,
        "steps",
    )?;
    md += &table6(&args.results, &paper)?;
    if let Some(seen) = eval.set("seen") {
        md += &format!(
            "## Seen tasks\n\nThe same DP-seed rows on {} tasks of the training pool (seen in training):\n\n",
            seen.task_count
        );
        md += &dp_rows(seen, "all");
    }
    md += &velocity_limits(&args.results)?;
    md += &surface_report::section(&args.results);
    md += &other_arms(&args.results, &args.figures)?;
    let summaries = [
        (
            &search_shares::SUMMARY,
            search_shares::shares_table(&args.results)?,
        ),
        (&timing::SUMMARY, timing::plan_times_table(&args.results)?),
        (
            &precision_eval::SUMMARY,
            precision_eval::readme_table(&args.results)?,
        ),
        (&gap_eval::SUMMARY, gap_eval::report_table(&args.results)?),
    ];
    let [shares, plan_times, precision, gaps] = &summaries;
    md += &shares.0.section(&shares.1);
    md += &plan_times.0.section(&plan_times.1);
    md += &path_eval::report_section(&args.results)?;
    md += &precision.0.section(&precision.1);
    md += &gaps.0.section(&gaps.1);
    emg_io::write_atomically(&args.out, md)?;
    println!("wrote {}", args.out.display());
    if args.results == workspace::root().join("docs/results") {
        for (place, table) in &summaries {
            place.copy_to_page(table)?;
        }
        println!(
            "wrote the table of search shares into README.md and those of plan times, precision \
             and loose bounds into {}",
            workspace::RESULTS_SUMMARY
        );
    }
    Ok(())
}

fn dp_rows(set: &SetResult, group: &str) -> String {
    let mut md = String::from("| π | path length (m) | ratio to ℓ_ref (%) |\n|---|---|---|\n");
    for cell in set.cells(dp(), group) {
        md += &format!(
            "| {} | {} | {} |\n",
            cell.controller.name(),
            four(&cell.stats.length_m, 3),
            four(&cell.stats.ratio_percent, 1)
        );
    }
    md + "\n"
}

/// Mean path length of `controller` from DP seeds over all tasks of `set`.
fn dp_mean(set: &SetResult, controller: ControllerKind) -> f64 {
    set.cell(dp(), controller, "all")
        .map_or(f64::NAN, |c| c.stats.length_m.mean)
}

/// The search planner's rows of Tables 1 and 2 (not in the paper): its default-budget run of
/// `cargo xtask search-eval` over the same tasks as the unseen set, bucketed by the same ℓ_ref.
enum SearchRows {
    /// `search.json` covers the unseen set.
    Present {
        /// The step budget.
        budget_steps: u64,
        /// Statistics per task group (`all` and each bucket).
        groups: BTreeMap<String, CellStats>,
        /// CPU time per task (ms, this machine).
        cpu_ms_per_task: f64,
        /// Mean length / Hybrid + DP's mean length on the same tasks.
        ratio_to_pipeline: f64,
        /// Task mean of length / reachability bound.
        share_of_bound: f64,
        /// Plans the checker rejected.
        checker_failures: usize,
        /// Task mean of length / ℓ* over the limit subset (`limit.json`), when present.
        share_of_limit: Option<f64>,
        /// Link (relative to `docs/`) to the mean length against budget figure, when written.
        budget_figure: Option<PathBuf>,
    },
    /// Why there are no Search rows.
    Missing(String),
}

/// The "All" row of `limit.json` (`cargo xtask limit --merge`), and the settings it was made
/// with.
#[derive(Deserialize)]
struct LimitFile {
    identity: LimitIdentity,
    rows: Vec<LimitRow>,
}

/// The search settings a `limit.json` was made with, as written: a setting the file lacks
/// (one added since) makes it another search's, not today's default.
#[derive(Deserialize)]
struct LimitIdentity {
    limit: serde_json::Value,
    search: serde_json::Value,
}

impl LimitIdentity {
    /// Whether the limit's searches are today's: its own settings and the default search's.
    fn is_current(&self) -> bool {
        let today = |config: SearchConfig| serde_json::to_value(config).ok();
        Some(&self.limit) == today(limit::limit_search()).as_ref()
            && Some(&self.search) == today(SearchConfig::default()).as_ref()
    }
}

/// One bucket of `limit.json`.
#[derive(Deserialize)]
struct LimitRow {
    bucket: String,
    search_share_of_limit: f64,
}

impl SearchRows {
    /// Reads `robot`'s `search.json` (and `limit.json`) from its directory under `results`, and
    /// looks for its budget figure under `figures` (`docs/figures`).
    fn read(
        results: &Path,
        figures: &Path,
        robot: ShippedRobot,
        set: &SetResult,
        buckets: &BucketConfig,
    ) -> anyhow::Result<Self> {
        let results = results.join(robot.data_subdir());
        // The `cargo xtask search-eval` arguments that select `robot` (none for the default).
        let robot_flag = if robot == SHIPPED_ROBOTS[0] {
            String::new()
        } else {
            format!(" --robot {}", robot.name)
        };
        let path = results.join("search.json");
        if !path.exists() {
            return Ok(Self::Missing(format!(
                "no `search.json`: run `cargo xtask search-eval{robot_flag} --tasks {}`",
                set.task_count
            )));
        }
        let record: search_eval::Record = read(&path)?;
        if record.tasks != set.tasks || record.task_count != set.task_count {
            return Ok(Self::Missing(format!(
                "`search.json` covers the first {} tasks of `{}`, not the {} of `{}`: run `cargo \
                 xtask search-eval{robot_flag} --tasks {}`",
                record.task_count, record.tasks, set.task_count, set.tasks, set.task_count
            )));
        }
        let Some(row) = record.default_budget_row() else {
            return Ok(Self::Missing(format!(
                "`search.json` lacks the default budget: run `cargo xtask search-eval{robot_flag}` \
                 with it"
            )));
        };
        let references = &set.references_m;
        let all: Vec<usize> = (0..references.len()).collect();
        let mut groups = BTreeMap::new();
        let members = std::iter::once(("all".to_string(), all)).chain(
            bucket_members(references, buckets)
                .into_iter()
                .map(|(bucket, members)| (bucket.name().to_lowercase(), members)),
        );
        for (group, members) in members {
            if let Some(stats) = cell_stats(&row.lengths_m, references, &members) {
                groups.insert(group, stats);
            }
        }
        let limit_path = results.join("limit.json");
        let share_of_limit = if limit_path.exists() {
            let limit: LimitFile = read(&limit_path)?;
            // A limit made with other search settings says nothing of today's search.
            limit
                .rows
                .iter()
                .find(|r| r.bucket == "All" && limit.identity.is_current())
                .map(|r| r.search_share_of_limit)
        } else {
            None
        };
        let figure = Path::new(robot.data_subdir()).join(BUDGET_FIGURE);
        let budget_figure = figures
            .join(&figure)
            .exists()
            .then(|| Path::new("figures").join(figure));
        Ok(Self::Present {
            budget_steps: row.budget_steps.unwrap_or_default(),
            groups,
            cpu_ms_per_task: row.cpu_ms_per_task,
            ratio_to_pipeline: row.ratio_to_pipeline,
            share_of_bound: row.share_of_bound,
            checker_failures: row.checker_failures,
            share_of_limit,
            budget_figure,
        })
    }

    /// The budget and the statistics of task group `group` (`all` or a bucket), when present.
    fn group(&self, group: &str) -> Option<(u64, &CellStats)> {
        match self {
            Self::Present {
                budget_steps,
                groups,
                ..
            } => groups.get(group).map(|stats| (*budget_steps, stats)),
            Self::Missing(_) => None,
        }
    }

    /// The sentence under a Table 1 that has Search rows: the search against Hybrid + DP, or why
    /// there are no rows.
    fn summary(&self) -> String {
        match self {
            Self::Present {
                groups,
                ratio_to_pipeline,
                share_of_bound,
                checker_failures,
                share_of_limit,
                budget_figure,
                ..
            } => format!(
                "Search vs Hybrid + DP: **×{ratio_to_pipeline:.3}** mean path length (goal ≥ ×1.35); \
                 it reaches **{:.1} %** of ℓ_ref on average, {:.1} % of the reachability bound{}; \
                 {checker_failures} checker failures.\n\n{}",
                groups.get("all").map_or(f64::NAN, |s| s.ratio_percent.mean),
                100.0 * share_of_bound,
                share_of_limit.map_or(String::new(), |s| format!(
                    " and {:.1} % of the best-known length ℓ* on the 1,000-task subset of `cargo xtask limit`",
                    100.0 * s
                )),
                budget_figure.as_ref().map_or(String::new(), |link| format!(
                    "![search budget]({})\n\n*Σ length / Σ reachability bound of the search \
                     planner against its step budget, per bucket of the bound and over all tasks, \
                     beside Hybrid + DP (`cargo xtask search-eval`).*\n\n",
                    link.display()
                )),
            ),
            Self::Missing(why) => format!("No search rows: {why}.\n\n"),
        }
    }
}

fn table1(set: &SetResult, paper: &PaperTables, search: &SearchRows) -> String {
    let mut md = String::from(
        "## Table 1: three controllers from DP seeds, by difficulty\n\n\
         The search rows (not in the paper) are the search planner of `emg plan` at its default \
         budget, from its own starts (`cargo xtask search-eval`).\n\n\
         | tasks | π | ours: path length (m) | paper | ours: ratio to ℓ_ref (%) | paper |\n|---|---|---|---|---|---|\n",
    );
    for group in ["all", "easy", "medium", "difficult"] {
        for cell in set.cells(dp(), group) {
            let controller = cell.controller.name();
            let theirs = &paper.table1[group][controller];
            md += &format!(
                "| {group} (ours n = {}, paper n = {}) | {controller} | {} | {} | {} | {} |\n",
                cell.stats.length_m.count,
                paper.table1_counts[group],
                four(&cell.stats.length_m, 3),
                paper_four(&theirs[0], 2),
                four(&cell.stats.ratio_percent, 1),
                paper_four(&theirs[1], 1)
            );
        }
        if let Some((budget_steps, stats)) = search.group(group) {
            md += &format!(
                "| {group} (ours n = {}, paper n = {}) | search ({budget_steps} steps) | {} | — | {} | — |\n",
                stats.length_m.count,
                paper.table1_counts[group],
                four(&stats.length_m, 3),
                four(&stats.ratio_percent, 1),
            );
        }
    }
    let ratio = set
        .cell(dp(), ControllerKind::Hybrid, "all")
        .map_or(f64::NAN, |c| c.stats.ratio_percent.mean);
    let classical = dp_mean(set, ControllerKind::Classical);
    md += &format!(
        "\nHybrid + DP vs Classical + DP: **{:+.1} %** mean path length (paper +27 %, goal ≥ +35 %); \
         Hybrid + DP reaches **{ratio:.1} %** of ℓ_ref on average (paper 90.6 %, goal ≥ 92 %). \
         RL + DP vs Classical + DP: {:+.1} %.\n\n",
        100.0 * (dp_mean(set, ControllerKind::Hybrid) / classical - 1.0),
        100.0 * (dp_mean(set, ControllerKind::Rl) / classical - 1.0),
    );
    md += &search.summary();
    md
}

/// The velocity-limit comparisons (`eval --compare-velocity-limits`) of every shipped robot.
fn velocity_limits(results: &Path) -> anyhow::Result<String> {
    let mut md = String::from(
        "## Beyond the paper: joint-velocity limits\n\nThe paper's runs ignore the joint-velocity \
         limits; ours honour them by time scaling (a too-fast step keeps its shape and lasts longer).\n\n",
    );
    for robot in SHIPPED_ROBOTS {
        let file = Path::new(robot.data_subdir()).join("velocity-limits.md");
        let text = std::fs::read_to_string(results.join(&file)).with_context(|| {
            format!(
                "reading docs/results/{} (run `cargo xtask eval --robot {} --compare-velocity-limits`)",
                file.display(),
                robot.name
            )
        })?;
        let body: Vec<&str> = text.lines().filter(|l| l.starts_with('|')).collect();
        md += &format!(
            "`{}` (`docs/results/{}`):\n\n{}\n\n",
            robot.name,
            file.display(),
            body.join("\n")
        );
    }
    Ok(md)
}

/// Table 1 of every shipped robot other than the FR3, from its own `eval.json`.
fn other_arms(results: &Path, figures: &Path) -> anyhow::Result<String> {
    let mut md = String::new();
    for &robot in &SHIPPED_ROBOTS[1..] {
        let file = Path::new(robot.data_subdir()).join("eval.json");
        let eval: EvalRecord = read(&results.join(&file))
            .with_context(|| format!("run `cargo xtask eval --robot {}` first", robot.name))?;
        let unseen = eval
            .set("unseen")
            .with_context(|| format!("docs/results/{} lacks the unseen set", file.display()))?;
        md += &format!(
            "## Shipped arm `{}`, Table 1\n\nThe whole pipeline on this shipped arm (its own task sets, labels, \
             diffusion seeder and policy; `docs/results/{}`), {} unseen tasks; the search rows are the \
             search planner of `emg plan` at its default budget (`cargo xtask search-eval --robot {}`):\n\n\
             | tasks | π | path length (m) | ratio to ℓ_ref (%) |\n|---|---|---|---|\n",
            robot.name,
            file.display(),
            unseen.task_count,
            robot.name
        );
        let search = SearchRows::read(results, figures, robot, unseen, &eval.buckets)?;
        for group in ["all", "easy", "medium", "difficult"] {
            for cell in unseen.cells(dp(), group) {
                md += &format!(
                    "| {group} (n = {}) | {} | {} | {} |\n",
                    cell.stats.length_m.count,
                    cell.controller.name(),
                    four(&cell.stats.length_m, 3),
                    four(&cell.stats.ratio_percent, 1)
                );
            }
            if let Some((budget_steps, stats)) = search.group(group) {
                md += &format!(
                    "| {group} (n = {}) | search ({budget_steps} steps) | {} | {} |\n",
                    stats.length_m.count,
                    four(&stats.length_m, 3),
                    four(&stats.ratio_percent, 1)
                );
            }
        }
        let classical = dp_mean(unseen, ControllerKind::Classical);
        md += &format!(
            "\nHybrid + DP vs Classical + DP: **{:+.1} %** mean path length; RL + DP vs Classical + DP: {:+.1} %.\n\n",
            100.0 * (dp_mean(unseen, ControllerKind::Hybrid) / classical - 1.0),
            100.0 * (dp_mean(unseen, ControllerKind::Rl) / classical - 1.0),
        );
        md += &search.summary();
    }
    Ok(md)
}

fn table2(set: &SetResult, paper: &PaperTables, search: &SearchRows) -> String {
    let mut md = String::from(
        "## Table 2: seeds × controllers (all tasks)\n\nt = mean per-task seed time on this machine (ms; the paper's on its own hardware); \
         for the search row, its whole planning time (CPU ms per task: its starts, their rollouts and repairs).\n\n\
         | π | q₀* | ours t (ms) | paper t | ours: path length (m) | paper | ours: ratio (%) | paper |\n|---|---|---|---|---|---|---|---|\n",
    );
    for controller in ControllerKind::ALL {
        for seed in &emg_eval::PROTOCOL_SEEDS {
            let Some(cell) = set.cell(seed.name(), controller, "all") else {
                continue;
            };
            let theirs = paper.table2[controller.name()].get(seed.name());
            let time = set
                .seed_time_ms
                .get(seed.title())
                .map_or(f64::NAN, |t| t.mean);
            md += &format!(
                "| {} | {} | {time:.2} | {} | {} | {} | {} | {} |\n",
                controller.title(),
                seed.title(),
                theirs.map_or("—".into(), |t| format!("{:.2}", t.0)),
                four(&cell.stats.length_m, 3),
                theirs.map_or("—".into(), |t| paper_four(&t.1, 2)),
                four(&cell.stats.ratio_percent, 1),
                theirs.map_or("—".into(), |t| paper_four(&t.2, 1))
            );
        }
    }
    if let SearchRows::Present {
        groups,
        cpu_ms_per_task,
        budget_steps,
        ..
    } = search
        && let Some(stats) = groups.get("all")
    {
        md += &format!(
            "| Search ({budget_steps} steps) | its own starts | {cpu_ms_per_task:.2} | — | {} | — | {} | — |\n",
            four(&stats.length_m, 3),
            four(&stats.ratio_percent, 1),
        );
    }
    md + "\n"
}

fn table3(results: &Path, paper: &PaperTables) -> anyhow::Result<String> {
    let ours: WeightsAblation = read(&results.join("ablate-classical-weights.json"))?;
    let mut md = String::from(
        "## Table 3: classical secondary-objective weights (from q0_seed)\n\nOurs (all 39 settings):\n\n\
         | k_μ | k_jl | k_θ | path length (m) | ratio to ℓ_ref (%) |\n|---|---|---|---|---|\n",
    );
    for row in &ours.rows {
        let s = &row.setting;
        md += &format!(
            "| {:?} | {:?} | {:?} | {} | {} |\n",
            s.k_mu,
            s.k_jl,
            s.k_theta,
            four(&row.stats.length_m, 3),
            four(&row.stats.ratio_percent, 1)
        );
    }
    md += "\nPaper (representative rows):\n\n| k_μ | k_jl | k_θ | path length (m) | ratio (%) |\n|---|---|---|---|---|\n";
    for row in &paper.table3 {
        md += &format!(
            "| {:?} | {:?} | {:?} | {} | {} |\n",
            row.k_mu,
            row.k_jl,
            row.k_theta,
            paper_four(&row.length, 2),
            paper_four(&row.ratio, 1)
        );
    }
    Ok(md + "\n")
}

fn included(
    results: &Path,
    file: &str,
    title: &str,
    paper: &[PaperDpRow],
    key: &str,
) -> anyhow::Result<String> {
    let text = std::fs::read_to_string(results.join(file))
        .with_context(|| format!("reading {file} (run the matching `cargo xtask ablate`)"))?;
    let body: String = text
        .lines()
        .skip_while(|l| l.starts_with('#') || l.trim().is_empty())
        .collect::<Vec<_>>()
        .join("\n");
    let mut md = format!(
        "## {title}\n\nOurs (`docs/results/{file}`):\n\n{body}\n\nPaper:\n\n| {key} | t (ms) | path length (m) | ratio (%) |\n|---|---|---|---|\n"
    );
    for row in paper {
        md += &format!(
            "| {} | {} | {} | {} |\n",
            row.value,
            row.t_ms,
            paper_four(&row.length, 3),
            paper_four(&row.ratio, 1)
        );
    }
    Ok(md + "\n")
}

fn table6(results: &Path, paper: &PaperTables) -> anyhow::Result<String> {
    let ours: SwitchingAblation = read(&results.join("ablate-switching.json"))?;
    let mut md = String::from(
        "## Table 6: switching thresholds and boundary measure (DP seeds, hybrid)\n\n\
         | measure | (τ_enter, τ_exit) | ours: switches | paper | ours: path length (m) | paper | ours: ratio (%) | paper |\n|---|---|---|---|---|---|---|---|\n",
    );
    for row in &ours.rows {
        let s = &row.setting;
        let paper_rule = s.measure == emg_hybrid::BoundaryMeasure::JointLimits;
        let theirs = paper
            .table6
            .iter()
            .find(|p| paper_rule && p.tau_enter == s.tau_enter && p.tau_exit == s.tau_exit);
        md += &format!(
            "| {} | ({:?}, {:?}) | {:.2} | {} | {} | {} | {} | {} |\n",
            s.measure.name(),
            s.tau_enter,
            s.tau_exit,
            row.switches_per_episode.unwrap_or(0.0),
            theirs.map_or("—".into(), |p| format!("{}", p.switches)),
            four(&row.stats.length_m, 3),
            theirs.map_or("—".into(), |p| paper_four(&p.length, 3)),
            four(&row.stats.ratio_percent, 1),
            theirs.map_or("—".into(), |p| paper_four(&p.ratio, 1)),
        );
    }
    Ok(md + "\n")
}

fn figures(args: &Args, set: &SetResult) -> anyhow::Result<String> {
    let references = &set.references_m;
    histogram(
        &args.figures.join("reference-lengths.svg"),
        "reference length ℓ_ref (m)",
        &[("ℓ_ref", references)],
        &[0.45, 0.80],
    )?;
    let per_controller: Vec<(&str, Vec<f64>)> = ControllerKind::ALL
        .iter()
        .map(|c| {
            let lengths = set.dp_lengths_m.get(c.name()).cloned().unwrap_or_default();
            (c.title(), lengths)
        })
        .collect();
    let series: Vec<(&str, &[f64])> = per_controller
        .iter()
        .map(|(n, v)| (*n, v.as_slice()))
        .collect();
    histogram(
        &args.figures.join("path-lengths.svg"),
        "path length from DP seeds (m)",
        &series,
        &[],
    )?;
    trace(args)?;
    Ok("## Figures\n\n\
        ![reference lengths](figures/reference-lengths.svg)\n\n*Reference lengths ℓ_ref over the evaluation set; \
        dashed lines: the 0.45 m and 0.80 m bucket thresholds.*\n\n\
        ![path lengths](figures/path-lengths.svg)\n\n*Path-length distributions from DP seeds per controller.*\n\n\
        ![hybrid trace](figures/hybrid-trace.svg)\n\n*A representative task under the hybrid controller: progress \
        along the line (top) and joint 6 (bottom) coloured by the acting controller; dashed lines: the joint-6 \
        values where ρ reaches τ_enter and τ_exit.*\n\n"
        .into())
}

fn histogram(
    path: &Path,
    x_label: &str,
    series: &[(&str, &[f64])],
    marks: &[f64],
) -> anyhow::Result<()> {
    let max = series
        .iter()
        .flat_map(|(_, v)| v.iter().copied())
        .fold(0.0f64, f64::max)
        .max(0.1);
    let bins = 40usize;
    let width = max / bins as f64;
    let counts: Vec<Vec<usize>> = series
        .iter()
        .map(|(_, values)| {
            let mut c = vec![0usize; bins];
            for v in values.iter() {
                c[((v / width) as usize).min(bins - 1)] += 1;
            }
            c
        })
        .collect();
    let top = counts.iter().flatten().copied().max().unwrap_or(1) as f64 * 1.1;
    let root = figure::canvas(path, (800, 420))?;
    let mut chart = ChartBuilder::on(&root)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..max, 0.0..top)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc("tasks")
        .draw()?;
    for (k, ((name, _), c)) in series.iter().zip(&counts).enumerate() {
        let color = Palette99::pick(k).to_rgba();
        let points: Vec<(f64, f64)> = c
            .iter()
            .enumerate()
            .flat_map(|(b, &n)| {
                [
                    (b as f64 * width, n as f64),
                    ((b + 1) as f64 * width, n as f64),
                ]
            })
            .collect();
        chart
            .draw_series(LineSeries::new(
                points,
                ShapeStyle::from(&color).stroke_width(2),
            ))?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
    }
    for &m in marks {
        chart.draw_series(DashedLineSeries::new(
            vec![(m, 0.0), (m, top)],
            6,
            4,
            ShapeStyle::from(&BLACK.mix(0.6)),
        ))?;
    }
    figure::draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
    root.present()?;
    Ok(())
}

/// The first evaluation task (of the first 300) whose DP + hybrid rollout hands over at least
/// twice, drawn over time.
fn trace(args: &Args) -> anyhow::Result<()> {
    let setup = protocol::load_setup(
        &args.robot,
        &protocol::default_policy(),
        &protocol::default_diffusion(),
    )?;
    let (task, trajectory) = switching_rollout(&setup)?;
    draw_trace(
        &setup,
        &task,
        &trajectory,
        &args.figures.join("hybrid-trace.svg"),
    )
}

/// The first task of the first 300 evaluation tasks whose DP + hybrid rollout hands over at
/// least twice over more than 0.3 m, with that rollout.
fn switching_rollout(setup: &Setup) -> anyhow::Result<(Task, Trajectory)> {
    let mut tasks: Vec<Task> = read_tasks(&workspace::data("tasks/eval-v1.tasks"), &setup.robot)?;
    tasks.truncate(300);
    let (seeds, _) = setup.seeds(&tasks, &SeedSource::Dp)?;
    let prototype = Executor::new(ControllerKind::Hybrid, Some(&setup.policy), &setup.executor)?;
    for (task, seed) in tasks.iter().zip(&seeds) {
        let trajectory = rollout(
            &setup.robot,
            task,
            seed,
            &mut prototype.clone(),
            &setup.rollout,
        );
        if count_switches(&trajectory) >= 2 && trajectory.path_length_m > 0.3 {
            return Ok((task.clone(), trajectory));
        }
    }
    anyhow::bail!("no representative task with switches among the first 300")
}

/// `trajectory` of `task` over time at `path`: the progress along the line above, q6 with the
/// switch thresholds below, each step coloured by the controller acting.
fn draw_trace(
    setup: &Setup,
    task: &Task,
    trajectory: &Trajectory,
    path: &Path,
) -> anyhow::Result<()> {
    let limits = setup.robot.limits();
    let (mid, half) = (limits.mid()[5], limits.half_range()[5]);
    let root = figure::canvas(path, (800, 560))?;
    let (upper, lower) = root.split_vertically(260);
    let end = trajectory.steps.last().map_or(1.0, |s| s.time_s).max(0.1);
    let colour = |c: Option<emg_control::ActingController>| match c {
        Some(emg_control::ActingController::Learned) => RGBColor(31, 119, 180),
        _ => RGBColor(214, 39, 40),
    };
    let progress: Vec<(f64, f64, RGBColor)> = trajectory
        .steps
        .iter()
        .map(|s| (s.time_s, task.progress(&s.tcp), colour(s.controller)))
        .collect();
    let mut top = ChartBuilder::on(&upper)
        .caption(
            format!(
                "hybrid from DP seed: {:.2} m; blue = RL, red = classical",
                trajectory.path_length_m
            ),
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..end, 0.0..trajectory.path_length_m.max(0.05) * 1.05)?;
    top.configure_mesh()
        .x_desc("time (s)")
        .y_desc("progress along d (m)")
        .draw()?;
    draw_coloured_steps(&mut top, &progress)?;
    let q6: Vec<(f64, f64, RGBColor)> = trajectory
        .steps
        .iter()
        .map(|s| (s.time_s, s.q[5], colour(s.controller)))
        .collect();
    let mut bottom = ChartBuilder::on(&lower)
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..end, limits.lower[5]..limits.upper[5])?;
    bottom
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc("q6 (rad)")
        .draw()?;
    draw_coloured_steps(&mut bottom, &q6)?;
    for tau in [
        setup.executor.switch.tau_enter,
        setup.executor.switch.tau_exit,
    ] {
        for sign in [-1.0, 1.0] {
            let q = mid + sign * tau * half;
            bottom.draw_series(DashedLineSeries::new(
                vec![(0.0, q), (end, q)],
                6,
                4,
                ShapeStyle::from(&BLACK.mix(0.5)),
            ))?;
        }
    }
    root.present()?;
    Ok(())
}

/// The line through `points` (x, y, colour), each piece in the colour of its first point.
fn draw_coloured_steps<'a>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    points: &[(f64, f64, RGBColor)],
) -> anyhow::Result<()> {
    chart.draw_series(points.windows(2).map(|w| {
        PathElement::new(
            vec![(w[0].0, w[0].1), (w[1].0, w[1].1)],
            ShapeStyle::from(&w[0].2).stroke_width(3),
        )
    }))?;
    Ok(())
}
