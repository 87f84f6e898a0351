//! The seeds × controllers protocol of Sec. 5 (Tables 1 and 2): per-task outcomes of every seed
//! source and controller on a task set, joined across shards bit for bit, summarised per
//! difficulty bucket, and the typed result file the report reads.

use std::collections::BTreeMap;

use emg_control::{RolloutConfig, Task};
use emg_hybrid::count_switches;
use emg_planner::{ControllerKind, ExecutorConfig, SeedSource};
use emg_seeding::LabelSet;
use serde::{Deserialize, Serialize};

use crate::batch::Summary;
use crate::buckets::{BucketConfig, CellStats, MIN_REFERENCE_M, bucket_members, cell_stats};
use crate::setup::{EvalError, Setup};

/// The whole result file of the protocol (`docs/results/eval.json`): the settings it ran with
/// and each task set's tables.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EvalRecord {
    /// Rollout settings.
    pub rollout: RolloutConfig,
    /// Controller settings.
    pub executor: ExecutorConfig,
    /// Difficulty thresholds.
    pub buckets: BucketConfig,
    /// Policy weights file (relative to the workspace).
    pub policy: String,
    /// Diffusion weights file (relative to the workspace).
    pub diffusion: String,
    /// Each task set's tables (`unseen`, then `seen` when run).
    pub sets: Vec<SetResult>,
    /// When only the tasks a cell can pose were evaluated: the clearance (m) by which their work
    /// surface clears the arm at `q0_seed`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_clearance_m: Option<f64>,
}

impl EvalRecord {
    /// The set called `name`.
    pub fn set(&self, name: &str) -> Option<&SetResult> {
        self.sets.iter().find(|s| s.name == name)
    }
}

impl SetResult {
    /// The cells of `seed` (a [`SeedSource::name`]) for task group `group`, in controller order.
    pub fn cells<'a>(&'a self, seed: &'a str, group: &'a str) -> impl Iterator<Item = &'a Cell> {
        self.cells
            .iter()
            .filter(move |c| c.seed == seed && c.group == group)
    }

    /// The cell of `seed`, `controller` and `group`, if present.
    pub fn cell(&self, seed: &str, controller: ControllerKind, group: &str) -> Option<&Cell> {
        self.cells
            .iter()
            .find(|c| c.seed == seed && c.group == group && c.controller == controller)
    }
}

/// One cell of a table: a seed, a controller, a group of tasks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cell {
    /// Seed source ([`SeedSource::name`]).
    pub seed: String,
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    /// Seed generation time (ms) per seed source, by its table title ([`SeedSource::title`]).
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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

/// The seed sources of the protocol's rows (Table 2), in table order.
pub const PROTOCOL_SEEDS: [SeedSource; 4] = [
    SeedSource::Generating,
    SeedSource::QMu,
    SeedSource::QJl,
    SeedSource::Dp,
];

/// The table title of the protocol seed called `name` (the name itself for any other).
fn seed_title(name: &str) -> &str {
    PROTOCOL_SEEDS
        .iter()
        .find(|s| s.name() == name)
        .map_or(name, |s| s.title())
}

fn cell_key(seed: &SeedSource, controller: ControllerKind) -> String {
    format!("{}/{}", seed.name(), controller.name())
}

/// Runs the protocol on the tasks of `all` at `indices` (in order; a shard's, or those a cell can
/// pose), named `tasks` in the results, with their `labels` (looked up by index into `all`).
pub fn run_set(
    setup: &Setup,
    name: &str,
    tasks: &str,
    all: &[Task],
    indices: &[usize],
    labels: &LabelSet,
) -> Result<RawSet, EvalError> {
    let indices = indices.to_vec();
    let picked: Vec<Task> = indices.iter().map(|&i| all[i].clone()).collect();
    let references_m = setup.references(&picked, &indices, labels)?;
    let tasks_name = tasks;
    let tasks = picked;
    let mut raw = RawSet {
        name: name.to_string(),
        tasks: tasks_name.to_string(),
        indices,
        references_m,
        seed_times_ms: BTreeMap::new(),
        lengths_m: BTreeMap::new(),
        switches: BTreeMap::new(),
    };
    for seed in &PROTOCOL_SEEDS {
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
pub fn merge_sets(parts: Vec<RawSet>) -> Result<RawSet, EvalError> {
    let mut parts = parts.into_iter();
    let mut merged = parts
        .next()
        .ok_or_else(|| EvalError::Merge("no shards to merge".into()))?;
    let mut order: Vec<(usize, usize, usize)> = (0..merged.indices.len())
        .map(|k| (merged.indices[k], 0, k))
        .collect();
    let mut rest = Vec::new();
    for (p, part) in parts.enumerate() {
        if part.name != merged.name || part.tasks != merged.tasks {
            return Err(EvalError::Merge(format!(
                "shard of {} ({}) does not belong to {} ({})",
                part.name, part.tasks, merged.name, merged.tasks
            )));
        }
        order.extend((0..part.indices.len()).map(|k| (part.indices[k], p + 1, k)));
        rest.push(part);
    }
    order.sort_unstable();
    for (position, (index, _, _)) in order.iter().enumerate() {
        if *index != position {
            return Err(EvalError::Merge(format!(
                "{}: task {position} is missing or repeated across the shards",
                merged.name
            )));
        }
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
pub fn summarize(raw: &RawSet, buckets: &BucketConfig) -> Result<SetResult, EvalError> {
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
    for seed in &PROTOCOL_SEEDS {
        seed_time_ms.insert(
            seed.title().to_string(),
            Summary::of(&raw.seed_times_ms[seed.name()]).ok_or(EvalError::NoTasks)?,
        );
        for controller in ControllerKind::ALL {
            let lengths = &raw.lengths_m[&cell_key(seed, controller)];
            if *seed == SeedSource::Dp {
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
                    seed: seed.name().to_string(),
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
        reference_m: Summary::of(references).ok_or(EvalError::NoTasks)?,
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
    let stuck = set
        .references_m
        .iter()
        .filter(|r| **r < MIN_REFERENCE_M)
        .count();
    if stuck > 0 {
        md += &format!(
            "{stuck} tasks have ℓ_ref < {:.0} cm (none of their labelled starts gets that far \
             under the constraints): they count in the lengths, not in the ratios.\n\n",
            MIN_REFERENCE_M * 100.0
        );
    }
    md += "**Table 1**: DP seed, three controllers, by difficulty.\n\n| tasks | π | path length (m) mean / std / min / max | ratio to ℓ_ref (%) mean / std / min / max | switches / episode |\n|---|---|---|---|---|\n";
    for group in ["all", "easy", "medium", "difficult"] {
        for cell in set
            .cells
            .iter()
            .filter(|c| c.seed == SeedSource::Dp.name() && c.group == group)
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
            let seed = seed_title(&cell.seed);
            md += &format!(
                "| {} | {} | {:.2} | {} | {} |\n",
                controller.title(),
                seed,
                set.seed_time_ms[seed].mean,
                four(&cell.stats.length_m, 3),
                four(&cell.stats.ratio_percent, 1)
            );
        }
    }
    md
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
        let error = merge_sets(vec![raw(vec![0, 2], 1.0), raw(vec![2, 3], 1.0)]).unwrap_err();
        assert!(
            error.to_string().contains("task 1 is missing or repeated"),
            "{error}"
        );
    }
}
