//! `cargo xtask eval`: a controller over the evaluation set, results in `docs/results/`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use emg_control::{RolloutConfig, Task};
use emg_eval::{
    BucketConfig, EvalRecord, RawSet, Summary, check_trajectories, joint_limit_histogram,
    markdown as protocol_markdown, merge_sets, rollout_all, run_set, summarize,
    termination_histogram,
};
use emg_io::read_tasks;
use emg_planner::{ControllerKind, Executor, ExecutorConfig};
use serde::{Deserialize, Serialize};

use crate::velocity_limits::{self, VelocityLimits};
use crate::{progress, protocol, workspace};

/// Options of `eval`.
#[derive(clap::Args)]
pub struct Args {
    /// Evaluate one controller from q0_seed; without it, run the whole seed × controller
    /// protocol (docs/results/eval.{json,md}).
    #[arg(long, value_name = "classical|rl|hybrid", value_parser = <ControllerKind as std::str::FromStr>::from_str)]
    controller: Option<ControllerKind>,
    /// Task set.
    #[arg(long, default_value_os_t = workspace::data("tasks/eval-v1.tasks"))]
    tasks: PathBuf,
    /// Evaluate only the first N tasks.
    #[arg(long)]
    limit: Option<usize>,
    /// Override the lateral correction gain k_lat (1/s).
    #[arg(long)]
    lateral_gain: Option<f64>,
    /// Worker threads (0 = one per core); results do not depend on it.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Skip the independent re-check of every trajectory.
    #[arg(long)]
    no_check: bool,
    /// Name of the result files (default: the controller's name).
    #[arg(long)]
    name: Option<String>,
    /// Directory of the result files.
    #[arg(long, default_value_os_t = workspace::results_dir())]
    out_dir: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
    /// Policy weights of the learned controllers.
    #[arg(long, default_value_os_t = protocol::default_policy())]
    weights: PathBuf,
    /// Diffusion-seeder weights (protocol).
    #[arg(long, default_value_os_t = protocol::default_diffusion())]
    diffusion: PathBuf,
    /// Labels of the evaluation set, whose candidates give the reference lengths (protocol).
    #[arg(long, default_value_os_t = workspace::data("labels/eval-v1.labels"))]
    labels: PathBuf,
    /// Training tasks evaluated as the "seen" set (protocol).
    #[arg(long, default_value_os_t = workspace::data("tasks/train-v1.tasks"))]
    seen_tasks: PathBuf,
    /// Labels of the training tasks (protocol).
    #[arg(long, default_value_os_t = workspace::data("labels/train-v1.labels"))]
    seen_labels: PathBuf,
    /// How many training tasks form the "seen" set (protocol; 0 skips it).
    #[arg(long, default_value_t = 1000)]
    seen_count: usize,
    /// Run only the tasks with `index % n == i` (protocol) and write their per-task outcomes to
    /// `<out-dir>/eval-shards/`; join them with `--merge n`.
    #[arg(long, value_name = "i/n", conflicts_with = "merge")]
    shard: Option<emg_seeding::Shard>,
    /// Join the outcomes of shards `0/n … (n−1)/n` into the tables (protocol).
    #[arg(long, value_name = "n")]
    merge: Option<usize>,
    /// Joint-velocity limits of the robot file: `on` (steps that would be too fast are slowed
    /// down in time) or `off` (unbounded joint speeds, the paper's setting).
    #[arg(long, value_enum, default_value_t = VelocityLimits::On)]
    velocity_limits: VelocityLimits,
    /// The work surface of each task (the plane through p0 with normal n): `on` keeps every link
    /// but the pen off it at every step, in the seeds, the references and the checks; `off` is
    /// the paper's protocol.
    #[arg(long, value_enum, default_value_t = Surface::Off)]
    surface: Surface,
    /// Evaluate only the tasks whose work surface clears the arm (all but the pen) at q0_seed
    /// by M metres: the tasks a real cell can pose, as `make-tasks --surface-clearance` samples
    /// them (protocol; not with --shard).
    #[arg(long, value_name = "M", value_parser = workspace::non_negative, conflicts_with_all = ["shard", "merge"])]
    surface_clearance: Option<f64>,
    /// Instead of the protocol: DP seeds × every controller with the velocity limits off and on,
    /// path length and duration compared (docs/results/velocity-limits.{json,md}).
    #[arg(long, conflicts_with_all = ["controller", "shard", "merge"])]
    compare_velocity_limits: bool,
}

/// Whether the work surface is a constraint of an evaluation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
enum Surface {
    /// The arm keeps off the work surface's whole half-space (the strictest surface: the
    /// sampled tasks of `--surface-clearance` keep it clear at their start).
    On,
    /// The paper's protocol: the surface is ignored.
    Off,
}

impl Surface {
    /// Sets the constraint in `constraints`.
    fn apply(self, constraints: &mut emg_control::ConstraintConfig) {
        constraints.work_surface = match self {
            Self::On => emg_kinematics::WorkSurface::HalfSpace,
            Self::Off => emg_kinematics::WorkSurface::Off,
        };
    }
}

/// The numbers of one evaluation: identical for any thread count.
#[derive(Serialize)]
struct EvalResult {
    controller: ControllerKind,
    tasks: String,
    task_count: usize,
    seed: &'static str,
    rollout: RolloutConfig,
    executor: ExecutorConfig,
    weights: Option<String>,
    path_length_m: Summary,
    steps: Summary,
    termination: BTreeMap<String, usize>,
    joint_limit_by_joint: BTreeMap<usize, usize>,
    independently_checked: usize,
}

/// Runs the protocol, or one controller with `--controller`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let pool = workspace::thread_pool(args.threads)?;
    if args.compare_velocity_limits {
        return pool.install(|| {
            let mut setup = protocol::load_setup(&args.robot, &args.weights, &args.diffusion)?;
            velocity_limits::run(&mut setup, &args.tasks, args.limit, &args.out_dir)
        });
    }
    match args.controller {
        None => pool.install(|| run_protocol(args)),
        Some(kind) => run_controller(args, kind, &pool),
    }
}

/// The seed × controller protocol on the unseen evaluation set and the seen training slice: the
/// whole run, one shard of it, or the merge of all shards (same tables as the whole run).
fn run_protocol(args: &Args) -> anyhow::Result<()> {
    let started = Instant::now();
    let name = args.name.clone().unwrap_or_else(|| "eval".into());
    let raw_sets = match args.merge {
        Some(n) => merged_shards(args, &name, n)?,
        None => match computed_sets(args, &name)? {
            Some(sets) => sets,
            None => return Ok(()),
        },
    };
    write_protocol(args, &name, &raw_sets, started)
}

/// Where shard `index` of `count` of the run `name` is kept.
fn shard_path(shard_dir: &Path, name: &str, index: usize, count: usize) -> PathBuf {
    shard_dir.join(format!("{name}-shard-{index}-of-{count}.json"))
}

/// The sets of the run `name` merged from its `n` shards, each computed from the same inputs.
fn merged_shards(args: &Args, name: &str, n: usize) -> anyhow::Result<Vec<RawSet>> {
    let shard_dir = args.out_dir.join("eval-shards");
    anyhow::ensure!(n > 0, "--merge needs the number of shards (at least 1)");
    let mut shards = Vec::new();
    for i in 0..n {
        let path = shard_path(&shard_dir, name, i, n);
        let shard = ShardFile::read(&path)?.with_context(|| {
            format!(
                "{} is missing (run `cargo xtask eval --shard {i}/{n}`)",
                path.display()
            )
        })?;
        if let Some(first) = shards.first().map(|first: &ShardFile| &first.inputs) {
            anyhow::ensure!(
                shard.inputs == *first,
                "{} was computed from other inputs than shard 0/{n} ({:?} against {:?}); \
                 rerun the shards with the same options",
                path.display(),
                shard.inputs,
                first
            );
        }
        shards.push(shard);
    }
    let mut shard_sets: Vec<Vec<RawSet>> = shards.into_iter().map(|s| s.sets).collect();
    let mut merged = Vec::new();
    while !shard_sets[0].is_empty() {
        let parts = shard_sets.iter_mut().map(|sets| sets.remove(0)).collect();
        merged.push(merge_sets(parts)?);
    }
    Ok(merged)
}

/// The run's sets computed here: all of them, or the shard `--shard` names; `None` where that
/// shard is written to its file (or was already done) and nothing is left to summarise.
fn computed_sets(args: &Args, name: &str) -> anyhow::Result<Option<Vec<RawSet>>> {
    let shard_dir = args.out_dir.join("eval-shards");
    let inputs = args.shard.map(|_| ShardInputs::of(args)).transpose()?;
    if let (Some(s), Some(inputs)) = (args.shard, &inputs) {
        let path = shard_path(&shard_dir, name, s.index, s.count);
        match ShardFile::read(&path)? {
            Some(done) if done.inputs == *inputs => {
                println!(
                    "shard {}/{} is already done ({}); skipped (remove the file to redo it)",
                    s.index,
                    s.count,
                    path.display()
                );
                return Ok(None);
            }
            Some(_) => println!(
                "{} was computed from other inputs; computing shard {}/{} again",
                path.display(),
                s.index,
                s.count
            ),
            None => {}
        }
    }
    let mut setup = protocol::load_setup(&args.robot, &args.weights, &args.diffusion)?;
    args.velocity_limits.apply(&mut setup.rollout.constraints);
    args.surface.apply(&mut setup.rollout.constraints);
    let selection = Selection {
        shard: args.shard.map(|s| (s.index, s.count)),
        surface_clearance_m: args.surface_clearance,
    };
    let mut sets = vec![protocol_set(
        &setup,
        "unseen",
        &args.tasks,
        &args.labels,
        args.limit,
        &selection,
    )?];
    if args.seen_count > 0 {
        sets.push(protocol_set(
            &setup,
            "seen",
            &args.seen_tasks,
            &args.seen_labels,
            Some(args.seen_count),
            &selection,
        )?);
    }
    if let (Some(s), Some(inputs)) = (args.shard, inputs) {
        let path = shard_path(&shard_dir, name, s.index, s.count);
        let file = ShardFile { inputs, sets };
        emg_io::write_atomically(&path, serde_json::to_string(&file)?)?;
        println!(
            "shard {}/{} done; wrote {}",
            s.index,
            s.count,
            path.display()
        );
        return Ok(None);
    }
    Ok(Some(sets))
}

/// Summarises `raw_sets` and writes the run `name`'s record and its tables, with the wall time
/// of the whole run `started` then.
fn write_protocol(
    args: &Args,
    name: &str,
    raw_sets: &[RawSet],
    started: Instant,
) -> anyhow::Result<()> {
    let buckets = BucketConfig::default();
    let sets = raw_sets
        .iter()
        .map(|raw| summarize(raw, &buckets))
        .collect::<Result<Vec<_>, _>>()?;
    let seconds = started.elapsed().as_secs_f64();
    let mut rollout = RolloutConfig::default();
    args.velocity_limits.apply(&mut rollout.constraints);
    args.surface.apply(&mut rollout.constraints);
    let record = EvalRecord {
        rollout,
        executor: ExecutorConfig::default(),
        buckets,
        policy: workspace::relative(&args.weights),
        diffusion: workspace::relative(&args.diffusion),
        sets,
        surface_clearance_m: args.surface_clearance,
    };
    let mut md = format!(
        "# Evaluation protocol: seeds × controllers\n\nWritten by `cargo xtask eval`. Do not edit by hand. \
         Every trajectory behind these tables passed the independent checker. Unseen = the evaluation set \
         (disjoint from every training set); seen = the first {} tasks of the training pool.\n\n{}",
        args.seen_count,
        surface_note(args)
    );
    for set in &record.sets {
        md += &protocol_markdown(set);
        md += "\n";
    }
    md += &match args.merge {
        Some(n) => format!(
            "## Run\n\nMerged from {n} shards (`cargo xtask eval --shard i/{n}`, then `--merge {n}`).\n"
        ),
        None => format!(
            "## Run\n\nWhole protocol (seeds, references, {} rollouts per set and seed, checks): {seconds:.1} s wall on {} threads ({}).\n",
            ControllerKind::ALL.len(),
            rayon::current_num_threads(),
            workspace::machine()
        ),
    };
    workspace::write_results(&args.out_dir, name, &record, &md)
}

/// What the run says about the work surface: a constraint or not, and which tasks it kept.
fn surface_note(args: &Args) -> String {
    let mut note = match args.surface {
        Surface::On => "Work surface on: every link but the pen stays on the free side of the plane \
                        through p0 with normal n, at every step, in the seeds and references and in \
                        the checks. "
            .to_string(),
        Surface::Off => "Work surface off (the paper's protocol). ".to_string(),
    };
    if let Some(clearance) = args.surface_clearance {
        note += &format!(
            "Only the tasks whose work surface clears the arm (all but the pen) by {:.0} mm at \
             q0_seed: those a real cell can pose. ",
            clearance * 1e3
        );
    }
    note + "\n\n"
}

/// What a protocol shard was computed from: rerunning a shard whose file holds the same inputs
/// skips it (a re-submitted job array redoes only what is missing), and a merge refuses shards of
/// different inputs.
#[derive(Debug, PartialEq, Serialize, Deserialize)]
struct ShardInputs {
    /// SHA-256 of every input file, by its option name.
    files: BTreeMap<String, String>,
    /// `--limit`.
    limit: Option<usize>,
    /// `--seen-count`.
    seen_count: usize,
    /// `--velocity-limits`.
    velocity_limits: VelocityLimits,
    /// `--surface`.
    #[serde(default = "surface_off")]
    surface: Surface,
}

/// The surface setting of shards written before it was an option.
fn surface_off() -> Surface {
    Surface::Off
}

impl ShardInputs {
    /// The inputs `args` name.
    fn of(args: &Args) -> anyhow::Result<Self> {
        let mut files = BTreeMap::new();
        let mut inputs = vec![
            ("robot", &args.robot),
            ("tasks", &args.tasks),
            ("labels", &args.labels),
            ("weights", &args.weights),
            ("diffusion", &args.diffusion),
        ];
        if args.seen_count > 0 {
            inputs.extend([
                ("seen-tasks", &args.seen_tasks),
                ("seen-labels", &args.seen_labels),
            ]);
        }
        for (option, path) in inputs {
            let digest = emg_seeding::file_sha256(path)
                .with_context(|| format!("hashing the --{option} file"))?;
            files.insert(option.to_string(), emg_seeding::hex(&digest));
        }
        Ok(Self {
            files,
            limit: args.limit,
            seen_count: args.seen_count,
            velocity_limits: args.velocity_limits,
            surface: args.surface,
        })
    }
}

/// One protocol shard's file in `<out-dir>/eval-shards/`: its inputs and raw per-task outcomes.
#[derive(Serialize, Deserialize)]
struct ShardFile {
    inputs: ShardInputs,
    sets: Vec<RawSet>,
}

impl ShardFile {
    /// The shard file at `path`, or `None` when there is none.
    fn read(path: &Path) -> anyhow::Result<Option<Self>> {
        match std::fs::read_to_string(path) {
            Ok(text) => Ok(Some(serde_json::from_str(&text).with_context(|| {
                format!(
                    "{} is not a shard file of this version (remove it to redo the shard)",
                    path.display()
                )
            })?)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(e).with_context(|| format!("reading {}", path.display())),
        }
    }
}

/// One controller from every task's q0_seed.
fn run_controller(
    args: &Args,
    kind: ControllerKind,
    pool: &rayon::ThreadPool,
) -> anyhow::Result<()> {
    let robot = workspace::load_robot(&args.robot)?;
    let mut tasks = read_tasks(&args.tasks, &robot).with_context(|| {
        format!(
            "reading {} (create it with `cargo xtask make-tasks`)",
            args.tasks.display()
        )
    })?;
    if let Some(limit) = args.limit {
        tasks.truncate(limit);
    }
    if tasks.iter().any(|t| t.q0_seed.is_none()) {
        bail!("every evaluation task needs its q0_seed");
    }
    let mut rollout = RolloutConfig::default();
    args.velocity_limits.apply(&mut rollout.constraints);
    if let Some(gain) = args.lateral_gain {
        rollout.lateral_gain_per_s = gain;
    }
    let executor = ExecutorConfig::default();
    let policy = if kind.needs_policy() {
        Some(emg_planner::load_policy(&robot, &args.weights)?)
    } else {
        None
    };
    let prototype = Executor::new(kind, policy.as_ref(), &executor)?;
    let seed_of = |task: &Task| task.q0_seed.expect("checked above");

    let bar = progress::bar(tasks.len() as u64, "rollouts");
    let started = Instant::now();
    let trajectories = pool.install(|| {
        rollout_all(
            &robot,
            &tasks,
            seed_of,
            || prototype.clone(),
            &rollout,
            &|| bar.inc(1),
        )
    });
    let rollout_seconds = started.elapsed().as_secs_f64();
    bar.finish();

    let mut check_seconds = None;
    let mut checked = 0;
    if !args.no_check {
        let checker = workspace::load_checker(&args.robot, &robot)?;
        let started = Instant::now();
        pool.install(|| check_trajectories(&checker, &tasks, &trajectories, &rollout.constraints))?;
        checked = tasks.len();
        check_seconds = Some(started.elapsed().as_secs_f64());
    }

    let lengths: Vec<f64> = trajectories.iter().map(|t| t.path_length_m).collect();
    let steps: Vec<f64> = trajectories
        .iter()
        .map(|t| (t.steps.len() - 1) as f64)
        .collect();
    let result = EvalResult {
        controller: kind,
        tasks: workspace::relative(&args.tasks),
        task_count: tasks.len(),
        seed: "q0_seed",
        rollout,
        executor,
        weights: policy.is_some().then(|| workspace::relative(&args.weights)),
        path_length_m: Summary::of(&lengths).context("no tasks to evaluate")?,
        steps: Summary::of(&steps).context("no tasks to evaluate")?,
        termination: termination_histogram(&trajectories),
        joint_limit_by_joint: joint_limit_histogram(&trajectories),
        independently_checked: checked,
    };
    let name = args.name.clone().unwrap_or_else(|| kind.name().into());
    let md = markdown(
        &result,
        rollout_seconds,
        check_seconds,
        pool.current_num_threads(),
    );
    println!(
        "path length mean {:.3} m (std {:.3}, min {:.3}, max {:.3}) over {} tasks; rollouts {:.2} s wall",
        result.path_length_m.mean,
        result.path_length_m.std,
        result.path_length_m.min,
        result.path_length_m.max,
        result.task_count,
        rollout_seconds
    );
    workspace::write_results(&args.out_dir, &name, &result, &md)
}

fn markdown(
    result: &EvalResult,
    rollout_seconds: f64,
    check_seconds: Option<f64>,
    threads: usize,
) -> String {
    let s = &result.path_length_m;
    let mut md = format!(
        "# Evaluation: {name} controller from q0_seed\n\n\
         Written by `cargo xtask eval --controller {name}` on {tasks} ({count} tasks, k_lat = {k_lat} 1/s). \
         Do not edit by hand.\n\n\
         | path length (m) | mean | std | min | max |\n|---|---|---|---|---|\n\
         | {count} tasks | {:.3} | {:.3} | {:.3} | {:.3} |\n\n\
         Steps per rollout: mean {:.1}, max {:.0}.\n\n## Termination\n\n| reason | tasks | share |\n|---|---|---|\n",
        s.mean,
        s.std,
        s.min,
        s.max,
        result.steps.mean,
        result.steps.max,
        name = result.controller.name(),
        tasks = result.tasks,
        count = result.task_count,
        k_lat = result.rollout.lateral_gain_per_s,
    );
    for (reason, n) in &result.termination {
        md += &format!(
            "| {reason} | {n} | {:.1} % |\n",
            100.0 * *n as f64 / result.task_count as f64
        );
    }
    md += "\n## Joint limits reached\n\n| joint | tasks |\n|---|---|\n";
    for (joint, n) in &result.joint_limit_by_joint {
        md += &format!("| {joint} | {n} |\n");
    }
    md += &format!(
        "\n## Run\n\nRollouts: {rollout_seconds:.2} s wall on {threads} threads ({}).\n",
        workspace::machine()
    );
    if let Some(check) = check_seconds {
        md += &format!(
            "Independent check: all {} trajectories pass, {check:.2} s wall.\n",
            result.independently_checked
        );
    }
    md
}

/// The protocol's raw outcomes on the task file `tasks_path` (its first `limit` tasks) with the
/// labels `labels_path`, for the whole set or one shard.
fn protocol_set(
    setup: &emg_eval::Setup,
    name: &str,
    tasks_path: &std::path::Path,
    labels_path: &std::path::Path,
    limit: Option<usize>,
    selection: &Selection,
) -> anyhow::Result<RawSet> {
    let mut tasks = read_tasks(tasks_path, &setup.robot)?;
    if let Some(limit) = limit {
        tasks.truncate(limit);
    }
    let labels = emg_seeding::LabelSet::read(labels_path).with_context(|| {
        format!(
            "reading {} (create it with `cargo xtask label-seeds`)",
            labels_path.display()
        )
    })?;
    let indices = selection.indices(&setup.robot, &tasks)?;
    println!("{name}: {} of {} tasks", indices.len(), tasks.len());
    Ok(run_set(
        setup,
        name,
        &workspace::relative(tasks_path),
        &tasks,
        &indices,
        &labels,
    )?)
}

/// Which tasks of a set a protocol run evaluates.
struct Selection {
    /// Only the tasks with `index % n == i`.
    shard: Option<(usize, usize)>,
    /// Only the tasks whose work surface clears the arm at `q0_seed` by this much (m).
    surface_clearance_m: Option<f64>,
}

impl Selection {
    /// The indices of the selected tasks, in order.
    fn indices(&self, robot: &emg_kinematics::Robot, tasks: &[Task]) -> anyhow::Result<Vec<usize>> {
        let mut indices = Vec::new();
        for (index, task) in tasks.iter().enumerate() {
            if self.shard.is_some_and(|(i, n)| index % n != i) {
                continue;
            }
            if let Some(clearance) = self.surface_clearance_m {
                let seed = task.q0_seed.with_context(|| {
                    format!("task {index} has no q0_seed to test its work surface against")
                })?;
                if !emg_control::surface_clears(robot, task, &robot.forward(&seed), clearance) {
                    continue;
                }
            }
            indices.push(index);
        }
        Ok(indices)
    }
}
