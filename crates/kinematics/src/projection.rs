//! Newton projection of a configuration onto an exact TCP pose within the joint limits, and
//! onto a TCP position alone.

use nalgebra::{Matrix3, SMatrix, SVector};
use serde::{Deserialize, Serialize};

use crate::pseudo_inverse::{DampingConfig, damped_pseudo_inverse};
use crate::robot::Robot;
use crate::vectors::{JointVector, MAX_DOF, Vec3};

/// The pose a configuration is projected onto.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseTarget {
    /// TCP position `p0` (m).
    pub position: Vec3,
    /// Unit tool axis the TCP z-axis must equal (`n`).
    pub tool_axis: Vec3,
    /// Optional unit TCP x-axis (fixes the roll about the tool axis); must be ⟂ `tool_axis`.
    pub roll_axis: Option<Vec3>,
}

impl PoseTarget {
    /// The target of SPEC §6: `z = n`, `x = normalise(d − (d·n)n)`.
    pub fn with_roll_from_direction(position: Vec3, n: Vec3, d: Vec3) -> Self {
        let x = (d - n * d.dot(&n)).normalize();
        Self {
            position,
            tool_axis: n,
            roll_axis: Some(x),
        }
    }
}

/// Settings of the Levenberg–Marquardt (damped Newton) iteration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ProjectionConfig {
    /// Iteration cap (every trial step counts, accepted or not).
    pub max_iterations: usize,
    /// Position error (m) below which the pose counts as reached.
    pub position_tolerance_m: f64,
    /// Orientation error (rad) below which the pose counts as reached.
    pub orientation_tolerance_rad: f64,
    /// Initial Levenberg damping `μ` added to `MMᵀ`; adapted by `damping_factor` per trial.
    pub damping: f64,
    /// Factor dividing `μ` after an accepted step and multiplying it after a rejected one.
    pub damping_factor: f64,
    /// Smallest damping (near the solution the step is a pure Gauss–Newton step).
    pub min_damping: f64,
    /// Largest damping (far steps become short gradient steps).
    pub max_damping: f64,
    /// Largest joint change of one iteration (rad, max-norm).
    pub max_step_rad: f64,
    /// Required distance from every joint limit (rad).
    pub joint_margin_rad: f64,
}

impl Default for ProjectionConfig {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            position_tolerance_m: 1e-10,
            orientation_tolerance_rad: 1e-10,
            damping: 1e-4,
            damping_factor: 10.0,
            min_damping: 1e-14,
            max_damping: 1e4,
            max_step_rad: 0.3,
            joint_margin_rad: 0.0,
        }
    }
}

/// Why a projection failed; the projection never returns a configuration that misses the pose.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProjectionError {
    /// The iteration did not reach the pose (typically held back by a joint limit).
    #[error(
        "Newton projection did not converge in {iterations} iterations \
         (position error {position_error_m:.3e} m, orientation error {orientation_error_rad:.3e} rad)"
    )]
    NotConverged {
        /// Iterations run.
        iterations: usize,
        /// Remaining position error (m).
        position_error_m: f64,
        /// Remaining orientation error (rad).
        orientation_error_rad: f64,
    },
    /// The target itself is unusable.
    #[error("pose target field '{field}' {problem}")]
    BadTarget {
        /// Offending field.
        field: &'static str,
        /// What is wrong with it.
        problem: &'static str,
    },
}

/// Newton steps [`project_to_point`] takes at most.
pub const POINT_ITERATIONS: usize = 50;

/// TCP distance (m) from the point within which [`project_to_point`] has converged.
pub const POINT_TOLERANCE_M: f64 = 1e-6;

/// The configuration near `q` whose TCP lies within [`POINT_TOLERANCE_M`] of `point`, the tool
/// axis free: Newton steps `q ← q + J⁺ e` on the TCP position (`J⁺` the pseudo-inverse at each
/// step, damped as [`DampingConfig::default`]; the joint limits not held), at most
/// [`POINT_ITERATIONS`]; `None` where they do not converge.
pub fn project_to_point(robot: &Robot, q: &JointVector, point: &Vec3) -> Option<JointVector> {
    let mut current = *q;
    for _ in 0..POINT_ITERATIONS {
        let kinematics = robot.forward(&current);
        let error = point - kinematics.tcp();
        if error.norm() <= POINT_TOLERANCE_M {
            return Some(current);
        }
        let pseudo_inverse =
            damped_pseudo_inverse(kinematics.jacobian(), &DampingConfig::default());
        current += pseudo_inverse.matrix * error;
    }
    None
}

/// Projects `start` onto the exact pose `target` by Levenberg–Marquardt steps, keeping every
/// joint within `[q_min + margin, q_max − margin]` (Sec. 4.1). A trial step is accepted only if it
/// lowers the squared pose error (then `μ` shrinks, else it grows); joints resting on a bound
/// whose step points outward are frozen for that step, so clamping never stalls the iteration.
/// Returns the configuration and the number of iterations, or an honest failure. Allocation-free.
pub fn project_to_pose(
    robot: &Robot,
    start: &JointVector,
    target: &PoseTarget,
    cfg: &ProjectionConfig,
) -> Result<(JointVector, usize), ProjectionError> {
    check_target(target)?;
    let limits = robot.limits();
    let margin = JointVector::repeat(cfg.joint_margin_rad);
    let (lower, upper) = (limits.lower + margin, limits.upper - margin);
    let clamp = |q: JointVector| q.zip_zip_map(&lower, &upper, |v, lo, hi| v.clamp(lo, hi));
    let mut q = clamp(*start);
    // One buffer for every trial's kinematics, written in place.
    let mut kinematics = robot.forward(&q);
    let (mut rows, mut error) = pose_residual(&kinematics, target);
    let mut damping = cfg.damping;
    for iteration in 0..=cfg.max_iterations {
        let (position_error, orientation_error) = split_norms(&error);
        if position_error < cfg.position_tolerance_m
            && orientation_error < cfg.orientation_tolerance_rad
        {
            return Ok((q, iteration));
        }
        if iteration == cfg.max_iterations {
            break;
        }
        let Some(mut step) = damped_step(&rows, &error, damping) else {
            break;
        };
        // Freeze joints on a bound that the step would push further out, and solve again.
        let mut frozen = rows;
        let mut any_frozen = false;
        for i in 0..MAX_DOF {
            let outward =
                (q[i] <= lower[i] && step[i] < 0.0) || (q[i] >= upper[i] && step[i] > 0.0);
            if outward {
                frozen.column_mut(i).fill(0.0);
                any_frozen = true;
            }
        }
        if any_frozen {
            let Some(free_step) = damped_step(&frozen, &error, damping) else {
                break;
            };
            step = free_step;
        }
        let largest = step.amax();
        if largest > cfg.max_step_rad {
            step *= cfg.max_step_rad / largest;
        }
        let trial = clamp(q + step);
        robot.forward_into(&trial, &mut kinematics);
        let (trial_rows, trial_error) = pose_residual(&kinematics, target);
        if trial_error.norm_squared() < error.norm_squared() {
            (q, rows, error) = (trial, trial_rows, trial_error);
            damping = (damping / cfg.damping_factor).max(cfg.min_damping);
        } else {
            damping = (damping * cfg.damping_factor).min(cfg.max_damping);
        }
    }
    let (position_error_m, orientation_error_rad) = split_norms(&error);
    Err(ProjectionError::NotConverged {
        iterations: cfg.max_iterations,
        position_error_m,
        orientation_error_rad,
    })
}

/// Norms of the position and orientation parts of a pose residual.
fn split_norms(error: &SVector<f64, 6>) -> (f64, f64) {
    (
        error.fixed_rows::<3>(0).norm(),
        error.fixed_rows::<3>(3).norm(),
    )
}

/// The Levenberg–Marquardt step `Mᵀ(MMᵀ + μI)⁻¹e`.
fn damped_step(
    rows: &SMatrix<f64, 6, MAX_DOF>,
    error: &SVector<f64, 6>,
    damping: f64,
) -> Option<JointVector> {
    let gram = rows * rows.transpose() + SMatrix::<f64, 6, 6>::identity() * damping;
    gram.cholesky().map(|c| rows.transpose() * c.solve(error))
}

fn check_target(target: &PoseTarget) -> Result<(), ProjectionError> {
    let unit = |v: &Vec3| v.iter().all(|c| c.is_finite()) && (v.norm() - 1.0).abs() < 1e-6;
    if !target.position.iter().all(|c| c.is_finite()) {
        return Err(ProjectionError::BadTarget {
            field: "position",
            problem: "is not finite",
        });
    }
    if !unit(&target.tool_axis) {
        return Err(ProjectionError::BadTarget {
            field: "tool_axis",
            problem: "is not a unit vector",
        });
    }
    if let Some(x) = &target.roll_axis
        && (!unit(x) || x.dot(&target.tool_axis).abs() > 1e-6)
    {
        return Err(ProjectionError::BadTarget {
            field: "roll_axis",
            problem: "is not a unit vector perpendicular to tool_axis",
        });
    }
    Ok(())
}

/// Task rows `M` (6×7) and residual `e` of the pose constraint at `kin`: rows 0–2 are the
/// position Jacobian and `e` the position error; rows 3–5 the angular Jacobian and the rotation
/// vector toward the target. Without a roll target only the two directions ⟂ `z` are
/// constrained (rows 3–4) and row 5 and `e[5]` are zero, so `M` has rank 5.
pub fn pose_residual(
    kin: &crate::fk::Kinematics,
    target: &PoseTarget,
) -> (SMatrix<f64, 6, MAX_DOF>, SVector<f64, 6>) {
    let mut rows = SMatrix::<f64, 6, MAX_DOF>::zeros();
    rows.fixed_rows_mut::<3>(0).copy_from(kin.jacobian());
    let mut error = SVector::<f64, 6>::zeros();
    error
        .fixed_rows_mut::<3>(0)
        .copy_from(&(target.position - kin.tcp()));
    let current = kin.tcp_rotation();
    let axes: [Vec3; MAX_DOF] = std::array::from_fn(|i| kin.joint_axis(i));
    match &target.roll_axis {
        Some(x) => {
            let goal = Matrix3::from_columns(&[*x, target.tool_axis.cross(x), target.tool_axis]);
            error
                .fixed_rows_mut::<3>(3)
                .copy_from(&rotation_vector(&(goal * current.transpose())));
            for (i, axis) in axes.iter().enumerate() {
                rows.fixed_view_mut::<3, 1>(3, i).copy_from(axis);
            }
        }
        None => {
            let z = kin.tool_axis();
            let (u, v) = (
                current.column(0).into_owned(),
                current.column(1).into_owned(),
            );
            let cross = z.cross(&target.tool_axis);
            let sin = cross.norm();
            let angle = libm::atan2(sin, z.dot(&target.tool_axis));
            let rotation_axis = if sin > 1e-12 { cross / sin } else { u };
            let phi = rotation_axis * angle;
            error[3] = u.dot(&phi);
            error[4] = v.dot(&phi);
            for (i, axis) in axes.iter().enumerate() {
                rows[(3, i)] = u.dot(axis);
                rows[(4, i)] = v.dot(axis);
            }
        }
    }
    (rows, error)
}

/// Rotation vector (axis · angle) of rotation matrix `r`, accurate for every angle.
///
/// `Rotation3::scaled_axis` takes the angle from `acos((tr r − 1)/2)`, which is blind below
/// ~1e-8 rad (and returns zero outright when the skew part is below machine epsilon), so a
/// 1e-10 orientation tolerance could be declared met with an error of ~2e-8 rad. Here the angle is
/// `atan2(‖skew‖, (tr r − 1)/2)`; near π the axis comes from the symmetric part.
fn rotation_vector(r: &Matrix3<f64>) -> Vec3 {
    let skew = Vec3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) * 0.5;
    let sin = skew.norm();
    let cos = (r.trace() - 1.0) * 0.5;
    let angle = libm::atan2(sin, cos);
    if cos > 0.0 || sin > 1e-6 {
        return if sin > 0.0 {
            skew * (angle / sin)
        } else {
            Vec3::zeros()
        };
    }
    // Angle near π: r ≈ 2aaᵀ − I, so (r + I)/2 ≈ aaᵀ; take its largest column, signed by skew.
    let outer = (r + Matrix3::identity()) * 0.5;
    let k = (0..3)
        .max_by(|&i, &j| outer[(i, i)].total_cmp(&outer[(j, j)]))
        .unwrap_or(0);
    let mut axis = outer.column(k).into_owned();
    axis /= axis.norm();
    if axis.dot(&skew) < 0.0 {
        axis = -axis;
    }
    axis * angle
}
