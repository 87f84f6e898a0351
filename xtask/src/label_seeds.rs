//! `cargo xtask label-seeds`: seed labels for the training pool and the evaluation set
//! (`data/labels/`), resumable and sharded, and the labelling report (`docs/results/labels.*`).
//!
//! Each set is labelled through a journal of chunk files under `target/label-journal/<set>/`;
//! a run skips finished chunks (kill and restart loses nothing), `--shard i/n` labels chunks
//! `c mod n = i` (one job-array element), and `--merge` (implied by a single complete run) joins
//! the chunks into the label file, byte-identical for any shard split.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use emg_control::{ClassicalController, Task, rollout};
use emg_eval::Summary;
use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_seeding::{
    HeuristicConfig, HeuristicObjective, LABEL_FORMAT_VERSION, LabelConfig, LabelJob, LabelSet,
    Shard, TaskStats, file_sha256, heuristic_seed, hex, label_task,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::{progress, workspace};

/// Which task sets to label.
#[derive(Clone, Copy, clap::ValueEnum, PartialEq, Eq)]
enum SetChoice {
    /// data/tasks/eval-v1.tasks.
    Eval,
    /// data/tasks/train-v1.tasks.
    Train,
    /// Both, the training pool first.
    Both,
}

/// Options of `label-seeds`.
#[derive(clap::Args)]
pub struct Args {
    /// Task set(s) to label.
    #[arg(long, value_enum, default_value_t = SetChoice::Both)]
    set: SetChoice,
    /// Label only chunks c with c mod n = i (one element of a job array), e.g. `--shard 3/8`.
    #[arg(long, default_value = "0/1")]
    shard: Shard,
    /// Only join the finished chunks of every shard into the label file and its manifest.
    #[arg(long)]
    merge: bool,
    /// Only write the labelling report docs/results/labels.{md,json} (needs both label files).
    #[arg(long)]
    report: bool,
    /// Stop after this many chunks (a later run resumes).
    #[arg(long)]
    chunk_limit: Option<usize>,
    /// Tasks per journal chunk.
    #[arg(long, default_value_t = 200)]
    chunk_size: usize,
    /// Tasks labelled afresh to measure throughput in the report.
    #[arg(long, default_value_t = 1000)]
    throughput_tasks: usize,
    /// Labelling configuration (JSON, fields of `LabelConfig`; defaults when absent).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Worker threads (0 = one per core); results do not depend on it.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Journal directory (one subdirectory per set).
    #[arg(long, default_value_os_t = workspace::scratch("label-journal"))]
    journal_dir: PathBuf,
    /// Task-set directory.
    #[arg(long, default_value_os_t = workspace::data("tasks"))]
    tasks_dir: PathBuf,
    /// Label directory.
    #[arg(long, default_value_os_t = workspace::data("labels"))]
    out_dir: PathBuf,
    /// Report directory.
    #[arg(long, default_value_os_t = workspace::results_dir())]
    results_dir: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
}

/// The manifest written beside a label file.
#[derive(Serialize, Deserialize)]
struct Manifest {
    format_version: u32,
    labels_file: String,
    task_set: String,
    task_set_sha256: String,
    task_count: usize,
    labels_total: usize,
    tasks_without_labels: usize,
    labels_per_task: BTreeMap<usize, usize>,
    branches_per_task: BTreeMap<u32, usize>,
    candidates_per_task: Summary,
    seed_length_m: Summary,
    best_label_length_m: Summary,
    best_candidate_length_m: Summary,
    best_label_gain_over_seed_m: Summary,
    tasks_where_best_label_beats_seed: usize,
    config: LabelConfig,
}

/// Runs the requested labelling, merge or report.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let robot = workspace::load_robot(&args.robot)?;
    let config: LabelConfig =
        workspace::read_config(args.config.as_deref(), "labelling configuration")?;
    let pool = workspace::thread_pool(args.threads)?;
    if args.report {
        return pool.install(|| report(args, &robot, &config));
    }
    let sets: &[&str] = match args.set {
        SetChoice::Eval => &["eval-v1"],
        SetChoice::Train => &["train-v1"],
        SetChoice::Both => &["train-v1", "eval-v1"],
    };
    for name in sets {
        pool.install(|| label_set(args, &robot, &config, name))?;
    }
    Ok(())
}

fn label_set(args: &Args, robot: &Robot, config: &LabelConfig, name: &str) -> anyhow::Result<()> {
    let task_path = args.tasks_dir.join(format!("{name}.tasks"));
    let tasks = read_tasks(&task_path, robot).with_context(|| {
        format!(
            "reading {} (create it with `cargo xtask make-tasks`)",
            task_path.display()
        )
    })?;
    let sha = file_sha256(&task_path)?;
    let job = LabelJob::new(
        robot,
        &tasks,
        sha,
        config,
        &args.journal_dir.join(name),
        args.chunk_size,
    )?;
    if !args.merge {
        let pending = job.pending_chunks(args.shard).len();
        let tasks_pending: usize = job
            .pending_chunks(args.shard)
            .iter()
            .map(|&c| args.chunk_size.min(tasks.len() - c * args.chunk_size))
            .sum();
        let bar = progress::bar(tasks_pending as u64, name);
        let started = Instant::now();
        let done = job.run(args.shard, args.chunk_limit, &|n| bar.inc(n as u64))?;
        let seconds = started.elapsed().as_secs_f64();
        let labelled = bar.position();
        bar.finish();
        println!(
            "{name}: shard {}/{}: {} chunks done in {seconds:.1} s ({:.1} tasks/s), {} were already done, {} left (of {pending} pending)",
            args.shard.index,
            args.shard.count,
            done.chunks_done,
            labelled as f64 / seconds.max(1e-9),
            done.chunks_skipped,
            done.chunks_left,
        );
        if args.shard != Shard::WHOLE || done.chunks_left > 0 {
            return Ok(());
        }
    }
    let (set, stats) = job.merge()?;
    std::fs::create_dir_all(&args.out_dir)?;
    let labels_path = args.out_dir.join(format!("{name}.labels"));
    set.write(&labels_path)?;
    let manifest = manifest(&labels_path, &task_path, &set, &stats, config)?;
    let manifest_path = args.out_dir.join(format!("{name}.manifest.json"));
    emg_io::write_atomically(
        &manifest_path,
        serde_json::to_string_pretty(&manifest)? + "\n",
    )?;
    println!(
        "{name}: {} labels for {} tasks ({} without) → {} and {}",
        manifest.labels_total,
        manifest.task_count,
        manifest.tasks_without_labels,
        labels_path.display(),
        manifest_path.display()
    );
    Ok(())
}

fn manifest(
    labels_path: &Path,
    task_path: &Path,
    set: &LabelSet,
    stats: &[TaskStats],
    config: &LabelConfig,
) -> anyhow::Result<Manifest> {
    let mut labels_per_task = BTreeMap::new();
    let mut branches_per_task = BTreeMap::new();
    for (task, stat) in set.tasks().iter().zip(stats) {
        *labels_per_task.entry(task.labels.len()).or_insert(0) += 1;
        *branches_per_task.entry(stat.branches).or_insert(0) += 1;
    }
    let best_label: Vec<f64> = set
        .tasks()
        .iter()
        .map(|t| t.labels.first().map_or(0.0, |l| l.length_m))
        .collect();
    let seed: Vec<f64> = stats.iter().map(|s| s.seed_length_m).collect();
    let gain: Vec<f64> = best_label.iter().zip(&seed).map(|(b, s)| b - s).collect();
    let summary = |values: &[f64]| Summary::of(values).context("the task set is empty");
    Ok(Manifest {
        format_version: LABEL_FORMAT_VERSION,
        labels_file: workspace::relative(labels_path),
        task_set: workspace::relative(task_path),
        task_set_sha256: hex(set.task_set_sha256()),
        task_count: set.tasks().len(),
        labels_total: set.tasks().iter().map(|t| t.labels.len()).sum(),
        tasks_without_labels: set.tasks().iter().filter(|t| t.labels.is_empty()).count(),
        labels_per_task,
        branches_per_task,
        candidates_per_task: summary(
            &stats
                .iter()
                .map(|s| f64::from(s.candidates))
                .collect::<Vec<_>>(),
        )?,
        seed_length_m: summary(&seed)?,
        best_label_length_m: summary(&best_label)?,
        best_candidate_length_m: summary(
            &stats.iter().map(|s| s.best_length_m).collect::<Vec<_>>(),
        )?,
        best_label_gain_over_seed_m: summary(&gain)?,
        tasks_where_best_label_beats_seed: gain.iter().filter(|g| **g > 0.0).count(),
        config: config.clone(),
    })
}

/// One seed source of the heuristic comparison.
#[derive(Serialize)]
struct SeedRow {
    seed: &'static str,
    generation_ms: Option<Summary>,
    generation_ms_median: Option<f64>,
    generation_ms_p95: Option<f64>,
    path_length_m: Summary,
    ratio_to_reference_percent: Summary,
    failed_tasks: usize,
}

/// The labelling report.
#[derive(Serialize)]
struct Report {
    labels_dir: String,
    threads: usize,
    throughput_tasks: usize,
    throughput_seconds: f64,
    throughput_tasks_per_s: f64,
    eval: Manifest,
    train: Manifest,
    reference: &'static str,
    heuristic: HeuristicConfig,
    seeds: Vec<SeedRow>,
}

/// What one seed of one task reaches.
struct SeedOutcome {
    /// The classical controller's path length from the seed (from `q0_seed` where the
    /// heuristic found none).
    length_m: f64,
    /// The time the heuristic took to find the seed (ms; none for `q0_seed` and where it
    /// found none).
    generation_ms: Option<f64>,
    /// Whether there was a seed.
    found: bool,
}

/// Writes `labels.{json,md}`: the labelling throughput, the label manifests and the seeds
/// (`q0_seed`, `q_mu`, `q_jl`) against the labels of the evaluation set.
fn report(args: &Args, robot: &Robot, config: &LabelConfig) -> anyhow::Result<()> {
    let read_manifest = |name: &str| -> anyhow::Result<Manifest> {
        let path = args.out_dir.join(format!("{name}.manifest.json"));
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {} (label the set first)", path.display()))?;
        Ok(serde_json::from_str(&text)?)
    };
    let (eval, train) = (read_manifest("eval-v1")?, read_manifest("train-v1")?);
    let task_path = args.tasks_dir.join("eval-v1.tasks");
    let tasks = read_tasks(&task_path, robot)?;
    let labels = LabelSet::read(&args.out_dir.join("eval-v1.labels"))?;
    if labels.task_set_sha256() != &file_sha256(&task_path)? || !labels.is_complete() {
        bail!(
            "{} does not label the current evaluation set completely",
            args.out_dir.join("eval-v1.labels").display()
        );
    }
    let sample = &tasks[..args.throughput_tasks.min(tasks.len())];
    let throughput_seconds = labelling_seconds(robot, sample, config);
    let reference = reference_lengths(robot, &tasks, &labels, config);
    let outcomes = seed_outcomes(robot, &tasks, config);
    let report = Report {
        labels_dir: workspace::relative(&args.out_dir),
        threads: rayon::current_num_threads(),
        throughput_tasks: sample.len(),
        throughput_seconds,
        throughput_tasks_per_s: sample.len() as f64 / throughput_seconds,
        eval,
        train,
        heuristic: HeuristicConfig::default(),
        reference: "longest label of the task (classical rollout); q0_seed's length where the task has no label",
        seeds: seed_rows(&outcomes, &reference)?,
    };
    workspace::write_results(&args.results_dir, "labels", &report, &markdown(&report))
}

/// The wall time (s) of labelling `sample` on the worker threads.
fn labelling_seconds(robot: &Robot, sample: &[Task], config: &LabelConfig) -> f64 {
    let bar = progress::bar(sample.len() as u64, "throughput");
    let started = Instant::now();
    sample.par_iter().enumerate().for_each(|(i, task)| {
        label_task(robot, task, i as u32, config);
        bar.inc(1);
    });
    let seconds = started.elapsed().as_secs_f64();
    bar.finish();
    seconds
}

/// The reference length of each task: its longest label, `q0_seed`'s classical length where it
/// has none.
fn reference_lengths(
    robot: &Robot,
    tasks: &[Task],
    labels: &LabelSet,
    config: &LabelConfig,
) -> Vec<f64> {
    labels
        .tasks()
        .iter()
        .zip(tasks)
        .map(|(t, task)| {
            t.labels.first().map_or_else(
                || classical_length(robot, task, config, &seed_of(task)),
                |l| l.length_m,
            )
        })
        .collect()
}

/// The outcomes of `q0_seed`, `q_mu` and `q_jl`, in that order, for every task in turn.
fn seed_outcomes(robot: &Robot, tasks: &[Task], config: &LabelConfig) -> Vec<SeedOutcome> {
    let bar = progress::bar(tasks.len() as u64 * 3, "seeds");
    let outcomes = tasks
        .par_iter()
        .flat_map_iter(|task| {
            let seed = classical_length(robot, task, config, &seed_of(task));
            let heuristics = [
                HeuristicObjective::Manipulability,
                HeuristicObjective::JointCentring,
            ]
            .map(|objective| {
                match heuristic_seed(
                    robot,
                    task,
                    objective,
                    &HeuristicConfig::default(),
                    &config.projection,
                ) {
                    Ok(h) => SeedOutcome {
                        length_m: classical_length(robot, task, config, &h.q),
                        generation_ms: Some(h.generation_time.as_secs_f64() * 1e3),
                        found: true,
                    },
                    Err(_) => SeedOutcome {
                        length_m: seed,
                        generation_ms: None,
                        found: false,
                    },
                }
            });
            bar.inc(3);
            let given = SeedOutcome {
                length_m: seed,
                generation_ms: None,
                found: true,
            };
            std::iter::once(given).chain(heuristics)
        })
        .collect();
    bar.finish();
    outcomes
}

/// One row per seed of [`seed_outcomes`]: its generation times, path lengths, ratios to
/// `reference` and the tasks it found no seed for.
fn seed_rows(outcomes: &[SeedOutcome], reference: &[f64]) -> anyhow::Result<Vec<SeedRow>> {
    let names = ["q0_seed", "q_mu", "q_jl"];
    names
        .iter()
        .enumerate()
        .map(|(k, &name)| -> anyhow::Result<SeedRow> {
            let column: Vec<&SeedOutcome> = outcomes.iter().skip(k).step_by(3).collect();
            let lengths: Vec<f64> = column.iter().map(|r| r.length_m).collect();
            let mut times: Vec<f64> = column.iter().filter_map(|r| r.generation_ms).collect();
            let ratio: Vec<f64> = lengths
                .iter()
                .zip(reference)
                .map(|(l, r)| 100.0 * l / r.max(1e-9))
                .collect();
            times.sort_by(f64::total_cmp);
            let quantile = |q: f64| {
                (!times.is_empty()).then(|| times[((times.len() - 1) as f64 * q).round() as usize])
            };
            Ok(SeedRow {
                seed: name,
                generation_ms: Summary::of(&times),
                generation_ms_median: quantile(0.5),
                generation_ms_p95: quantile(0.95),
                path_length_m: Summary::of(&lengths).context("no tasks")?,
                ratio_to_reference_percent: Summary::of(&ratio).context("no tasks")?,
                failed_tasks: column.iter().filter(|r| !r.found).count(),
            })
        })
        .collect()
}

fn seed_of(task: &Task) -> emg_kinematics::JointVector {
    task.q0_seed.expect("generated task sets keep q0_seed")
}

fn classical_length(
    robot: &Robot,
    task: &Task,
    config: &LabelConfig,
    q: &emg_kinematics::JointVector,
) -> f64 {
    let mut controller = ClassicalController::new(config.gains.clone());
    rollout(robot, task, q, &mut controller, &config.rollout).path_length_m
}

fn markdown(report: &Report) -> String {
    let mut md = format!(
        "# Seed labels: branches, best branch vs q0_seed, heuristic seeds\n\n\
         Written by `cargo xtask label-seeds --report` from {}/*.manifest.json and a fresh \
         run on the evaluation set. Do not edit by hand.\n\n",
        report.labels_dir
    );
    md += &format!(
        "## Throughput\n\nLabelling {} evaluation tasks afresh: {:.1} s wall on {} threads = **{:.1} tasks/s**.\n\n",
        report.throughput_tasks,
        report.throughput_seconds,
        report.threads,
        report.throughput_tasks_per_s
    );
    md += "## Labels\n\n| set | tasks | labels | tasks without labels | mean labels/task | q0_seed L (m) | best label L (m) | best candidate L (m) | best label − q0_seed (m) | best label beats q0_seed |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (name, m) in [("eval-v1", &report.eval), ("train-v1", &report.train)] {
        md += &format!(
            "| {name} | {} | {} | {} | {:.2} | {:.3} | {:.3} | {:.3} | {:.3} (max {:.3}) | {:.1} % |\n",
            m.task_count,
            m.labels_total,
            m.tasks_without_labels,
            m.labels_total as f64 / m.task_count as f64,
            m.seed_length_m.mean,
            m.best_label_length_m.mean,
            m.best_candidate_length_m.mean,
            m.best_label_gain_over_seed_m.mean,
            m.best_label_gain_over_seed_m.max,
            100.0 * m.tasks_where_best_label_beats_seed as f64 / m.task_count as f64,
        );
    }
    md += "\n## Self-motion branches per task\n\n| branches | eval-v1 tasks | train-v1 tasks |\n|---|---|---|\n";
    let keys: std::collections::BTreeSet<u32> = report
        .eval
        .branches_per_task
        .keys()
        .chain(report.train.branches_per_task.keys())
        .copied()
        .collect();
    for k in keys {
        md += &format!(
            "| {k} | {} | {} |\n",
            report.eval.branches_per_task.get(&k).unwrap_or(&0),
            report.train.branches_per_task.get(&k).unwrap_or(&0)
        );
    }
    md += &format!(
        "\n## Seeds under the classical controller (evaluation set)\n\nReference: {}.\n\n\
         | seed | t median (ms) | t p95 (ms) | path length (m) mean / std / min / max | ratio to reference (%) mean / std | failed |\n|---|---|---|---|---|---|\n",
        report.reference
    );
    for row in &report.seeds {
        let (l, r) = (&row.path_length_m, &row.ratio_to_reference_percent);
        let ms = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.3}"));
        md += &format!(
            "| {} | {} | {} | {:.3} / {:.3} / {:.3} / {:.3} | {:.1} / {:.1} | {} |\n",
            row.seed,
            ms(row.generation_ms_median),
            ms(row.generation_ms_p95),
            l.mean,
            l.std,
            l.min,
            l.max,
            r.mean,
            r.std,
            row.failed_tasks
        );
    }
    md
}
