//! Resumable, sharded labelling of a task set: an append-only journal of chunk files.
//!
//! The task set is cut into chunks of `chunk_size` consecutive tasks; chunk `c` belongs to shard
//! `c mod n`. A finished chunk is written atomically as `chunk-<first task>.labels` (the label
//! layout with that chunk's records) plus `chunk-<first task>.stats.json`; a run skips chunks
//! whose files exist, so an interrupted run loses at most the chunks in flight and a restart
//! completes them. [`LabelJob::merge`] joins all chunks into the single-run label set: the result
//! does not depend on the shard split, the thread count or interruptions.

use std::path::{Path, PathBuf};

use emg_control::Task;
use emg_kinematics::Robot;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::config::LabelConfig;
use crate::labelling::{TaskStats, label_task};
use crate::labels::{LabelError, LabelSet, hex};

/// Shard `index` of `count` (`--shard i/n`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// 0-based shard index, below `count`.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
}

impl Shard {
    /// The whole task set as one shard.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };
}

/// A shard given as text that is not `i/n` with `0 ≤ i < n`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("shard '{text}': {problem}")]
pub struct ShardError {
    /// The text given.
    pub text: String,
    /// What is wrong with it.
    pub problem: &'static str,
}

impl std::str::FromStr for Shard {
    type Err = ShardError;

    /// Parses `i/n` with `0 ≤ i < n`.
    fn from_str(text: &str) -> Result<Self, ShardError> {
        let error = |problem| ShardError {
            text: text.to_string(),
            problem,
        };
        let (index, count) = text
            .split_once('/')
            .ok_or_else(|| error("not of the form i/n"))?;
        let parse = |s: &str| {
            s.trim()
                .parse::<usize>()
                .map_err(|_| error("i and n must be whole numbers"))
        };
        let (index, count) = (parse(index)?, parse(count)?);
        if count == 0 || index >= count {
            return Err(error("need 0 ≤ i < n"));
        }
        Ok(Self { index, count })
    }
}

/// What the journal directory was made for; a restart with anything else is refused.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct JournalIdentity {
    task_set_sha256: String,
    task_count: usize,
    chunk_size: usize,
    config: LabelConfig,
}

/// A labelling job over one task set, journaled in `dir`.
pub struct LabelJob<'a> {
    robot: &'a Robot,
    tasks: &'a [Task],
    task_set_sha256: [u8; 32],
    config: &'a LabelConfig,
    dir: PathBuf,
    chunk_size: usize,
}

/// What one [`LabelJob::run`] call did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RunProgress {
    /// Chunks of this shard already in the journal before the call.
    pub chunks_skipped: usize,
    /// Chunks labelled by this call.
    pub chunks_done: usize,
    /// Chunks of this shard still missing after the call.
    pub chunks_left: usize,
}

impl<'a> LabelJob<'a> {
    /// A job labelling `tasks` (the task set with SHA-256 `task_set_sha256`) in chunks of
    /// `chunk_size`, journaled in `dir` (created if missing; refused if it holds another job's
    /// journal).
    pub fn new(
        robot: &'a Robot,
        tasks: &'a [Task],
        task_set_sha256: [u8; 32],
        config: &'a LabelConfig,
        dir: &Path,
        chunk_size: usize,
    ) -> Result<Self, LabelError> {
        if chunk_size == 0 {
            return Err(LabelError::Format {
                path: dir.display().to_string(),
                problem: "chunk_size must be at least 1".into(),
            });
        }
        let identity = JournalIdentity {
            task_set_sha256: hex(&task_set_sha256),
            task_count: tasks.len(),
            chunk_size,
            config: config.clone(),
        };
        let text = serde_json::to_string_pretty(&identity).expect("identity serialises") + "\n";
        emg_io::open_journal(dir, &text).map_err(|error| match error {
            emg_io::JournalError::Io { path, source } => LabelError::Io { path, source },
            emg_io::JournalError::Mismatch { path, .. } => LabelError::Format {
                path,
                problem: "this journal was made for another task set, chunk size or labelling \
                          config; remove the directory to start over"
                    .into(),
            },
        })?;
        Ok(Self {
            robot,
            tasks,
            task_set_sha256,
            config,
            dir: dir.to_path_buf(),
            chunk_size,
        })
    }

    /// Number of chunks of the task set.
    pub fn chunk_count(&self) -> usize {
        self.tasks.len().div_ceil(self.chunk_size)
    }

    /// Chunks of `shard` (`c mod n = i`) not yet in the journal, in order.
    pub fn pending_chunks(&self, shard: Shard) -> Vec<usize> {
        (shard.index..self.chunk_count())
            .step_by(shard.count)
            .filter(|&c| !self.label_path(c).exists())
            .collect()
    }

    /// Labels the pending chunks of `shard` in parallel (at most `chunk_limit` of them when
    /// given), writing each chunk when it finishes; `progress(tasks)` is called per finished chunk.
    pub fn run(
        &self,
        shard: Shard,
        chunk_limit: Option<usize>,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<RunProgress, LabelError> {
        let total = (shard.index..self.chunk_count())
            .step_by(shard.count)
            .count();
        let mut pending = self.pending_chunks(shard);
        let chunks_skipped = total - pending.len();
        if let Some(limit) = chunk_limit {
            pending.truncate(limit);
        }
        pending
            .par_iter()
            .map(|&chunk| {
                let tasks = self.label_chunk(chunk)?;
                progress(tasks);
                Ok(())
            })
            .collect::<Result<Vec<()>, LabelError>>()?;
        Ok(RunProgress {
            chunks_skipped,
            chunks_done: pending.len(),
            chunks_left: total - chunks_skipped - pending.len(),
        })
    }

    /// Joins every chunk of the journal into the complete label set and its per-task statistics;
    /// fails naming the first missing chunk.
    pub fn merge(&self) -> Result<(LabelSet, Vec<TaskStats>), LabelError> {
        let mut parts = Vec::with_capacity(self.chunk_count());
        let mut stats = Vec::with_capacity(self.tasks.len());
        for chunk in 0..self.chunk_count() {
            let path = self.label_path(chunk);
            if !path.exists() {
                return Err(LabelError::Format {
                    path: path.display().to_string(),
                    problem: "chunk missing: run every shard to completion before merging".into(),
                });
            }
            parts.push(LabelSet::read(&path)?);
            let stats_path = self.stats_path(chunk);
            let text = std::fs::read_to_string(&stats_path).map_err(|source| LabelError::Io {
                path: stats_path.display().to_string(),
                source,
            })?;
            let chunk_stats: Vec<TaskStats> =
                serde_json::from_str(&text).map_err(|e| LabelError::Format {
                    path: stats_path.display().to_string(),
                    problem: e.to_string(),
                })?;
            stats.extend(chunk_stats);
        }
        Ok((LabelSet::merge(parts)?, stats))
    }

    fn label_chunk(&self, chunk: usize) -> Result<usize, LabelError> {
        let first = chunk * self.chunk_size;
        let last = (first + self.chunk_size).min(self.tasks.len());
        let (labels, stats): (Vec<_>, Vec<_>) = (first..last)
            .map(|i| label_task(self.robot, &self.tasks[i], i as u32, self.config))
            .unzip();
        let set = LabelSet::new(
            self.task_set_sha256,
            self.tasks.len() as u64,
            self.config.max_labels as u32,
            labels,
        )?;
        // Statistics first: a chunk counts as finished once its label file exists.
        let stats_path = self.stats_path(chunk);
        let text = serde_json::to_string(&stats).expect("stats serialise");
        emg_io::write_atomically(&stats_path, text.as_bytes()).map_err(|source| {
            LabelError::Io {
                path: stats_path.display().to_string(),
                source,
            }
        })?;
        set.write(&self.label_path(chunk))?;
        Ok(last - first)
    }

    fn label_path(&self, chunk: usize) -> PathBuf {
        self.dir
            .join(format!("chunk-{:07}.labels", chunk * self.chunk_size))
    }

    fn stats_path(&self, chunk: usize) -> PathBuf {
        self.dir
            .join(format!("chunk-{:07}.stats.json", chunk * self.chunk_size))
    }
}
