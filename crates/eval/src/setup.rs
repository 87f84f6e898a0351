//! Everything an evaluation runs with, loaded once: the robot and its independent checker, the
//! settings, the trained models; and the stages every table is made of: seeds, checked rollouts
//! and reference lengths.

use std::path::{Path, PathBuf};
use std::time::Instant;

use emg_control::{CheckRollout, ConstraintConfig, RolloutConfig, Task, Trajectory};
use emg_diffusion::{DpSeedError, DpSeeder, SeedWorkspace};
use emg_kinematics::{JointVector, ProjectionConfig, Robot, RobotError};
use emg_planner::{
    ControllerKind, Executor, ExecutorConfig, ExecutorError, ModelsError, SeedSource, load_policy,
    load_seeder,
};
use emg_policy::RlController;
use emg_seeding::{HeuristicConfig, HeuristicObjective, LabelSet, heuristic_seed};
use emg_verify::{CheckFailure, ModelError, ReferenceModel};
use rayon::prelude::*;

use crate::batch::rollout_from;
use crate::progress::{Progress, Silent};

/// Why an evaluation cannot run or does not hold up.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// The robot file cannot be loaded.
    #[error("cannot load robot {path}")]
    Robot {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: RobotError,
    },
    /// The checker cannot read the robot file.
    #[error("the checker cannot load robot {path}")]
    Checker {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: ModelError,
    },
    /// A model cannot be loaded.
    #[error(transparent)]
    Models(#[from] ModelsError),
    /// A controller cannot be built.
    #[error(transparent)]
    Controller(#[from] ExecutorError),
    /// The diffusion seeder failed on a task.
    #[error("DP seed")]
    Seed(#[from] DpSeedError),
    /// A task lacks the `q0_seed` the protocol needs.
    #[error("task {index} has no q0_seed; every evaluated task needs its generating configuration")]
    NoGeneratingConfiguration {
        /// Index of the task in the evaluated list.
        index: usize,
    },
    /// A seed source the protocol does not evaluate.
    #[error("seed source '{0}' is not one of the protocol's (generating, q_mu, q_jl, dp)")]
    UnsupportedSeed(&'static str),
    /// Trajectories fail the independent check.
    #[error("{count} trajectories fail the independent check, first: task {task}: {first}")]
    Check {
        /// How many fail.
        count: usize,
        /// Index of the first failing task.
        task: usize,
        /// Its failure.
        first: CheckFailure,
    },
    /// There is nothing to evaluate.
    #[error("no tasks to evaluate")]
    NoTasks,
    /// Shards do not join into one set.
    #[error("cannot merge the shards: {0}")]
    Merge(String),
}

/// Everything the protocol runs with, loaded once.
pub struct Setup {
    /// The robot.
    pub robot: Robot,
    /// Its independent checker, read again from the robot file.
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
    progress: Box<dyn Progress>,
}

impl Setup {
    /// Loads the robot (its file's root-to-leaf chain), its checker, the policy and the
    /// diffusion seeder, with the default settings and no progress report.
    pub fn load(
        robot_path: &Path,
        policy_path: &Path,
        diffusion_path: &Path,
    ) -> Result<Self, EvalError> {
        let robot = Robot::from_chain_file(robot_path).map_err(|source| EvalError::Robot {
            path: robot_path.to_path_buf(),
            source,
        })?;
        let checker =
            ReferenceModel::from_urdf_file(robot_path, robot.base_link(), robot.tip_link())
                .map_err(|source| EvalError::Checker {
                    path: robot_path.to_path_buf(),
                    source,
                })?;
        let policy = load_policy(&robot, policy_path)?;
        let dp = load_seeder(&robot, diffusion_path)?;
        Ok(Self {
            robot,
            checker,
            rollout: RolloutConfig::default(),
            executor: ExecutorConfig::default(),
            policy,
            dp,
            heuristic: HeuristicConfig::default(),
            projection: ProjectionConfig::default(),
            progress: Box::new(Silent),
        })
    }

    /// Reports the progress of every stage to `progress`.
    pub fn with_progress(mut self, progress: Box<dyn Progress>) -> Self {
        self.progress = progress;
        self
    }

    /// Seeds of `source` for every task and their generation times (ms), in parallel: the
    /// task's `q0_seed` (`generating`), the heuristic ascents `q_mu` / `q_jl` (falling back to
    /// `q0_seed` when the ascent fails) or the DP seed.
    pub fn seeds(
        &self,
        tasks: &[Task],
        source: &SeedSource,
    ) -> Result<(Vec<JointVector>, Vec<f64>), EvalError> {
        let objective = match source {
            SeedSource::QMu => Some(HeuristicObjective::Manipulability),
            SeedSource::QJl => Some(HeuristicObjective::JointCentring),
            SeedSource::Generating | SeedSource::Dp => None,
            other => return Err(EvalError::UnsupportedSeed(other.name())),
        };
        self.progress.begin(source.title(), tasks.len());
        let seeds: Vec<Result<(JointVector, f64), EvalError>> = tasks
            .par_iter()
            .enumerate()
            .map_init(SeedWorkspace::default, |workspace, (index, task)| {
                let q0 = task
                    .q0_seed
                    .ok_or(EvalError::NoGeneratingConfiguration { index })?;
                let seed = match (source, objective) {
                    (_, Some(objective)) => {
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
                    (SeedSource::Dp, None) => {
                        let seed = self.dp.seed(
                            &self.robot,
                            task,
                            &self.rollout.constraints,
                            workspace,
                        )?;
                        (seed.q, seed.elapsed.as_secs_f64() * 1e3)
                    }
                    _ => (q0, 0.0),
                };
                self.progress.advance();
                Ok(seed)
            })
            .collect();
        self.progress.end();
        let seeds = seeds.into_iter().collect::<Result<Vec<_>, _>>()?;
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
    ) -> Result<Vec<Trajectory>, EvalError> {
        let prototype = Executor::new(controller, Some(&self.policy), executor)?;
        self.progress.begin(what, tasks.len());
        let trajectories = rollout_from(
            &self.robot,
            tasks,
            seeds,
            || prototype.clone(),
            &self.rollout,
            &|| self.progress.advance(),
        );
        self.progress.end();
        self.check(tasks, &trajectories)?;
        Ok(trajectories)
    }

    /// Runs the independent checker over every trajectory.
    pub fn check(&self, tasks: &[Task], trajectories: &[Trajectory]) -> Result<(), EvalError> {
        check_trajectories(
            &self.checker,
            tasks,
            trajectories,
            &self.rollout.constraints,
        )
    }

    /// Reference lengths `ℓ_ref` (Sec. 5.1), the one definition behind every table: the
    /// longest hybrid rollout over each task's label candidates (its `q0_seed` when it has
    /// none); `indices[i]` is task `i`'s index in the labelled set.
    pub fn references(
        &self,
        tasks: &[Task],
        indices: &[usize],
        labels: &LabelSet,
    ) -> Result<Vec<f64>, EvalError> {
        let mut owners = Vec::new();
        let mut candidates = Vec::new();
        for (i, task) in tasks.iter().enumerate() {
            let found: Vec<JointVector> = labels
                .get(indices[i] as u32)
                .map(|t| t.labels.iter().map(|l| l.q).collect())
                .unwrap_or_default();
            let found = if found.is_empty() {
                vec![
                    task.q0_seed
                        .ok_or(EvalError::NoGeneratingConfiguration { index: i })?,
                ]
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
) -> Result<(), EvalError> {
    let failures: Vec<(usize, CheckFailure)> = tasks
        .par_iter()
        .zip(trajectories)
        .enumerate()
        .filter_map(|(i, (task, trajectory))| {
            checker
                .check(task, trajectory, constraints)
                .err()
                .map(|e| (i, e))
        })
        .collect();
    let count = failures.len();
    match failures.into_iter().next() {
        None => Ok(()),
        Some((task, first)) => Err(EvalError::Check { count, task, first }),
    }
}
