//! Initial configurations for extreme straight-line motion (Sec. 4.1 of the paper, SPEC §7).
//!
//! For one task many configurations put the pen tip at `p0` with its axis along `n`; joint limits
//! cut that self-motion family into disconnected branches, and the branch a rollout starts on
//! largely decides how far the line can go. This crate holds the seed-label dataset that the
//! learning crates read: [`LabelSet`] (one [`TaskLabels`] per task, at most `K'` [`Label`]s each,
//! longest first), stored in a compact versioned binary file.
//!
//! ```
//! use emg_kinematics::JointVector;
//! use emg_seeding::{Label, LabelSet, TaskLabels};
//! let labels = vec![Label::stored(JointVector::repeat(0.1), 0.62, 0, 0.01)];
//! let set = LabelSet::new([7; 32], 10, 6, vec![TaskLabels { task_index: 3, labels }])?;
//! let path = std::env::temp_dir().join(format!("emg-seeding-doc-{}.labels", std::process::id()));
//! set.write(&path)?;
//! let back = LabelSet::read(&path)?;
//! assert_eq!(back, set);
//! assert_eq!(back.get(3).unwrap().labels[0].length_m, f64::from(0.62f32));
//! # std::fs::remove_file(&path).ok();
//! # Ok::<(), emg_seeding::LabelError>(())
//! ```

mod branch;
mod config;
mod heuristic;
mod ik;
mod journal;
mod labelling;
mod labels;
mod tangent;

pub use branch::{
    BranchSamples, SelfMotionWalk, WalkEnd, connected, sample_branches, tangent_directions, walk,
};
pub use config::{BranchConfig, HeuristicConfig, IkConfig, LabelConfig, StabilityConfig};
pub use heuristic::{HeuristicError, HeuristicObjective, HeuristicSeed, heuristic_seed};
pub use ik::{cone_ik_solutions, solve_cone_ik};
pub use journal::{LabelJob, RunProgress, Shard};
pub use labelling::{TaskStats, label_task};
pub use labels::{
    LABEL_FORMAT_VERSION, Label, LabelError, LabelSet, TaskLabels, hex, task_set_sha256,
};
pub use tangent::self_motion_projector;
