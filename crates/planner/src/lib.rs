//! The entry point of extreme straight-line motion: give a [`Planner`] a robot, its trained
//! [`Models`] and a [`PlannerConfig`], and [`Planner::plan`] a task (Eq. 1: start `p0`,
//! direction `d`, normal `n`) into a trajectory that moves the tool along the line as far as it
//! can while every step holds every constraint.
//!
//! The paper's pipeline ([`PlanRequest::pipeline`]) is a seed ([`SeedSource`]: the diffusion
//! seeder by default, Sec. 4.1) put exactly on the start pose, then one rollout of the chosen
//! null-space controller ([`ControllerKind`]: classical, RL or the hybrid of Sec. 4.3) through
//! the shared step; the default request ([`PlanRequest::default`], what `emg plan` and Python
//! run) is the search: the pipeline's plan first, then many other starts within a step budget,
//! guided by the task's reachability bound. [`PlannerConfig::cell`] keeps the arm off a work
//! plate under the line; [`PlannerConfig::default`] is the paper's protocol.
//! [`PlanFiles`] turns a plan into the files `emg plan` writes, its joint trajectory timed rest to
//! rest within the joint limits by [`MotionTiming`].
//!
//! The README's example (there the data directory is `data/` of the checkout):
//!
//! ```
//! use emg_planner::{Models, PlanRequest, Planner, PlannerConfig};
//! let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data");
//! let robot = emg_kinematics::Robot::from_chain_file(data.join("robots/fr3_pen.urdf"))?;
//! let models = Models::shipped(&robot, &data)?;
//! let planner = Planner::new(robot, models, PlannerConfig::cell())?; // the work plate on
//! let (p0, d, n) = ([0.45, -0.2, 0.25].into(), [0.0, 1.0, 0.0].into(), [0.0, 0.0, -1.0].into());
//! let task = emg_control::Task::new(planner.robot(), p0, d, n, None)?;
//! let plan = planner.plan(&task, &PlanRequest::default())?; // the search, as `emg plan`
//! println!("{:.3} m, ended: {}", plan.trajectory.path_length_m, plan.trajectory.termination);
//! assert!(plan.trajectory.path_length_m > 0.9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod beam;
mod cartesian;
mod config;
mod controller;
mod demo;
pub mod embedded;
mod far_end;
mod files;
mod gap;
mod in_place;
mod models;
pub mod parse;
mod planner;
mod reach;
mod search;
mod seed;
mod shipped;
#[cfg(test)]
mod test_support;
mod timing;
mod track;

pub use cartesian::{CartesianConfig, CartesianEnd, CartesianPath, cartesian_path};
pub use config::{ConfigError, PlannerConfig};
pub use controller::{ControllerKind, Executor, ExecutorConfig, ExecutorError};
pub use demo::demo_task;
pub use files::{PlanFiles, PlanFilesError, PlanRecord};
pub use gap::{GapProbe, GapProbeOutcome, gap_probes};
pub use in_place::{InPlaceConfig, in_place_motion, motion_along_line};
pub use models::{
    DIFFUSION_WEIGHTS_FILE, Models, ModelsError, POLICY_WEIGHTS_FILE, load_policy, load_seeder,
    robot_stamp,
};
pub use parse::ParseError;
pub use planner::{CONTINUITY_RESTARTS, Plan, PlanError, PlanRequest, Planner, PlannerKind};
pub use reach::{
    BoundNote, FAR_END_SHARE, MAX_REACH_RESTARTS, Reach, ReachConfig, SHORTFALL_SHARE,
    StartBlockers, StartContact, far_end_chains, reach, reachable_points, shortfall,
    start_blockers, witness_chains,
};
pub use search::{
    MAX_FAR_END_SHARES, MAX_SEARCH_BUDGET_STEPS, SearchConfig, search_classical_gains,
};
pub use seed::{
    CHAIN_SOURCE, FAR_END_SOURCE, SCAN_SOURCE, Seed, SeedError, SeedSource, prepare_seed,
    seed_source_meaning,
};
pub use shipped::{DataDir, INDUSTRIAL_ROBOTS, SHIPPED_ROBOTS, ShippedRobot};
pub use timing::{
    ASSUMED_LIMITS, DEFAULT_RATE_HZ, MotionTiming, TimingSetupError, limits_file_beside,
};
