//! Walking the self-motion family of a pose and telling its branches apart (Sec. 4.1, Fig. 3).
//!
//! The configurations reaching `(p0, tool axis = n)` form a 2-D family (1-D with a roll target);
//! joint limits and self-collision cut it into disconnected branches. A walk integrates motion in
//! the family's tangent space (`P v`, see [`self_motion_projector`]), re-projecting onto the exact
//! pose after every step, until a joint limit, a collision or the step cap.

use emg_kinematics::{JointVector, PoseTarget, ProjectionConfig, Robot, project_to_pose};
use serde::{Deserialize, Serialize};

use crate::config::BranchConfig;
use crate::tangent::self_motion_projector;

/// Why a self-motion walk stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum WalkEnd {
    /// The next step would pass a joint limit (1-based joint number).
    JointLimit {
        /// Joint that reached its limit.
        joint: usize,
    },
    /// The next configuration collides with itself.
    SelfCollision,
    /// The tangent space degenerated or the re-projection failed (a singular pose).
    Stalled,
    /// The walk took its step cap.
    StepCap,
}

/// The configurations visited by one walk, from its start, with their joint-space arc length.
#[derive(Clone, Debug, PartialEq)]
pub struct SelfMotionWalk {
    /// Visited configurations (all on the exact pose), the start first.
    pub points: Vec<JointVector>,
    /// Joint-space arc length (rad, Euclidean) from the start to each point.
    pub arc_length_rad: Vec<f64>,
    /// Why the walk stopped.
    pub end: WalkEnd,
}

/// The two leading tangent directions at `q` (orthonormal; the second is zero for a 1-D family):
/// the largest columns of the tangent projector, Gram–Schmidt orthogonalised.
pub fn tangent_directions(
    robot: &Robot,
    q: &JointVector,
    target: &PoseTarget,
    cfg: &BranchConfig,
) -> [JointVector; 2] {
    let projector = self_motion_projector(robot, q, target, cfg.projector_damping);
    let largest = |vectors: &mut dyn Iterator<Item = JointVector>| {
        vectors
            .max_by(|a, b| a.norm_squared().total_cmp(&b.norm_squared()))
            .unwrap_or_else(JointVector::zeros)
    };
    let first = largest(&mut projector.column_iter().map(|c| c.into_owned()));
    let first = normalised(first).unwrap_or_else(JointVector::zeros);
    let second = largest(
        &mut projector
            .column_iter()
            .map(|c| c.into_owned() - first * first.dot(&c)),
    );
    let second = if second.norm() > 1e-6 {
        normalised(second).unwrap_or_else(JointVector::zeros)
    } else {
        JointVector::zeros()
    };
    [first, second]
}

/// Walks from `start` (on the exact pose) along the family, each step the tangent projection of
/// the previous direction (a straightest path), starting along `direction`.
pub fn walk(
    robot: &Robot,
    start: &JointVector,
    target: &PoseTarget,
    direction: &JointVector,
    cfg: &BranchConfig,
    projection: &ProjectionConfig,
) -> SelfMotionWalk {
    let mut points = vec![*start];
    let mut arc_length_rad = vec![0.0];
    let mut q = *start;
    let mut heading = *direction;
    for _ in 0..cfg.max_steps {
        let tangent = self_motion_projector(robot, &q, target, cfg.projector_damping) * heading;
        let Some(unit) = normalised(tangent) else {
            return finish(points, arc_length_rad, WalkEnd::Stalled);
        };
        heading = unit;
        let next = match step(robot, &q, &(unit * cfg.step_rad), target, projection) {
            Ok(next) => next,
            Err(end) => return finish(points, arc_length_rad, end),
        };
        let travelled = arc_length_rad.last().copied().unwrap_or(0.0) + (next - q).norm();
        points.push(next);
        arc_length_rad.push(travelled);
        q = next;
    }
    finish(points, arc_length_rad, WalkEnd::StepCap)
}

/// Whether a walk from `from` toward `to` (both on the exact pose), each step the tangent
/// projection of the remaining joint-space difference, gets within `cfg.reach_rad` of `to`
/// without passing a joint limit or a collision: the test that puts both on one branch.
pub fn connected(
    robot: &Robot,
    from: &JointVector,
    to: &JointVector,
    target: &PoseTarget,
    cfg: &BranchConfig,
    projection: &ProjectionConfig,
) -> bool {
    let mut q = *from;
    for _ in 0..cfg.connect_max_steps {
        let remaining = to - q;
        if remaining.amax() < cfg.reach_rad {
            return true;
        }
        let tangent = self_motion_projector(robot, &q, target, cfg.projector_damping) * remaining;
        // Progress stalls when the difference leaves the tangent space (another sheet).
        if tangent.norm() < 0.2 * remaining.norm() {
            return false;
        }
        let length = cfg.step_rad.min(remaining.norm());
        let Some(unit) = normalised(tangent) else {
            return false;
        };
        match step(robot, &q, &(unit * length), target, projection) {
            Ok(next) => q = next,
            Err(_) => return false,
        }
    }
    (to - q).amax() < cfg.reach_rad
}

/// One step `q + δ` re-projected onto the exact pose, rejected at a joint limit or collision.
fn step(
    robot: &Robot,
    q: &JointVector,
    delta: &JointVector,
    target: &PoseTarget,
    projection: &ProjectionConfig,
) -> Result<JointVector, WalkEnd> {
    let limits = robot.limits();
    let guess = q + delta;
    if let Some(i) = limits.first_violation(&guess, 0.0) {
        return Err(WalkEnd::JointLimit { joint: i + 1 });
    }
    let (next, _) =
        project_to_pose(robot, &guess, target, projection).map_err(|_| WalkEnd::Stalled)?;
    if let Some(i) =
        (0..next.len()).find(|&i| next[i] <= limits.lower[i] || next[i] >= limits.upper[i])
    {
        return Err(WalkEnd::JointLimit { joint: i + 1 });
    }
    if robot.first_collision(&robot.forward(&next), 0.0).is_some() {
        return Err(WalkEnd::SelfCollision);
    }
    Ok(next)
}

fn normalised(v: JointVector) -> Option<JointVector> {
    let norm = v.norm();
    (norm > 1e-9).then(|| v / norm)
}

fn finish(points: Vec<JointVector>, arc_length_rad: Vec<f64>, end: WalkEnd) -> SelfMotionWalk {
    SelfMotionWalk {
        points,
        arc_length_rad,
        end,
    }
}

/// Candidates of one pose grouped into branches, and samples walked along each branch.
#[derive(Clone, Debug, PartialEq)]
pub struct BranchSamples {
    /// `(configuration, branch id)`: first the given candidates, then the walk samples.
    pub configurations: Vec<(JointVector, u32)>,
    /// Number of distinct branches.
    pub branch_count: u32,
}

/// Assigns every candidate (on the exact pose) a branch id, in order: the id of the first
/// earlier branch root it is [`connected`] to, else a new id. Then walks `cfg.rays` rays from
/// every root (evenly spread in the tangent plane) and collects a sample every
/// `cfg.sample_every_steps` steps.
pub fn sample_branches(
    robot: &Robot,
    candidates: &[JointVector],
    target: &PoseTarget,
    cfg: &BranchConfig,
    projection: &ProjectionConfig,
) -> BranchSamples {
    let mut roots: Vec<JointVector> = Vec::new();
    let mut configurations = Vec::with_capacity(candidates.len() * 4);
    for q in candidates {
        let branch = roots
            .iter()
            .position(|root| connected(robot, q, root, target, cfg, projection))
            .unwrap_or_else(|| {
                roots.push(*q);
                roots.len() - 1
            });
        configurations.push((*q, branch as u32));
    }
    for (branch, root) in roots.iter().enumerate() {
        let [first, second] = tangent_directions(robot, root, target, cfg);
        for ray in 0..cfg.rays {
            let angle = std::f64::consts::TAU * ray as f64 / cfg.rays as f64;
            let (sin, cos) = libm::sincos(angle);
            let direction = first * cos + second * sin;
            let path = walk(robot, root, target, &direction, cfg, projection);
            configurations.extend(
                path.points
                    .iter()
                    .skip(cfg.sample_every_steps)
                    .step_by(cfg.sample_every_steps.max(1))
                    .map(|q| (*q, branch as u32)),
            );
        }
    }
    BranchSamples {
        configurations,
        branch_count: roots.len() as u32,
    }
}
