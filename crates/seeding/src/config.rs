//! Every constant of seed enumeration, heuristic seeds and labelling, with SPEC §7 defaults.

use emg_control::{ClassicalGains, RolloutConfig};
use emg_kinematics::ProjectionConfig;
use serde::{Deserialize, Serialize};

/// Cone-constrained IK from many restarts (SPEC §7).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IkConfig {
    /// Restarts per task.
    pub restarts: usize,
    /// Share of restarts drawn biased toward the joint limits (the rest uniform).
    pub limit_biased_fraction: f64,
    /// A biased restart puts each joint, with probability ½, in this outer fraction of its range.
    pub limit_band_fraction: f64,
    /// Half-angle of the tool-axis cone around `n` the IK accepts (degrees).
    pub cone_deg: f64,
    /// Distance every solution keeps from every joint limit (rad).
    pub joint_margin_rad: f64,
    /// Damped-least-squares iterations per restart.
    pub max_iterations: usize,
    /// Damping `λ` of the damped-least-squares step `Mᵀ(MMᵀ + λ²I)⁻¹e`.
    pub damping: f64,
    /// Largest joint change of one iteration (rad, max-norm).
    pub max_step_rad: f64,
    /// Position error accepted as reached before the exact projection (m).
    pub position_tolerance_m: f64,
    /// Solutions closer than this (max-norm, rad) are duplicates.
    pub dedup_rad: f64,
    /// A restart is given up once its residual (position and the orientation beyond the cone)
    /// has not fallen below [`STALL_RATIO`] of what it was this many iterations before: it
    /// has settled in a local minimum short of the target. 0 runs every restart to
    /// `max_iterations`.
    #[serde(default)]
    pub stall_iterations: usize,
}

/// Share of its residual a restart must shed every [`IkConfig::stall_iterations`] iterations
/// to go on.
pub const STALL_RATIO: f64 = 0.9;

impl Default for IkConfig {
    fn default() -> Self {
        Self {
            restarts: 32,
            limit_biased_fraction: 0.5,
            limit_band_fraction: 0.15,
            cone_deg: 5.0,
            joint_margin_rad: 0.05,
            max_iterations: 60,
            damping: 0.05,
            max_step_rad: 0.3,
            position_tolerance_m: 1e-4,
            dedup_rad: 0.08,
            stall_iterations: 0,
        }
    }
}

/// Walking the self-motion family and telling its branches apart.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BranchConfig {
    /// Joint-space arc length of one walk step (rad, Euclidean).
    pub step_rad: f64,
    /// Steps of one walk ray before it stops.
    pub max_steps: usize,
    /// A sample is collected every this many steps of a ray.
    pub sample_every_steps: usize,
    /// Rays walked from each branch root (evenly spread directions in the tangent plane).
    pub rays: usize,
    /// Steps a connection attempt between two configurations may take.
    pub connect_max_steps: usize,
    /// Distance (max-norm, rad) at which a walk counts as having reached a configuration.
    pub reach_rad: f64,
    /// Damping `ε` of the tangent projector `I − Mᵀ(MMᵀ + εI)⁻¹M`.
    pub projector_damping: f64,
}

impl Default for BranchConfig {
    fn default() -> Self {
        Self {
            step_rad: 0.05,
            max_steps: 60,
            sample_every_steps: 8,
            rays: 4,
            connect_max_steps: 80,
            reach_rad: 0.08,
            projector_damping: 1e-9,
        }
    }
}

/// Null-space gradient ascent of the heuristic seeds `q_μ` and `q_jl` (paper Sec. 5, Table 2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HeuristicConfig {
    /// Ascent blocks (each a few tangent steps followed by a Newton re-projection).
    pub blocks: usize,
    /// Tangent steps between two re-projections.
    pub steps_per_block: usize,
    /// Initial largest joint change of one tangent step (rad, max-norm); halved on a failed block.
    pub step_rad: f64,
    /// The ascent stops when the step has been halved below this (rad).
    pub min_step_rad: f64,
    /// Damping `λ_μ` of the directional manipulability objective.
    pub manipulability_damping: f64,
    /// Damping `ε` of the tangent projector.
    pub projector_damping: f64,
}

impl Default for HeuristicConfig {
    fn default() -> Self {
        Self {
            blocks: 30,
            steps_per_block: 4,
            step_rad: 0.05,
            min_step_rad: 0.002,
            manipulability_damping: 1e-3,
            projector_damping: 1e-9,
        }
    }
}

/// Small task perturbations under which a label's path length must hold (SPEC §7).
///
/// A perturbed task moves `p0` by `position_m` in a random direction and turns `n` and `d`
/// together by `angle_deg` about a random axis ⟂ `n`; the candidate is Newton-projected onto the
/// perturbed pose and rolled out again. `stability_m` = the largest `|L' − L|` over the
/// perturbations (a failed projection counts as `L' = 0`); a candidate is stable when
/// `stability_m ≤ max(stable_abs_m, stable_fraction · L)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StabilityConfig {
    /// Perturbed tasks per candidate (the same ones for every candidate of a task).
    pub perturbations: usize,
    /// Displacement of `p0` (m).
    pub position_m: f64,
    /// Rotation of `n` and `d` (degrees).
    pub angle_deg: f64,
    /// Absolute length change always tolerated (m).
    pub stable_abs_m: f64,
    /// Length change tolerated relative to `L`.
    pub stable_fraction: f64,
}

impl Default for StabilityConfig {
    fn default() -> Self {
        Self {
            perturbations: 4,
            position_m: 0.005,
            angle_deg: 2.0,
            stable_abs_m: 0.05,
            stable_fraction: 0.2,
        }
    }
}

/// Everything the labeller uses; recorded in every label manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LabelConfig {
    /// Seed of every random choice (restarts, walk directions are deterministic, perturbations);
    /// task `i` draws from stream `i`.
    pub seed: u64,
    /// Labels kept per task, `K'`.
    pub max_labels: usize,
    /// Candidates whose classical path length is below this are dropped (m).
    pub min_length_m: f64,
    /// Labels of one task closer than this (max-norm, rad) are duplicates; the longer is kept.
    pub dedup_rad: f64,
    /// Cone-constrained IK.
    pub ik: IkConfig,
    /// Self-motion walks and branch ids.
    pub branch: BranchConfig,
    /// Small-perturbation stability.
    pub stability: StabilityConfig,
    /// Exact projection onto `(p0, n)` (labels, walks, perturbed tasks).
    pub projection: ProjectionConfig,
    /// The scoring rollout.
    pub rollout: RolloutConfig,
    /// Gains of the scoring classical controller.
    pub gains: ClassicalGains,
}

impl Default for LabelConfig {
    fn default() -> Self {
        Self {
            seed: 2026,
            max_labels: 6,
            min_length_m: 0.05,
            dedup_rad: 0.08,
            ik: IkConfig::default(),
            branch: BranchConfig::default(),
            stability: StabilityConfig::default(),
            projection: ProjectionConfig::default(),
            rollout: RolloutConfig::default(),
            gains: ClassicalGains::default(),
        }
    }
}
