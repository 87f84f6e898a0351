//! Cone-constrained IK from many restarts: configurations putting the TCP at `p0` with the tool
//! axis inside a small cone around `n`, spread over the self-motion branches (SPEC §7).

use emg_kinematics::{JointVector, PoseTarget, Robot, Vec3, pose_residual};
use nalgebra::SMatrix;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::config::{IkConfig, STALL_RATIO};

/// Distinct IK solutions of `(p0, tool axis within cfg.cone_deg of n)`, each at least
/// `cfg.joint_margin_rad` inside every joint limit, pairwise at least `cfg.dedup_rad` apart
/// (max-norm), in the order their restarts were drawn from `rng`.
pub fn cone_ik_solutions(
    robot: &Robot,
    p0: &Vec3,
    n: &Vec3,
    cfg: &IkConfig,
    rng: &mut ChaCha8Rng,
) -> Vec<JointVector> {
    let biased = (cfg.restarts as f64 * cfg.limit_biased_fraction).round() as usize;
    let mut solutions: Vec<JointVector> = Vec::new();
    for restart in 0..cfg.restarts {
        let start = restart_configuration(robot, cfg, restart < biased, rng);
        if let Some(q) = solve_cone_ik(robot, &start, p0, n, cfg)
            && solutions.iter().all(|s| (s - q).amax() >= cfg.dedup_rad)
        {
            solutions.push(q);
        }
    }
    solutions
}

/// A restart: uniform within the margin-shrunk limits, or (biased) with each joint, with
/// probability ½, in the outer `limit_band_fraction` of its range at a random end.
fn restart_configuration(
    robot: &Robot,
    cfg: &IkConfig,
    biased: bool,
    rng: &mut ChaCha8Rng,
) -> JointVector {
    let limits = robot.limits();
    robot.configuration_from_fn(|i| {
        let lower = limits.lower[i] + cfg.joint_margin_rad;
        let upper = limits.upper[i] - cfg.joint_margin_rad;
        let u: f64 = rng.random();
        if biased && rng.random::<f64>() < 0.5 {
            let band = (upper - lower) * cfg.limit_band_fraction;
            if rng.random::<f64>() < 0.5 {
                lower + u * band
            } else {
                upper - u * band
            }
        } else {
            lower + u * (upper - lower)
        }
    })
}

/// Damped least squares from `start` toward the TCP at `p0` with the tool axis inside the cone:
/// the orientation residual is the rotation toward `n` beyond the cone's half-angle. Returns the
/// configuration once the position is within tolerance and the axis inside the cone.
pub fn solve_cone_ik(
    robot: &Robot,
    start: &JointVector,
    p0: &Vec3,
    n: &Vec3,
    cfg: &IkConfig,
) -> Option<JointVector> {
    let limits = robot.limits();
    let margin = JointVector::repeat(cfg.joint_margin_rad);
    let (lower, upper) = (limits.lower + margin, limits.upper - margin);
    let target = PoseTarget {
        position: *p0,
        tool_axis: *n,
        roll_axis: None,
    };
    let cone = cfg.cone_deg.to_radians();
    let mut q = *start;
    // One buffer for every iteration's kinematics, written in place.
    let mut kin = robot.forward(&q);
    // The residual norm at the start of the current stall window.
    let mut window_start = f64::INFINITY;
    for iteration in 0..=cfg.max_iterations {
        if iteration > 0 {
            robot.forward_into(&q, &mut kin);
        }
        let (rows, mut error) = pose_residual(&kin, &target);
        let axis = kin.tool_axis();
        let angle = libm::atan2(axis.cross(n).norm(), axis.dot(n));
        let excess = (angle - cone).max(0.0);
        let orientation_scale = if angle > 0.0 { excess / angle } else { 0.0 };
        for k in 3..6 {
            error[k] *= orientation_scale;
        }
        if error.fixed_rows::<3>(0).norm() < cfg.position_tolerance_m && excess == 0.0 {
            return Some(q);
        }
        if cfg.stall_iterations > 0 && iteration % cfg.stall_iterations == 0 {
            let residual = error.norm();
            if residual > STALL_RATIO * window_start {
                return None;
            }
            window_start = residual;
        }
        let gram = rows * rows.transpose()
            + SMatrix::<f64, 6, 6>::identity() * (cfg.damping * cfg.damping);
        let mut step: JointVector = rows.transpose() * gram.cholesky()?.solve(&error);
        let largest = step.amax();
        if largest > cfg.max_step_rad {
            step *= cfg.max_step_rad / largest;
        }
        q = (q + step).zip_zip_map(&lower, &upper, |v, lo, hi| v.clamp(lo, hi));
    }
    None
}
