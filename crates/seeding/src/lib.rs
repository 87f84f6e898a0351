//! Initial configurations for extreme straight-line motion (Sec. 4.1 and Table 2 of the paper,
//! SPEC §7).
//!
//! For one task many configurations put the pen tip at `p0` with its axis along `n`; joint limits
//! cut that self-motion family into disconnected branches, and the branch a rollout starts on
//! largely decides how far the line can go. This crate finds and scores those branches:
//!
//! * [`cone_ik_solutions`]: IK of `(p0, axis within a 5° cone of n)` from many restarts (half
//!   biased toward the limits), with a joint margin and deduplication.
//! * [`walk`], [`connected`], [`sample_branches`]: motion along the family (the null space of the
//!   5-D pose constraint, [`self_motion_projector`]) to a limit or collision; branch ids.
//! * [`heuristic_seed`]: the `q_μ` / `q_jl` seeds (null-space ascent from `q0_seed`).
//! * [`label_task`]: one task's labels — candidates scored by classical rollouts, kept when
//!   length-stable under small task perturbations, the top `K'` (all constants in [`LabelConfig`]).
//! * [`LabelJob`]: resumable, sharded labelling of a task set; [`LabelSet`] is the label file the
//!   learning crates read (`docs/labels-format.md`).
//!
//! ```
//! use emg_control::Task;
//! use emg_kinematics::{Robot, Vec3};
//! use emg_seeding::{LabelConfig, LabelSet, label_task};
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
//! let robot = Robot::from_urdf_file(path, "link0", "pen_tip")?;
//! let seed = robot.mid_range();
//! let kin = robot.forward(&seed);
//! let task = Task::new(&robot, kin.tcp(), Vec3::y(), kin.tool_axis(), Some(seed))?;
//! let mut config = LabelConfig::default();
//! config.ik.restarts = 8;
//! let (labels, stats) = label_task(&robot, &task, 0, &config);
//! assert!(stats.branches >= 1 && labels.labels.len() <= config.max_labels);
//! for label in &labels.labels {
//!     assert!((robot.forward(&label.q).tcp() - task.p0).norm() < 1e-6);
//! }
//! let set = LabelSet::new([0; 32], 1, 6, vec![labels])?;
//! let path = std::env::temp_dir().join(format!("emg-seeding-doc-{}.labels", std::process::id()));
//! set.write(&path)?;
//! assert_eq!(LabelSet::read(&path)?, set);
//! # std::fs::remove_file(&path).ok();
//! # Ok::<(), Box<dyn std::error::Error>>(())
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
pub use config::{
    BranchConfig, HeuristicConfig, IkConfig, LabelConfig, STALL_RATIO, StabilityConfig,
};
pub use heuristic::{HeuristicError, HeuristicObjective, HeuristicSeed, heuristic_seed};
pub use ik::{cone_ik_solutions, solve_cone_ik};
pub use journal::{LabelJob, RunProgress, Shard, ShardError};
pub use labelling::{TaskStats, label_task};
pub use labels::{LABEL_FORMAT_VERSION, Label, LabelError, LabelSet, TaskLabels, file_sha256, hex};
pub use tangent::self_motion_projector;
