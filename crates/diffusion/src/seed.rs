//! The DP seed (Sec. 4.1): sample candidates with DDIM + guidance, Newton-project each onto the
//! exact start pose, keep the first IK-valid one within `max_tries`, else fall back to `q0_seed`.

use std::time::{Duration, Instant};

use emg_control::{ConstraintConfig, Task, first_violation};
use emg_kinematics::{JointVector, PoseTarget, ProjectionConfig, Robot, project_to_pose};
use emg_learning::StandardNormal;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::config::SampleConfig;
use crate::sampler::{DdimSampler, SampleError, SamplerWorkspace};
use crate::weights::{DenoiserWeights, WeightsError};

/// Dimension of the task condition `c = [p0, d, n]`.
pub const CONDITION_DIM: usize = 9;

/// How the projection fixes the roll of the tool about its axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RollTarget {
    /// Any roll (the pen is symmetric about its axis): project onto `(p0, z = n)` only.
    #[default]
    Free,
    /// SPEC §6's full pose: `z = n`, `x = normalise(d − (d·n)n)`.
    FromDirection,
}

/// Settings of the DP seed pipeline (SPEC §6 defaults).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DpSeedConfig {
    /// DDIM settings (50 steps, `w` = 1.5).
    pub sample: SampleConfig,
    /// Candidates tried before falling back to `q0_seed` (32).
    pub max_tries: usize,
    /// Candidates denoised in the first batch; each later batch doubles the candidates tried so
    /// far (1, 1, 2, 4, … by default), so an easy task pays for one candidate and a hard one for
    /// a few batched runs. Results do not depend on it (each candidate's noise is its own draw),
    /// only the time does.
    pub first_batch: usize,
    /// Seed of the candidates' noise (mixed with a hash of the task).
    pub seed: u64,
    /// Roll handling of the projection.
    pub roll: RollTarget,
    /// The Newton projection.
    pub projection: ProjectionConfig,
}

impl Default for DpSeedConfig {
    fn default() -> Self {
        Self {
            sample: SampleConfig::default(),
            max_tries: 32,
            first_batch: 1,
            seed: 0,
            roll: RollTarget::default(),
            projection: ProjectionConfig::default(),
        }
    }
}

/// Where a DP seed came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SeedOrigin {
    /// A projected diffusion sample.
    Diffusion,
    /// No candidate was IK-valid: the task's `q0_seed`.
    Fallback,
}

/// A DP seed and what it cost.
#[derive(Clone, Debug, PartialEq)]
pub struct DpSeed {
    /// The configuration.
    pub q: JointVector,
    /// Diffusion sample or fallback.
    pub origin: SeedOrigin,
    /// Candidates projected (1 … `max_tries`).
    pub tries: usize,
    /// Wall time of the whole pipeline.
    pub elapsed: Duration,
}

/// Why no DP seed could be produced.
#[derive(Debug, thiserror::Error)]
pub enum DpSeedError {
    /// No candidate was IK-valid and the task has no `q0_seed` to fall back to.
    #[error(
        "none of the {tries} diffusion candidates reaches the start pose within the constraints, and the task has no q0_seed to fall back to"
    )]
    NoValidSeed {
        /// Candidates tried.
        tries: usize,
    },
    /// The sampling settings are invalid.
    #[error(transparent)]
    Sample(#[from] SampleError),
    /// The weights do not fit the seeder.
    #[error(transparent)]
    Weights(#[from] WeightsError),
    /// A pipeline setting is invalid.
    #[error("dp seed config field '{field}' {problem}")]
    Config {
        /// Field.
        field: &'static str,
        /// What is wrong.
        problem: &'static str,
    },
}

/// Reusable buffers of [`DpSeeder::seed`].
#[derive(Clone, Debug, Default)]
pub struct SeedWorkspace {
    sampler: SamplerWorkspace,
    candidates: Vec<f32>,
}

/// The diffusion seeder: trained weights, their sampler and the pipeline settings.
#[derive(Clone, Debug)]
pub struct DpSeeder {
    sampler: DdimSampler,
    config: DpSeedConfig,
    /// Joints of the arm the weights were trained for (the sample dimension).
    joints: usize,
}

impl DpSeeder {
    /// A seeder for `robot` over `weights` (which must map a 9-D task condition to an
    /// `n`-D configuration of its `n` joints).
    pub fn new(
        robot: &Robot,
        weights: &DenoiserWeights,
        config: DpSeedConfig,
    ) -> Result<Self, DpSeedError> {
        let joints = robot.dof();
        weights.require_dimensions(joints, CONDITION_DIM)?;
        if config.max_tries == 0 {
            return Err(DpSeedError::Config {
                field: "max_tries",
                problem: "must be at least 1",
            });
        }
        if config.first_batch == 0 {
            return Err(DpSeedError::Config {
                field: "first_batch",
                problem: "must be at least 1",
            });
        }
        let sampler = DdimSampler::new(weights);
        sampler.validate(&config.sample)?;
        Ok(Self {
            sampler,
            config,
            joints,
        })
    }

    /// The settings.
    pub fn config(&self) -> &DpSeedConfig {
        &self.config
    }

    /// Candidates `q` (joint space, not yet projected) for `task`, in try order: `count` of the
    /// candidates [`seed`](Self::seed) would try.
    pub fn candidates(
        &self,
        robot: &Robot,
        task: &Task,
        count: usize,
        workspace: &mut SeedWorkspace,
    ) -> Result<Vec<JointVector>, DpSeedError> {
        let mut rng = self.noise(task);
        self.sample_batch(task, count, &mut rng, workspace)?;
        Ok(workspace
            .candidates
            .chunks_exact(self.joints)
            .map(|x| denormalise(robot, x))
            .collect())
    }

    /// The DP seed of `task`: the first candidate that projects onto the exact start pose and
    /// breaks no constraint there, else the task's `q0_seed`.
    pub fn seed(
        &self,
        robot: &Robot,
        task: &Task,
        constraints: &ConstraintConfig,
        workspace: &mut SeedWorkspace,
    ) -> Result<DpSeed, DpSeedError> {
        let started = Instant::now();
        let target = match self.config.roll {
            RollTarget::Free => PoseTarget {
                position: task.p0,
                tool_axis: task.n,
                roll_axis: None,
            },
            RollTarget::FromDirection => {
                PoseTarget::with_roll_from_direction(task.p0, task.n, task.d)
            }
        };
        let mut rng = self.noise(task);
        let mut tries = 0;
        while tries < self.config.max_tries {
            let wanted = if tries == 0 {
                self.config.first_batch
            } else {
                tries
            };
            let batch = wanted.min(self.config.max_tries - tries);
            self.sample_batch(task, batch, &mut rng, workspace)?;
            for x in workspace.candidates.chunks_exact(self.joints) {
                tries += 1;
                let start = denormalise(robot, x);
                let Ok((q, _)) = project_to_pose(robot, &start, &target, &self.config.projection)
                else {
                    continue;
                };
                let kinematics = robot.forward(&q);
                if first_violation(robot, task, &kinematics, constraints).is_none() {
                    return Ok(DpSeed {
                        q,
                        origin: SeedOrigin::Diffusion,
                        tries,
                        elapsed: started.elapsed(),
                    });
                }
            }
        }
        match task.q0_seed {
            Some(q) => Ok(DpSeed {
                q,
                origin: SeedOrigin::Fallback,
                tries,
                elapsed: started.elapsed(),
            }),
            None => Err(DpSeedError::NoValidSeed { tries }),
        }
    }

    /// The noise stream of `task`: the configured seed, on a stream named by the task's bits.
    fn noise(&self, task: &Task) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::seed_from_u64(self.config.seed);
        rng.set_stream(task_hash(task));
        rng
    }

    /// Denoises the next `count` candidates of `rng` into `workspace.candidates` (normalised).
    fn sample_batch(
        &self,
        task: &Task,
        count: usize,
        rng: &mut ChaCha8Rng,
        workspace: &mut SeedWorkspace,
    ) -> Result<(), DpSeedError> {
        workspace.candidates.clear();
        workspace
            .candidates
            .extend((0..count * self.joints).map(|_| rng.sample::<f32, _>(StandardNormal)));
        let condition = condition_of(task);
        self.sampler.sample(
            &condition,
            &self.config.sample,
            &mut workspace.candidates,
            &mut workspace.sampler,
        )?;
        Ok(())
    }
}

/// The condition `c = [p0, d, n]` of a task, as the network reads it.
pub fn condition_of(task: &Task) -> [f32; CONDITION_DIM] {
    let mut c = [0.0; CONDITION_DIM];
    for (i, v) in task
        .p0
        .iter()
        .chain(task.d.iter())
        .chain(task.n.iter())
        .enumerate()
    {
        c[i] = *v as f32;
    }
    c
}

/// Joint configuration of a normalised sample `x ∈ [−1, 1]ⁿ`: `q = q_mid + x · q_half`.
pub fn denormalise(robot: &Robot, x: &[f32]) -> JointVector {
    let limits = robot.limits();
    robot.configuration_from_fn(|i| limits.mid()[i] + f64::from(x[i]) * limits.half_range()[i])
}

/// FNV-1a over the bits of `p0`, `d`, `n`: the task's own noise stream.
fn task_hash(task: &Task) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for v in task.p0.iter().chain(task.d.iter()).chain(task.n.iter()) {
        for byte in v.to_bits().to_le_bytes() {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    hash
}
