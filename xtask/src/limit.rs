//! `cargo xtask limit`: the best-known length ℓ* of each task of a fixed evaluation subset (the
//! search planner with a large budget and its beam stage, every trajectory re-checked by the
//! independent checker), its trajectory, and its reachability bound, beside what the paper's
//! pipeline and the default search reach.
//!
//! Resumable and shardable: each finished task is written atomically as its own file in the
//! journal directory (`target/limit/` by default) and a run skips the tasks already there;
//! `--shard i/n` takes the tasks whose index is `i` mod `n`. `--merge` reads every task's file
//! and writes `docs/results/limit.{json,md}`: per bucket of the bound, length-weighted shares
//! (ℓ* and each planner of the bound, each planner of ℓ*) and the tasks below half their bound;
//! per bucket of ℓ*, the task means the report reads.

use std::path::{Path, PathBuf};

use anyhow::Context;
use emg_control::{CheckRollout, Task};
use emg_eval::{
    BOUND_BUCKET_EDGES_M, BoundShare, BucketConfig, Difficulty, Summary, bound_bucket,
    bound_shares, four,
};

use emg_planner::{
    FAR_END_SHARE, PlanRequest, Planner, PlannerConfig, PlannerKind, SHORTFALL_SHARE, SearchConfig,
    far_end_chains,
};
use emg_seeding::Shard;
use emg_verify::ReferenceModel;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::search_eval::far_end_points;
use crate::task_set_options::TaskSetOptions;
use crate::{progress, workspace};

/// Where `--out-dir` stands among the options of `limit` (after `--tasks`, `--shard`,
/// `--merge` and the three options before it in [`TaskSetOptions`]): `--journal` is listed
/// there, before it.
const OUT_DIR_SLOT: usize = 6;

/// Options of `limit`.
#[derive(clap::Args)]
#[command(
    mut_arg("out_dir", |arg| arg.help("Output directory of limit.{json,md}")),
)]
pub struct Args {
    /// Tasks: the first this many of the task set.
    #[arg(long, default_value_t = 1000)]
    tasks: usize,
    /// The part of the tasks this run takes (`i/n`: the tasks whose index is i mod n).
    #[arg(long, default_value = "0/1")]
    shard: Shard,
    /// Merge the journal into docs/results/limit.{json,md} instead of running.
    #[arg(long)]
    merge: bool,
    /// Worker threads, task set, robot file and output directory.
    #[command(flatten)]
    common: TaskSetOptions,
    /// Journal directory: one file per finished task.
    #[arg(long, default_value_os_t = workspace::scratch("limit"), display_order = OUT_DIR_SLOT)]
    journal: PathBuf,
}

/// The search settings of the limit: far more starts, finalists, repairs, chains and steps
/// than the planner's default, then, where the plan still ends short of the bound, the
/// far-end stage (motions planned back to `p0` from far along the line, at this breadth) and
/// the beam stage (a search over action sequences) with a larger budget.
pub fn limit_search() -> SearchConfig {
    SearchConfig {
        budget_steps: 200_000,
        dp_samples: 128,
        ik_restarts: 512,
        finalists: 16,
        repaired_starts: 16,
        chains: 16,
        // Its own budget and breadth are already far wider than the widened pass's.
        widened_budget_steps: 0,
        beam_width: 512,
        beam_budget_steps: 1_000_000,
        ..SearchConfig::default()
    }
}

/// What the journal was made with; a run refuses a journal made otherwise.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Identity {
    tasks: String,
    task_count: usize,
    limit: SearchConfig,
    search: SearchConfig,
    /// Restarts of the continuity test ([`FAR_END_RESTARTS`]).
    far_end_restarts: usize,
}

/// One task's results, the file the journal holds for it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct TaskLimit {
    index: usize,
    /// ℓ*: the longest of the large search, the default search and the pipeline (m).
    limit_m: f64,
    /// Where the limit's start came from.
    limit_seed: String,
    /// The limit's joint configurations, one per step (rad).
    limit_q: Vec<Vec<f64>>,
    /// The reachability bound (m): the scan's, raised to ℓ* where the limit went beyond it.
    bound_m: f64,
    /// Hybrid + DP, the paper's pipeline (m).
    pipeline_m: f64,
    /// The default search (m).
    search_m: f64,
    /// Whether a chain of valid configurations joins `p0` to [`FAR_END_SHARE`] of the scan
    /// ([`far_end_chains`] from [`FAR_END_RESTARTS`] restarts).
    joined: bool,
}

/// Random IK restarts at the far end of the scan whose configurations [`far_end_chains`]
/// extends back to `p0`.
const FAR_END_RESTARTS: usize = 64;

/// Runs this shard's pending tasks, or merges the journal.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let workspace::PlannerSetup {
        planner,
        checker,
        tasks,
    } = args.common.planner_setup(args.tasks, "limit")?;
    let identity = Identity {
        tasks: workspace::relative(&args.common.task_file),
        task_count: tasks.len(),
        limit: limit_search(),
        search: SearchConfig::default(),
        far_end_restarts: FAR_END_RESTARTS,
    };
    open_journal(&args.journal, &identity)?;
    if args.merge {
        return merge(args, &identity);
    }
    let limit_planner = planner.with_config(PlannerConfig {
        search: limit_search(),
        ..PlannerConfig::default()
    })?;
    let pending: Vec<usize> = (args.shard.index..tasks.len())
        .step_by(args.shard.count)
        .filter(|&i| !task_path(&args.journal, i).exists())
        .collect();
    println!(
        "{} tasks of shard {}/{} to do ({} already in {})",
        pending.len(),
        args.shard.index,
        args.shard.count,
        (args.shard.index..tasks.len())
            .step_by(args.shard.count)
            .count()
            - pending.len(),
        args.journal.display()
    );
    let bar = progress::bar(pending.len() as u64, "limit");
    workspace::thread_pool(args.common.threads)?.install(|| {
        pending.par_iter().try_for_each(|&index| {
            let record = task_limit(&planner, &limit_planner, &checker, index, &tasks[index])?;
            let text = serde_json::to_string(&record)? + "\n";
            emg_io::write_atomically(task_path(&args.journal, index), text.as_bytes())?;
            bar.inc(1);
            anyhow::Ok(())
        })
    })?;
    bar.finish();
    Ok(())
}

/// Task `index` planned by the pipeline, by the default search and by the limit's
/// (`limit_planner`): the longest plan, checked, with its reachability bound and whether its
/// far end joins back to `p0`.
fn task_limit(
    planner: &Planner,
    limit_planner: &Planner,
    checker: &ReferenceModel,
    index: usize,
    task: &Task,
) -> anyhow::Result<TaskLimit> {
    let search = PlanRequest {
        planner: PlannerKind::Search,
        ..PlanRequest::pipeline()
    };
    let plan = |planner: &Planner, request: &PlanRequest| {
        planner
            .plan(task, request)
            .with_context(|| format!("task {index}"))
    };
    let pipeline = plan(planner, &PlanRequest::pipeline())?;
    let searched = plan(planner, &search)?;
    let large = plan(limit_planner, &search)?;
    let (pipeline_m, search_m) = (
        pipeline.trajectory.path_length_m,
        searched.trajectory.path_length_m,
    );
    // ℓ*: the longest of all three plans (the large search usually).
    let limit = [large, searched, pipeline]
        .into_iter()
        .reduce(|best, other| {
            if other.trajectory.path_length_m > best.trajectory.path_length_m {
                other
            } else {
                best
            }
        })
        .context("three plans")?;
    checker
        .check(
            task,
            &limit.trajectory,
            &planner.config().rollout.constraints,
        )
        .map_err(|failure| {
            anyhow::anyhow!("task {index}: the limit fails the checker: {failure:?}")
        })?;
    let reach = planner.reach_of(task, &limit);
    let config = planner.config();
    let joined = !far_end_chains(
        planner.robot(),
        task,
        &config.rollout.constraints,
        &config.reach,
        &reach,
        config.search.chain_jump_rad,
        FAR_END_RESTARTS,
    )
    .is_empty();
    Ok(TaskLimit {
        index,
        limit_m: limit.trajectory.path_length_m,
        limit_seed: limit.seed.source.to_string(),
        limit_q: limit
            .trajectory
            .steps
            .iter()
            .map(|s| planner.robot().joints_of(&s.q).to_vec())
            .collect(),
        bound_m: reach.reachable_m,
        pipeline_m,
        search_m,
        joined,
    })
}

fn task_path(journal: &Path, index: usize) -> PathBuf {
    journal.join(format!("task-{index:06}.json"))
}

/// Creates the journal with `identity`, or checks that an existing one was made with it.
fn open_journal(dir: &Path, identity: &Identity) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(identity)? + "\n";
    emg_io::open_journal(dir, &text)
        .context("the limit journal holds another task set, task count or search settings")
}

/// Per-bucket (by ℓ*) and overall statistics.
#[derive(Serialize)]
struct Bucket {
    bucket: String,
    tasks: usize,
    limit_m: Summary,
    bound_m: Summary,
    /// Mean of ℓ* / bound over the bucket's tasks with a positive bound.
    limit_share_of_bound: f64,
    /// Mean of the pipeline's length / ℓ*.
    pipeline_share_of_limit: f64,
    /// Mean of the default search's length / ℓ*.
    search_share_of_limit: f64,
}

/// Length-weighted shares over one bucket of the bound.
#[derive(Serialize)]
struct BoundBucket {
    /// ℓ* of the bound.
    limit: BoundShare,
    /// The default search of the bound.
    search: BoundShare,
    /// Hybrid + DP of the bound.
    pipeline: BoundShare,
    /// The default search of ℓ*.
    search_of_limit: BoundShare,
}

/// Where ℓ* ends short of the bound, whether the bound's points join into one motion: over
/// one bucket of the bound, the tasks whose ℓ* ends below [`SHORTFALL_SHARE`] of their bound.
#[derive(Serialize)]
struct ContinuityBucket {
    bucket: String,
    /// Tasks whose ℓ* ends short.
    short: usize,
    /// Of them, the tasks a chain joins `p0` to [`FAR_END_SHARE`] of the scan on.
    joined: usize,
    /// Σ (bound − ℓ*) over the short tasks (m).
    missing_m: f64,
    /// Σ (bound − ℓ*) over the short tasks a chain joins (m).
    missing_joined_m: f64,
}

#[derive(Serialize)]
struct Record {
    robot: String,
    identity: Identity,
    /// Per bucket of the bound, then all tasks.
    by_bound: Vec<BoundBucket>,
    /// Per bucket of the bound, then all tasks.
    continuity: Vec<ContinuityBucket>,
    buckets_by_limit: BucketConfig,
    rows: Vec<Bucket>,
}

fn merge(args: &Args, identity: &Identity) -> anyhow::Result<()> {
    let records = (0..identity.task_count)
        .map(|index| {
            let path = task_path(&args.journal, index);
            let text = std::fs::read_to_string(&path).with_context(|| {
                format!("task {index} is missing: run every shard to completion before merging")
            })?;
            serde_json::from_str::<TaskLimit>(&text)
                .with_context(|| format!("reading {}", path.display()))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let buckets = BucketConfig::default();
    let mut rows = Vec::new();
    let groups = Difficulty::ALL.map(|d| (d.name().to_string(), Some(d)));
    for (name, difficulty) in groups.into_iter().chain([("All".to_string(), None)]) {
        let members: Vec<&TaskLimit> = records
            .iter()
            .filter(|r| difficulty.is_none_or(|d| buckets.classify(r.limit_m) == d))
            .collect();
        if members.is_empty() {
            continue;
        }
        let values =
            |f: &dyn Fn(&TaskLimit) -> f64| members.iter().map(|r| f(r)).collect::<Vec<_>>();
        let share = |f: &dyn Fn(&TaskLimit) -> (f64, f64)| {
            let ratios: Vec<f64> = members
                .iter()
                .map(|r| f(r))
                .filter(|(_, of)| *of > 1e-9)
                .map(|(v, of)| v / of)
                .collect();
            ratios.iter().sum::<f64>() / ratios.len().max(1) as f64
        };
        rows.push(Bucket {
            bucket: name,
            tasks: members.len(),
            limit_m: Summary::of(&values(&|r| r.limit_m)).context("bucket")?,
            bound_m: Summary::of(&values(&|r| r.bound_m)).context("bucket")?,
            limit_share_of_bound: share(&|r| (r.limit_m, r.bound_m)),
            pipeline_share_of_limit: share(&|r| (r.pipeline_m, r.limit_m)),
            search_share_of_limit: share(&|r| (r.search_m, r.limit_m)),
        });
    }
    let column = |f: fn(&TaskLimit) -> f64| records.iter().map(f).collect::<Vec<f64>>();
    let (limits, bounds) = (column(|r| r.limit_m), column(|r| r.bound_m));
    let (searched, pipeline) = (column(|r| r.search_m), column(|r| r.pipeline_m));
    let by_bound = bound_shares(&limits, &bounds, &bounds)
        .into_iter()
        .zip(bound_shares(&searched, &bounds, &bounds))
        .zip(bound_shares(&pipeline, &bounds, &bounds))
        .zip(bound_shares(&searched, &limits, &bounds))
        .map(
            |(((limit, search), pipeline), search_of_limit)| BoundBucket {
                limit,
                search,
                pipeline,
                search_of_limit,
            },
        )
        .collect();
    let record = Record {
        robot: workspace::relative(&args.common.robot),
        identity: identity.clone(),
        by_bound,
        continuity: continuity(&records),
        buckets_by_limit: buckets,
        rows,
    };
    workspace::write_results(&args.common.out_dir, "limit", &record, &markdown(&record))
}

/// The continuity of the short tasks per bucket of the bound, then over all tasks.
fn continuity(records: &[TaskLimit]) -> Vec<ContinuityBucket> {
    let short: Vec<&TaskLimit> = records
        .iter()
        .filter(|r| r.limit_m < SHORTFALL_SHARE * r.bound_m)
        .collect();
    let bucket = |name: &str, members: Vec<&&TaskLimit>| {
        let missing = |r: &&&TaskLimit| r.bound_m - r.limit_m;
        ContinuityBucket {
            bucket: name.to_string(),
            short: members.len(),
            joined: members.iter().filter(|r| r.joined).count(),
            // A fold from +0: an empty sum of floats is −0, which would print as "-0.00".
            missing_m: members.iter().map(missing).fold(0.0, |a, m| a + m),
            missing_joined_m: (members.iter().filter(|r| r.joined).map(missing))
                .fold(0.0, |a, m| a + m),
        }
    };
    let mut buckets: Vec<ContinuityBucket> = std::iter::once(0.0)
        .chain(BOUND_BUCKET_EDGES_M)
        .map(|lower| {
            let name = bound_bucket(lower);
            bucket(
                name,
                short
                    .iter()
                    .filter(|r| bound_bucket(r.bound_m) == name)
                    .collect(),
            )
        })
        .collect();
    buckets.push(bucket("all", short.iter().collect()));
    buckets
}

fn markdown(record: &Record) -> String {
    by_bound_section(record) + &continuity_section(record) + &by_limit_section(record)
}

/// The page's head, what ℓ* and the bound are, and the section by bucket of the bound.
fn by_bound_section(record: &Record) -> String {
    let limit = &record.identity.limit;
    let mut md = format!(
        "# Best-known lengths (ℓ*) and the reachability bound\n\nWritten by `cargo xtask limit` and \
         `cargo xtask limit --merge`. Do not edit by hand. Robot `{}`, the first {} tasks of `{}`. \
         ℓ* is the search planner with a large budget ({} steps, {} diffusion samples, cone IK from \
         {} restarts, {} finalists, the best {} starts repaired, up to {} of the scan's chains \
         followed from `p0`, then, where the plan still ends below {} × the bound, motions \
         planned backwards to `p0` from {} read and followed forwards, then where it still ends \
         below {} × \
         the bound, a beam search over action sequences: {} members, up to {} more steps), \
         every trajectory re-checked by the independent checker; the bound is the reachability \
         scan (a necessary condition, so an upper bound as good as its IK sampling), raised to ℓ* \
         where a plan went beyond it.\n\n\
         ## By bucket of the bound\n\nΣ length / Σ reference over the tasks whose bound lies in \
         the bucket (the task mean of the ratio in brackets); below ½: the tasks that end below \
         half of the reference.\n\n\
         | bound | tasks | ℓ* / bound | search / bound | Hybrid + DP / bound | search / ℓ* | \
         search below ½ bound | ℓ* below ½ bound |\n|---|---|---|---|---|---|---|---|\n",
        record.robot,
        record.identity.task_count,
        record.identity.tasks,
        limit.budget_steps,
        limit.dp_samples,
        limit.ik_restarts,
        limit.finalists,
        limit.repaired_starts,
        limit.chains,
        SHORTFALL_SHARE,
        far_end_points(limit),
        limit.beam_below_share,
        limit.beam_width,
        limit.beam_budget_steps,
    );
    let share = |s: &BoundShare| format!("{:.3} ({:.3})", s.share, s.task_mean_share);
    for row in &record.by_bound {
        md += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} |\n",
            row.limit.bucket,
            row.limit.tasks,
            share(&row.limit),
            share(&row.search),
            share(&row.pipeline),
            share(&row.search_of_limit),
            row.search.below_half.len(),
            row.limit.below_half.len(),
        );
    }
    let short: Vec<String> = record
        .by_bound
        .last()
        .map(|all| all.limit.below_half.iter().map(|i| i.to_string()).collect())
        .unwrap_or_default();
    if !short.is_empty() {
        md += &format!(
            "\nTasks whose ℓ* ends below half their bound (by index): {}.\n",
            short.join(", ")
        );
    }
    md
}

/// The section on the tasks whose ℓ* ends short: how many a chain of valid configurations
/// joins, per bucket of the bound.
fn continuity_section(record: &Record) -> String {
    let mut md = format!(
        "\n## Where ℓ* ends short: do the bound's points join into one motion?\n\nThe bound \
         only says that every point up to it has a valid configuration. For each task, valid \
         configurations at {:.0} % of the scan (the scan's own, then the cone IK from {} seeded \
         random restarts) are extended backwards to `p0`, at every 1 cm grid point the valid \
         configuration nearest the one after it, while no joint moves more than {} rad between \
         neighbours (`emg_planner::far_end_chains`). Over the tasks whose ℓ* ends below {} × \
         their bound: how many such a chain joins, and the length ℓ* misses (Σ bound − ℓ*) on \
         all of them and on the joined ones. Where no chain joins, the points found need not \
         join into one motion: the shortfall there is more likely the bound's looseness than a \
         motion the search missed.\n\n\
         | bound | tasks ℓ* < {} × bound | joined by a chain | missing (m) | missing on joined (m) \
         |\n|---|---|---|---|---|\n",
        100.0 * FAR_END_SHARE,
        FAR_END_RESTARTS,
        record.identity.search.chain_jump_rad,
        SHORTFALL_SHARE,
        SHORTFALL_SHARE,
    );
    for row in &record.continuity {
        md += &format!(
            "| {} | {} | {} | {:.2} | {:.2} |\n",
            row.bucket, row.short, row.joined, row.missing_m, row.missing_joined_m
        );
    }
    md
}

/// The section by bucket of ℓ*.
fn by_limit_section(record: &Record) -> String {
    let mut md = format!(
        "\n## By bucket of ℓ*\n\nBuckets by ℓ* (Easy ≥ {} m, Difficult < {} m); shares are task \
         means of the ratio.\n\n\
         | bucket | tasks | ℓ* (m, mean / std / min / max) | bound (m) | ℓ* / bound | Hybrid + DP / ℓ* | \
         search (default budget {}) / ℓ* |\n|---|---|---|---|---|---|---|\n",
        record.buckets_by_limit.easy_min_m,
        record.buckets_by_limit.difficult_below_m,
        record.identity.search.budget_steps,
    );
    for row in &record.rows {
        md += &format!(
            "| {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} |\n",
            row.bucket,
            row.tasks,
            four(&row.limit_m, 3),
            row.bound_m.mean,
            row.limit_share_of_bound,
            row.pipeline_share_of_limit,
            row.search_share_of_limit,
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn identity(task_count: usize) -> Identity {
        Identity {
            tasks: "data/tasks/eval-v1.tasks".into(),
            task_count,
            limit: limit_search(),
            search: SearchConfig::default(),
            far_end_restarts: FAR_END_RESTARTS,
        }
    }

    #[test]
    fn a_journal_is_reopened_only_with_the_settings_it_was_made_with() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let journal = dir.path().join("limit");
        open_journal(&journal, &identity(10)).expect("a new journal");
        open_journal(&journal, &identity(10)).expect("the same settings resume it");
        let error = open_journal(&journal, &identity(20)).expect_err("other settings");
        assert!(format!("{error:#}").contains("start over"), "{error:#}");
    }
}
