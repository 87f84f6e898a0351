//! The paper's evaluation protocol (Sec. 5): run seeds × controllers over a task set, every
//! trajectory re-checked by the independent checker, and turn the per-task outcomes into the
//! tables.
//!
//! * [`rollout_all`] / [`rollout_from`]: one controller over many tasks in parallel, in task
//!   order whatever the thread count; [`Summary`] and histograms of the outcomes.
//! * [`Setup`]: the robot, its checker, the models and settings, loaded once; its stages are the
//!   seeds of a [`emg_planner::SeedSource`], checked rollouts, and the reference lengths
//!   [`Setup::references`] — the one definition of `ℓ_ref` behind every table.
//! * [`run_set`], [`merge_sets`], [`summarize`], [`markdown`]: Tables 1–2 of one task set, whole
//!   or from shards merged bit for bit; [`EvalRecord`] is the typed result file.
//! * [`BucketConfig`], [`cell_stats`]: the difficulty buckets and per-cell statistics.
//! * [`bound_shares`]: length-weighted shares of a reference by bucket of the reachability bound.
//! * [`lines_one_at_a_time`]: a polyline stroke planned as a line-only planner plans it, for the
//!   path evaluation's comparison.

mod batch;
mod bound_share;
mod buckets;
mod lines;
mod progress;
mod protocol;
mod setup;

pub use batch::{Summary, joint_limit_histogram, rollout_all, rollout_from, termination_histogram};
pub use bound_share::{BOUND_BUCKET_EDGES_M, BoundShare, bound_bucket, bound_shares};
pub use buckets::{
    BucketConfig, CellStats, Difficulty, MIN_REFERENCE_M, bucket_members, cell_stats,
};
pub use lines::{LinesOutcome, SAME_CONFIGURATION_RAD, lines_one_at_a_time};
pub use progress::{Progress, Silent};
pub use protocol::{
    Cell, EvalRecord, PROTOCOL_SEEDS, RawSet, SetResult, four, markdown, merge_sets, run_set,
    summarize,
};
pub use setup::{EvalError, Setup, check_trajectories};
