//! The arm environment on the shared [`Episode`] step (Sec. 4.2): observation of Eq. 6, action
//! `a ∈ (−1, 1)⁴` in `B(q)` scaled by `a_max` (Eq. 7), reward `clip(Δp·d / (v·Δt), 0, 1)`,
//! termination at the first broken constraint, truncation at the step cap.

use emg_control::{ActingController, Episode, NullAction, RolloutConfig, StepOutcome, Task};
use emg_kinematics::{JointVector, Robot};
use emg_seeding::LabelSet;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::config::EnvConfig;
use crate::error::PolicyError;
use crate::observation::{ACTION_DIM, OBSERVATION_DIM, observe};
use crate::vec_env::{Environment, EpisodeEnd, Transition};

/// Resets tried before giving up on drawing a valid start (each draws a new task).
const RESET_ATTEMPTS: usize = 64;

/// The training tasks with their candidate starting configurations.
pub struct TrainingPool {
    robot: Robot,
    tasks: Vec<Task>,
    labelled_starts: Vec<Vec<JointVector>>,
    rollout: RolloutConfig,
    env: EnvConfig,
}

impl TrainingPool {
    /// Tasks with their labels' configurations where `labels` has them (matched by task
    /// index); every task needs its `q0_seed`, the start of unlabelled tasks.
    pub fn new(
        robot: Robot,
        tasks: Vec<Task>,
        labels: Option<&LabelSet>,
        rollout: RolloutConfig,
        env: EnvConfig,
    ) -> Result<Self, PolicyError> {
        if tasks.is_empty() {
            return Err(PolicyError::BadConfig {
                field: "tasks",
                problem: "the training pool is empty".into(),
            });
        }
        if let Some(i) = tasks.iter().position(|t| t.q0_seed.is_none()) {
            return Err(PolicyError::BadConfig {
                field: "tasks",
                problem: format!("training task {i} has no q0_seed"),
            });
        }
        if !(0.0..=1.0).contains(&env.q0_seed_probability) {
            return Err(PolicyError::BadConfig {
                field: "q0_seed_probability",
                problem: format!("is {}, must lie in [0, 1]", env.q0_seed_probability),
            });
        }
        let mut labelled_starts = vec![Vec::new(); tasks.len()];
        if let Some(labels) = labels {
            if labels.task_set_len() != tasks.len() as u64 {
                return Err(PolicyError::BadConfig {
                    field: "labels",
                    problem: format!(
                        "label a task set of {} tasks, the training pool has {}",
                        labels.task_set_len(),
                        tasks.len()
                    ),
                });
            }
            for task_labels in labels.tasks() {
                labelled_starts[task_labels.task_index as usize] =
                    task_labels.labels.iter().map(|l| l.q).collect();
            }
        }
        Ok(Self {
            robot,
            tasks,
            labelled_starts,
            rollout,
            env,
        })
    }

    /// Number of tasks.
    pub fn len(&self) -> usize {
        self.tasks.len()
    }

    /// Whether the pool has no tasks (never true for a constructed pool).
    pub fn is_empty(&self) -> bool {
        self.tasks.is_empty()
    }

    /// Tasks with at least one labelled start.
    pub fn labelled_tasks(&self) -> usize {
        self.labelled_starts
            .iter()
            .filter(|s| !s.is_empty())
            .count()
    }

    /// The rollout settings of every episode.
    pub fn rollout_config(&self) -> &RolloutConfig {
        &self.rollout
    }

    /// `count` environments drawing their episodes from this pool.
    pub fn environments(&self, count: usize) -> Vec<ArmEnvironment<'_>> {
        (0..count)
            .map(|_| ArmEnvironment {
                pool: self,
                episode: None,
            })
            .collect()
    }

    /// A start for `task`: `q0_seed`, or (for a labelled task, with probability
    /// `1 − q0_seed_probability`) a uniformly chosen label.
    fn start(&self, task: usize, rng: &mut ChaCha8Rng) -> JointVector {
        let labels = &self.labelled_starts[task];
        let q0_seed = self.tasks[task].q0_seed.expect("checked at construction");
        if labels.is_empty() || rng.random::<f64>() < self.env.q0_seed_probability {
            q0_seed
        } else {
            labels[rng.random_range(0..labels.len())]
        }
    }
}

/// One arm environment: an [`Episode`] on a task of the pool, driven by actions in `B(q)`;
/// after the episode's end it is observed at its last accepted step (a truncation's value
/// bootstrap) until the next reset.
pub struct ArmEnvironment<'a> {
    pool: &'a TrainingPool,
    episode: Option<Episode<'a>>,
}

impl ArmEnvironment<'_> {
    fn episode(&self) -> &Episode<'_> {
        self.episode
            .as_ref()
            .expect("an environment is reset before use")
    }
}

impl Environment for ArmEnvironment<'_> {
    fn reset(&mut self, rng: &mut ChaCha8Rng) {
        let pool = self.pool;
        for _ in 0..RESET_ATTEMPTS {
            let index = rng.random_range(0..pool.tasks.len());
            let start = pool.start(index, rng);
            let episode = Episode::start(&pool.robot, &pool.tasks[index], &start, &pool.rollout);
            if !episode.is_finished() {
                self.episode = Some(episode);
                return;
            }
        }
        panic!("{RESET_ATTEMPTS} draws from the training pool all gave an invalid start");
    }

    fn observe(&self, out: &mut [f32; OBSERVATION_DIM]) {
        observe(self.episode().state(), out);
    }

    fn step(&mut self, action: &[f32; ACTION_DIM]) -> Transition {
        let episode = self.episode.as_mut().expect("step after reset");
        let action = NullAction::from_fn(|i, _| f64::from(action[i]));
        let config = &self.pool.rollout;
        let reward =
            |progress_m: f64| (progress_m / (config.speed_m_per_s * config.dt_s)).clamp(0.0, 1.0);
        match episode.apply(&action, ActingController::Learned) {
            StepOutcome::Continued { progress_m } => Transition {
                reward: reward(progress_m),
                end: None,
            },
            StepOutcome::Truncated { progress_m } => Transition {
                reward: reward(progress_m),
                end: Some(EpisodeEnd::Truncated),
            },
            StepOutcome::Terminated => Transition {
                reward: 0.0,
                end: Some(EpisodeEnd::Terminated),
            },
        }
    }

    fn score(&self) -> f64 {
        let state = self.episode().state();
        state.task.progress(&state.kinematics.tcp())
    }
}
