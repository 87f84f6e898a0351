//! The seed × controller protocol of Sec. 5 (`cargo xtask eval` without `--controller`):
//! seeds q0_seed, q_μ, q_jl and DP; controllers classical, RL and hybrid; per-task reference
//! lengths from the label candidates; difficulty buckets; the paper's Tables 1 and 2, on the
//! evaluation set (tasks never seen in training) and on a slice of the training pool (seen).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use emg_control::{
    ConstraintConfig, ReferenceModel, RolloutConfig, Summary, Task, Trajectory, read_tasks,
    rollout_from,
};
use emg_diffusion::{DenoiserWeights, DpSeedConfig, DpSeeder, SeedWorkspace};
use emg_hybrid::{
    BucketConfig, CellStats, ControllerKind, Executor, ExecutorConfig, bucket_members, cell_stats,
    count_switches,
};
use emg_kinematics::{JointVector, ProjectionConfig, Robot};
use emg_policy::{PolicyWeights, RlController};
use emg_seeding::{HeuristicConfig, HeuristicObjective, LabelSet, heuristic_seed};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::{progress, workspace};

/// Where a rollout's starting configuration comes from (Table 2's rows).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SeedKind {
    /// The configuration that generated the task.
    Q0Seed,
    /// Directional-manipulability ascent from `q0_seed` (`q_μ`).
    QMu,
    /// Joint-centring ascent from `q0_seed` (`q_jl`).
    QJl,
    /// The diffusion seeder (DP).
    Dp,
}

impl SeedKind {
    /// All seeds in table order.
    pub const ALL: [SeedKind; 4] = [Self::Q0Seed, Self::QMu, Self::QJl, Self::Dp];

    /// Name in result files (`q0_seed`, `q_mu`, `q_jl`, `dp`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Q0Seed => "q0_seed",
            Self::QMu => "q_mu",
            Self::QJl => "q_jl",
            Self::Dp => "dp",
        }
    }

    /// Name for tables.
    pub fn title(self) -> &'static str {
        match self {
            Self::Q0Seed => "q0_seed",
            Self::QMu => "q_μ",
            Self::QJl => "q_jl",
            Self::Dp => "DP",
        }
    }
}

/// Everything the protocol runs with, loaded once.
pub struct Setup {
    /// The robot.
    pub robot: Robot,
    /// Its independent checker.
    pub checker: ReferenceModel,
    /// Rollout settings.
    pub rollout: RolloutConfig,
    /// Controller settings.
    pub executor: ExecutorConfig,
    /// The trained policy.
    pub policy: RlController,
    /// The diffusion seeder.
    pub dp: DpSeeder,
    /// Heuristic-seed settings.
    pub heuristic: HeuristicConfig,
    /// Projection settings of the heuristic seeds.
    pub projection: ProjectionConfig,
}

impl Setup {
    /// Loads the robot, the shipped policy and diffusion weights.
    pub fn load(
        robot_path: &Path,
        policy_path: &Path,
        diffusion_path: &Path,
    ) -> anyhow::Result<Self> {
        let robot = workspace::load_robot(robot_path)?;
        let checker = workspace::load_checker(robot_path, &robot)?;
        let diffusion = DenoiserWeights::read(diffusion_path).context(
            "loading the diffusion seeder (train it with `cargo xtask train-diffusion`)",
        )?;
        Ok(Self {
            robot,
            checker,
            rollout: RolloutConfig::default(),
            executor: ExecutorConfig::default(),
            policy: load_policy(policy_path)?,
            dp: DpSeeder::new(&diffusion, DpSeedConfig::default())?,
            heuristic: HeuristicConfig::default(),
            projection: ProjectionConfig::default(),
        })
    }

    /// Seeds of `kind` for every task and their generation times (ms), in parallel.
    pub fn seeds(
        &self,
        tasks: &[Task],
        kind: SeedKind,
    ) -> anyhow::Result<(Vec<JointVector>, Vec<f64>)> {
        let bar = progress::bar(tasks.len() as u64, kind.title());
        let seeds: Vec<anyhow::Result<(JointVector, f64)>> = tasks
            .par_iter()
            .map_init(SeedWorkspace::default, |workspace, task| {
                let q0 = task
                    .q0_seed
                    .context("every evaluated task needs its q0_seed")?;
                let seed = match kind {
                    SeedKind::Q0Seed => (q0, 0.0),
                    SeedKind::QMu | SeedKind::QJl => {
                        let objective = if kind == SeedKind::QMu {
                            HeuristicObjective::Manipulability
                        } else {
                            HeuristicObjective::JointCentring
                        };
                        let started = Instant::now();
                        match heuristic_seed(
                            &self.robot,
                            task,
                            objective,
                            &self.heuristic,
                            &self.projection,
                        ) {
                            Ok(seed) => (seed.q, seed.generation_time.as_secs_f64() * 1e3),
                            Err(_) => (q0, started.elapsed().as_secs_f64() * 1e3),
                        }
                    }
                    SeedKind::Dp => {
                        let seed = self.dp.seed(
                            &self.robot,
                            task,
                            &self.rollout.constraints,
                            workspace,
                        )?;
                        (seed.q, seed.elapsed.as_secs_f64() * 1e3)
                    }
                };
                bar.inc(1);
                Ok(seed)
            })
            .collect();
        bar.finish_and_clear();
        let seeds = seeds.into_iter().collect::<anyhow::Result<Vec<_>>>()?;
        Ok(seeds.into_iter().unzip())
    }

    /// Rollouts of `controller` from `seeds`, every one re-checked independently.
    pub fn rollouts(
        &self,
        tasks: &[Task],
        seeds: &[JointVector],
        controller: ControllerKind,
        executor: &ExecutorConfig,
        what: &str,
    ) -> anyhow::Result<Vec<Trajectory>> {
        let prototype = Executor::new(controller, Some(&self.policy), executor)?;
        let bar = progress::bar(tasks.len() as u64, what);
        let trajectories = rollout_from(
            &self.robot,
            tasks,
            seeds,
            || prototype.clone(),
            &self.rollout,
            &|| bar.inc(1),
        );
        bar.finish_and_clear();
        self.check(tasks, &trajectories)?;
        Ok(trajectories)
    }

    /// Runs the independent checker over every trajectory.
    pub fn check(&self, tasks: &[Task], trajectories: &[Trajectory]) -> anyhow::Result<()> {
        check_trajectories(
            &self.checker,
            tasks,
            trajectories,
            &self.rollout.constraints,
        )
    }

    /// Reference lengths `ℓ_ref`: the longest hybrid rollout over each task's label candidates
    /// (its `q0_seed` when it has none); `indices[i]` is task `i`'s index in the labelled set.
    pub fn references(
        &self,
        tasks: &[Task],
        indices: &[usize],
        labels: &LabelSet,
    ) -> anyhow::Result<Vec<f64>> {
        let mut owners = Vec::new();
        let mut candidates = Vec::new();
        for (i, task) in tasks.iter().enumerate() {
            let found: Vec<JointVector> = labels
                .get(indices[i] as u32)
                .map(|t| t.labels.iter().map(|l| l.q).collect())
                .unwrap_or_default();
            let found = if found.is_empty() {
                vec![task.q0_seed.context("task needs q0_seed")?]
            } else {
                found
            };
            for q in found {
                owners.push(i);
                candidates.push(q);
            }
        }
        let candidate_tasks: Vec<Task> = owners.iter().map(|&i| tasks[i].clone()).collect();
        let trajectories = self.rollouts(
            &candidate_tasks,
            &candidates,
            ControllerKind::Hybrid,
            &self.executor,
            "references",
        )?;
        let mut references = vec![0.0f64; tasks.len()];
        for (owner, trajectory) in owners.iter().zip(&trajectories) {
            references[*owner] = references[*owner].max(trajectory.path_length_m);
        }
        Ok(references)
    }
}

/// Re-checks every trajectory with the independent checker (in parallel); fails naming the first
/// offending task.
pub fn check_trajectories(
    checker: &ReferenceModel,
    tasks: &[Task],
    trajectories: &[Trajectory],
    constraints: &ConstraintConfig,
) -> anyhow::Result<()> {
    let failures: Vec<String> = tasks
        .par_iter()
        .zip(trajectories)
        .enumerate()
        .filter_map(|(i, (task, trajectory))| {
            checker
                .check(task, trajectory, constraints)
                .err()
                .map(|e| format!("task {i}: {e}"))
        })
        .collect();
    if let Some(first) = failures.first() {
        bail!(
            "{} trajectories fail the independent check, first: {first}",
            failures.len()
        );
    }
    Ok(())
}

/// Loads the trained policy as a controller.
pub fn load_policy(path: &Path) -> anyhow::Result<RlController> {
    let weights = PolicyWeights::read(path).with_context(|| {
        format!(
            "loading the policy {} (train it with `cargo xtask train-ppo`)",
            path.display()
        )
    })?;
    Ok(RlController::new(&weights))
}

/// One cell of a table: a seed, a controller, a group of tasks.
#[derive(Serialize)]
pub struct Cell {
    /// Seed source.
    pub seed: SeedKind,
    /// Controller.
    pub controller: ControllerKind,
    /// Task group (`all` or a bucket).
    pub group: String,
    /// Length and ratio statistics.
    pub stats: CellStats,
    /// Mean hand-overs per episode (hybrid only).
    pub switches_per_episode: Option<f64>,
}

/// The protocol's numbers on one task set.
#[derive(Serialize)]
pub struct SetResult {
    /// Which set: `unseen` (evaluation set) or `seen` (training pool slice).
    pub name: String,
    /// Task file.
    pub tasks: String,
    /// Tasks evaluated.
    pub task_count: usize,
    /// Reference lengths.
    pub reference_m: Summary,
    /// Tasks per bucket.
    pub buckets: BTreeMap<String, usize>,
    /// Seed generation time (ms) per seed source.
    pub seed_time_ms: BTreeMap<String, Summary>,
    /// Every cell.
    pub cells: Vec<Cell>,
    /// Per-task reference lengths (m), in task order.
    pub references_m: Vec<f64>,
    /// Per-task path lengths (m) from DP seeds, by controller name.
    pub dp_lengths_m: BTreeMap<String, Vec<f64>>,
}

/// Per-task outcomes of the protocol on a task set (or one shard of it), in task order: what
/// shards write and what the tables are computed from.
#[derive(Serialize, Deserialize)]
pub struct RawSet {
    /// Which set: `unseen` or `seen`.
    pub name: String,
    /// Task file.
    pub tasks: String,
    /// Indices of the evaluated tasks in the task file.
    pub indices: Vec<usize>,
    /// Reference lengths (m).
    #[serde(with = "exact")]
    pub references_m: Vec<f64>,
    /// Seed generation time (ms) per task, by seed name.
    #[serde(with = "exact_map")]
    pub seed_times_ms: BTreeMap<String, Vec<f64>>,
    /// Path length (m) per task, by `seed/controller`.
    #[serde(with = "exact_map")]
    pub lengths_m: BTreeMap<String, Vec<f64>>,
    /// Hand-overs per task of the hybrid controller, by seed name.
    #[serde(with = "exact_map")]
    pub switches: BTreeMap<String, Vec<f64>>,
}

/// Shard files store values as their IEEE-754 bits, so a merge reproduces a whole run exactly.
mod exact {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(values: &[f64], s: S) -> Result<S::Ok, S::Error> {
        values
            .iter()
            .map(|v| v.to_bits())
            .collect::<Vec<u64>>()
            .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        Ok(Vec::<u64>::deserialize(d)?
            .into_iter()
            .map(f64::from_bits)
            .collect())
    }
}

/// [`exact`] for maps of value lists.
mod exact_map {
    use std::collections::BTreeMap;

    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(
        map: &BTreeMap<String, Vec<f64>>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        map.iter()
            .map(|(k, v)| {
                (
                    k.clone(),
                    v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>(),
                )
            })
            .collect::<BTreeMap<_, _>>()
            .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<BTreeMap<String, Vec<f64>>, D::Error> {
        Ok(BTreeMap::<String, Vec<u64>>::deserialize(d)?
            .into_iter()
            .map(|(k, v)| (k, v.into_iter().map(f64::from_bits).collect()))
            .collect())
    }
}

fn cell_key(seed: SeedKind, controller: ControllerKind) -> String {
    format!("{}/{}", seed.name(), controller.name())
}

/// Runs the protocol on the tasks of `tasks_path` (the first `limit`; those with
/// `index % n == i` for `shard = Some((i, n))`), labels `labels_path`.
pub fn run_set(
    setup: &Setup,
    name: &str,
    tasks_path: &Path,
    labels_path: &Path,
    limit: Option<usize>,
    shard: Option<(usize, usize)>,
) -> anyhow::Result<RawSet> {
    let mut all = read_tasks(tasks_path, &setup.robot)?;
    if let Some(limit) = limit {
        all.truncate(limit);
    }
    let labels = LabelSet::read(labels_path).with_context(|| {
        format!(
            "reading {} (create it with `cargo xtask label-seeds`)",
            labels_path.display()
        )
    })?;
    let indices: Vec<usize> = (0..all.len())
        .filter(|i| shard.is_none_or(|(k, n)| i % n == k))
        .collect();
    let tasks: Vec<Task> = indices.iter().map(|&i| all[i].clone()).collect();
    println!("{name}: {} tasks", tasks.len());
    let references_m = setup.references(&tasks, &indices, &labels)?;
    let mut raw = RawSet {
        name: name.to_string(),
        tasks: workspace::relative(tasks_path),
        indices,
        references_m,
        seed_times_ms: BTreeMap::new(),
        lengths_m: BTreeMap::new(),
        switches: BTreeMap::new(),
    };
    for seed in SeedKind::ALL {
        let (seeds, times) = setup.seeds(&tasks, seed)?;
        raw.seed_times_ms.insert(seed.name().to_string(), times);
        for controller in ControllerKind::ALL {
            let what = format!("{}+{}", seed.title(), controller.name());
            let trajectories =
                setup.rollouts(&tasks, &seeds, controller, &setup.executor, &what)?;
            if controller == ControllerKind::Hybrid {
                let switches = trajectories
                    .iter()
                    .map(|t| count_switches(t) as f64)
                    .collect();
                raw.switches.insert(seed.name().to_string(), switches);
            }
            let lengths = trajectories.iter().map(|t| t.path_length_m).collect();
            raw.lengths_m.insert(cell_key(seed, controller), lengths);
        }
    }
    Ok(raw)
}

/// Joins shards of one set into the set in task order; every task must appear exactly once.
pub fn merge_sets(parts: Vec<RawSet>) -> anyhow::Result<RawSet> {
    let mut parts = parts.into_iter();
    let mut merged = parts.next().context("no shards to merge")?;
    let mut order: Vec<(usize, usize, usize)> = (0..merged.indices.len())
        .map(|k| (merged.indices[k], 0, k))
        .collect();
    let mut rest = Vec::new();
    for (p, part) in parts.enumerate() {
        anyhow::ensure!(
            part.name == merged.name && part.tasks == merged.tasks,
            "shard of {} ({}) does not belong to {} ({})",
            part.name,
            part.tasks,
            merged.name,
            merged.tasks
        );
        order.extend((0..part.indices.len()).map(|k| (part.indices[k], p + 1, k)));
        rest.push(part);
    }
    order.sort_unstable();
    for (position, (index, _, _)) in order.iter().enumerate() {
        anyhow::ensure!(
            *index == position,
            "{}: task {position} is missing or repeated across the shards",
            merged.name
        );
    }
    let sources: Vec<&RawSet> = std::iter::once(&merged).chain(&rest).collect();
    let pick = |get: &dyn Fn(&RawSet) -> &Vec<f64>| -> Vec<f64> {
        order.iter().map(|&(_, p, k)| get(sources[p])[k]).collect()
    };
    let references_m = pick(&|r| &r.references_m);
    let remap = |map: &BTreeMap<String, Vec<f64>>,
                 field: fn(&RawSet) -> &BTreeMap<String, Vec<f64>>| {
        map.keys()
            .map(|key| (key.clone(), pick(&|r| &field(r)[key])))
            .collect::<BTreeMap<_, _>>()
    };
    let seed_times_ms = remap(&merged.seed_times_ms, |r| &r.seed_times_ms);
    let lengths_m = remap(&merged.lengths_m, |r| &r.lengths_m);
    let switches = remap(&merged.switches, |r| &r.switches);
    merged.indices = (0..order.len()).collect();
    merged.references_m = references_m;
    merged.seed_times_ms = seed_times_ms;
    merged.lengths_m = lengths_m;
    merged.switches = switches;
    Ok(merged)
}

/// The tables of one set from its per-task outcomes.
pub fn summarize(raw: &RawSet, buckets: &BucketConfig) -> anyhow::Result<SetResult> {
    let references = &raw.references_m;
    let groups: Vec<(String, Vec<usize>)> =
        std::iter::once(("all".to_string(), (0..references.len()).collect()))
            .chain(
                bucket_members(references, buckets)
                    .into_iter()
                    .map(|(b, m)| (b.name().to_lowercase(), m)),
            )
            .collect();
    let mut cells = Vec::new();
    let mut seed_time_ms = BTreeMap::new();
    let mut dp_lengths_m = BTreeMap::new();
    for seed in SeedKind::ALL {
        seed_time_ms.insert(
            seed.title().to_string(),
            Summary::of(&raw.seed_times_ms[seed.name()]).context("no tasks")?,
        );
        for controller in ControllerKind::ALL {
            let lengths = &raw.lengths_m[&cell_key(seed, controller)];
            if seed == SeedKind::Dp {
                dp_lengths_m.insert(controller.name().to_string(), lengths.clone());
            }
            for (group, members) in &groups {
                let Some(stats) = cell_stats(lengths, references, members) else {
                    continue;
                };
                let switches_per_episode = (controller == ControllerKind::Hybrid).then(|| {
                    let switches = &raw.switches[seed.name()];
                    members.iter().map(|&i| switches[i]).sum::<f64>() / members.len() as f64
                });
                cells.push(Cell {
                    seed,
                    controller,
                    group: group.clone(),
                    stats,
                    switches_per_episode,
                });
            }
        }
    }
    Ok(SetResult {
        name: raw.name.clone(),
        tasks: raw.tasks.clone(),
        task_count: references.len(),
        reference_m: Summary::of(references).context("no tasks")?,
        buckets: groups[1..]
            .iter()
            .map(|(g, m)| (g.clone(), m.len()))
            .collect(),
        seed_time_ms,
        cells,
        references_m: references.clone(),
        dp_lengths_m,
    })
}

/// `mean / std / min / max` with the given precision.
pub fn four(summary: &Summary, decimals: usize) -> String {
    format!(
        "{:.d$} / {:.d$} / {:.d$} / {:.d$}",
        summary.mean,
        summary.std,
        summary.min,
        summary.max,
        d = decimals
    )
}

/// Markdown of one set's Tables 1 and 2.
pub fn markdown(set: &SetResult) -> String {
    let mut md = format!(
        "### {} tasks ({}, n = {})\n\nReference length ℓ_ref (m): {}. Buckets: {}.\n\n",
        set.name,
        set.tasks,
        set.task_count,
        four(&set.reference_m, 3),
        set.buckets
            .iter()
            .map(|(b, n)| format!("{b} {n}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    md += "**Table 1**: DP seed, three controllers, by difficulty.\n\n| tasks | π | path length (m) mean / std / min / max | ratio to ℓ_ref (%) mean / std / min / max | switches / episode |\n|---|---|---|---|---|\n";
    for group in ["all", "easy", "medium", "difficult"] {
        for cell in set
            .cells
            .iter()
            .filter(|c| c.seed == SeedKind::Dp && c.group == group)
        {
            md += &format!(
                "| {group} (n = {}) | {} | {} | {} | {} |\n",
                cell.stats.length_m.count,
                cell.controller.title(),
                four(&cell.stats.length_m, 3),
                four(&cell.stats.ratio_percent, 1),
                cell.switches_per_episode
                    .map_or("—".into(), |s| format!("{s:.2}"))
            );
        }
    }
    md += "\n**Table 2**: seeds × controllers, all tasks; t = per-task seed time (ms, mean).\n\n| π | q₀* | t (ms) | path length (m) | ratio to ℓ_ref (%) |\n|---|---|---|---|---|\n";
    for controller in ControllerKind::ALL {
        for cell in set
            .cells
            .iter()
            .filter(|c| c.controller == controller && c.group == "all")
        {
            md += &format!(
                "| {} | {} | {:.2} | {} | {} |\n",
                controller.title(),
                cell.seed.title(),
                set.seed_time_ms[cell.seed.title()].mean,
                four(&cell.stats.length_m, 3),
                four(&cell.stats.ratio_percent, 1)
            );
        }
    }
    md
}

/// Default paths of the shipped models.
pub fn default_policy() -> PathBuf {
    workspace::data("models/ppo-v1.weights")
}

/// Default path of the shipped diffusion weights.
pub fn default_diffusion() -> PathBuf {
    workspace::data("models/diffusion-v1.weights")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(indices: Vec<usize>, scale: f64) -> RawSet {
        let values = |offset: f64| {
            indices
                .iter()
                .map(|&i| offset + i as f64 * scale)
                .collect::<Vec<_>>()
        };
        RawSet {
            name: "unseen".into(),
            tasks: "tasks".into(),
            references_m: values(1.0),
            seed_times_ms: [("dp".to_string(), values(0.5))].into(),
            lengths_m: [("dp/hybrid".to_string(), values(0.25))].into(),
            switches: [("dp".to_string(), values(0.0))].into(),
            indices,
        }
    }

    #[test]
    fn merged_shards_equal_the_whole_set_bit_for_bit() {
        let whole = raw((0..7).collect(), 0.1);
        let shards = vec![
            raw(vec![1, 4], 0.1),
            raw(vec![0, 3, 6], 0.1),
            raw(vec![2, 5], 0.1),
        ];
        let text = serde_json::to_string(&shards).unwrap();
        let shards: Vec<RawSet> = serde_json::from_str(&text).unwrap();
        let merged = merge_sets(shards).unwrap();
        assert_eq!(
            serde_json::to_string(&merged).unwrap(),
            serde_json::to_string(&whole).unwrap()
        );
    }

    #[test]
    fn a_missing_or_repeated_task_is_refused() {
        let error = merge_sets(vec![raw(vec![0, 2], 1.0), raw(vec![2, 3], 1.0)])
            .err()
            .unwrap();
        assert!(
            error.to_string().contains("task 1 is missing or repeated"),
            "{error}"
        );
    }
}
