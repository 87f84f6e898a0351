//! Configurations moved a hair inside the joint limits, clear of the arm's own links and inside
//! the tool cone, as knots of the smooth path. A plan that rides a joint limit, grazes its own
//! links or rides the cone's edge has waypoints on that boundary; a spline through such knots
//! overshoots a limit it follows, and, neither the links' clearance nor the cone being convex
//! in joint space, a spline (or a chord) between two waypoints on their boundary bows out of it
//! (by a few micrometres, a few ten-thousandths of a degree). Knots held [`JOINT_INSET_RAD`]
//! inside the joint limits, [`CLEARANCE_INSET_M`] beyond the collision margin and turned
//! [`CONE_INSET_DEG`] inside the cone leave the spline between them room to stay inside.

use emg_control::{ConstraintConfig, Task, tool_angle_deg};
use emg_kinematics::{JointVector, Kinematics, Robot, Vec3};

/// Distance (rad) inside its position limits to which each joint of the smooth path's inner
/// knots is moved where it lies closer to them.
pub const JOINT_INSET_RAD: f64 = 1e-4;

/// Depth (degrees) inside the tool cone to which the smooth path's inner knots are turned where
/// they lie closer to its edge.
pub const CONE_INSET_DEG: f64 = 0.005;

/// Clearance (m) beyond the collision margin to which the smooth path's inner knots move the
/// arm's checked link pairs where they come closer to each other.
pub const CLEARANCE_INSET_M: f64 = 2e-5;

/// Joint step (rad) of the central differences of the links' clearance ([`clearance_gradient`]).
const CLEARANCE_STEP_RAD: f64 = 1e-7;

/// How far (m) below its target an inset's clearance may end.
const CLEARANCE_TOLERANCE_M: f64 = 1e-9;

/// Newton steps at most of one inset.
const INSET_STEPS: usize = 4;

/// How far (degrees) above its target depth an inset may end (Newton's last step is far closer).
const INSET_TOLERANCE_DEG: f64 = 1e-6;

/// The gradient `∂θ/∂q` of the angle `θ = ∠(z(q), n)` between the tool axis and `n` (rad per
/// rad): `−(n − (z·n) z)ᵀ (∂z/∂q) / sin θ`, since `dθ = −n·dz / sin θ` and `dz ⟂ z`. `None`
/// where `z` is parallel to `n` (the angle is not differentiable there).
pub(crate) fn tool_angle_gradient(kinematics: &Kinematics, n: &Vec3) -> Option<JointVector> {
    let z = kinematics.tool_axis();
    let across = n - z * z.dot(n);
    let sin = across.norm();
    (sin > 1e-12).then(|| -(kinematics.tool_axis_jacobian().transpose() * across) / sin)
}

/// The smallest clearance (m) between the arm's checked link pairs at `kinematics`
/// ([`Robot::min_clearance`]), infinite for an arm without pairs.
fn links_clearance(robot: &Robot, kinematics: &Kinematics) -> f64 {
    robot
        .min_clearance(kinematics)
        .map_or(f64::INFINITY, |hit| hit.clearance)
}

/// The gradient `∂c/∂q` of the links' clearance `c` ([`links_clearance`]) at `q` by central
/// differences of [`CLEARANCE_STEP_RAD`]: `c` is the distance between two capsules' axes less
/// their radii, smooth wherever the nearest pair and its closest features stay the same.
fn clearance_gradient(robot: &Robot, q: &JointVector) -> JointVector {
    let clearance = |q: &JointVector| links_clearance(robot, &robot.forward(q));
    JointVector::from_fn(|j, _| {
        if j >= robot.dof() {
            return 0.0;
        }
        let mut step = JointVector::zeros();
        step[j] = CLEARANCE_STEP_RAD;
        (clearance(&(q + step)) - clearance(&(q - step))) / (2.0 * CLEARANCE_STEP_RAD)
    })
}

/// The joint direction that changes a function of the configuration with `gradient` by one
/// unit (to first order) and moves the TCP not at all: the gradient projected into the null
/// space of the position Jacobian `J`, `N∇f / (∇fᵀ N ∇f)` with `N = I − Jᵀ(JJᵀ)⁻¹J`. `None` at
/// a singular `J` or where the null space cannot change the function.
fn null_space_turn(kinematics: &Kinematics, gradient: &JointVector) -> Option<JointVector> {
    let jacobian = kinematics.jacobian();
    let inverse_gram = kinematics.jacobian_gram().try_inverse()?;
    let projected = gradient - jacobian.transpose() * (inverse_gram * (jacobian * gradient));
    let gain = gradient.dot(&projected);
    (gain > 1e-12).then(|| projected / gain)
}

/// `q` with every joint at least [`JOINT_INSET_RAD`] inside its limits (where the range is
/// wider than twice that); then, where two of its checked link pairs come closer than
/// [`CLEARANCE_INSET_M`] beyond `constraints.collision_margin_m`, moved about its TCP (Newton
/// steps along [`null_space_turn`] of [`clearance_gradient`]) until they are that far clear;
/// then, where its tool axis lies less than [`CONE_INSET_DEG`] inside the task's cone of
/// half-angle `constraints.theta_max_deg`, turned about its TCP (the same, along the tool
/// angle's gradient) until it lies that far inside. `None` when a move fails. The moves shift
/// the TCP only to second order (tens of nanometres for a hundredth of a degree); no
/// constraint is checked here.
pub(crate) fn inset(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    q: &JointVector,
) -> Option<JointVector> {
    let limits = robot.limits();
    let mut q = JointVector::from_fn(|j, _| {
        let (lower, upper) = (limits.lower[j], limits.upper[j]);
        if upper - lower > 2.0 * JOINT_INSET_RAD {
            q[j].clamp(lower + JOINT_INSET_RAD, upper - JOINT_INSET_RAD)
        } else {
            q[j]
        }
    });
    let target_m = constraints.collision_margin_m + CLEARANCE_INSET_M;
    let kinematics = robot.forward(&q);
    // The broad phase answers for all but the few configurations that graze.
    if robot.first_collision(&kinematics, target_m).is_some() {
        q = newton_inset(robot, q, |kinematics, q| {
            let shortfall = target_m - links_clearance(robot, kinematics);
            (shortfall > CLEARANCE_TOLERANCE_M).then(|| {
                null_space_turn(kinematics, &clearance_gradient(robot, q))
                    .map(|turn| turn * shortfall)
            })
        })?;
    }
    let target_deg = constraints.theta_max_deg - CONE_INSET_DEG;
    newton_inset(robot, q, |kinematics, _| {
        let excess_deg = tool_angle_deg(&kinematics.tool_axis(), &task.n) - target_deg;
        (excess_deg > INSET_TOLERANCE_DEG).then(|| {
            let gradient = tool_angle_gradient(kinematics, &task.n)?;
            null_space_turn(kinematics, &gradient).map(|turn| -turn * excess_deg.to_radians())
        })
    })
}

/// `q` moved by up to [`INSET_STEPS`] Newton steps: `step` says, from the kinematics and the
/// configuration, `None` once the configuration is where it should be, else the step to add
/// (itself `None` where no step can be made). `None` when no step can be made or the steps do
/// not get there.
fn newton_inset(
    robot: &Robot,
    mut q: JointVector,
    step: impl Fn(&Kinematics, &JointVector) -> Option<Option<JointVector>>,
) -> Option<JointVector> {
    for _ in 0..=INSET_STEPS {
        match step(&robot.forward(&q), &q) {
            None => return Some(q),
            Some(change) => q += change?,
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use emg_kinematics::rotation_about;

    fn fr3() -> Robot {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
        Robot::from_urdf_file(&path, "link0", "pen_tip").unwrap()
    }

    /// A task whose normal lies `angle_deg` from the tool axis of `q`.
    fn task_at_angle(robot: &Robot, q: &JointVector, angle_deg: f64) -> Task {
        let kinematics = robot.forward(q);
        let z = kinematics.tool_axis();
        let across = z.cross(&Vec3::x()).normalize();
        let n = rotation_about(&across, angle_deg.to_radians()) * z;
        let d = n.cross(&across);
        Task::new(robot, kinematics.tcp(), d, n, Some(*q)).unwrap()
    }

    /// The default constraints with the cone's half-angle `theta_max_deg`.
    fn cone(theta_max_deg: f64) -> ConstraintConfig {
        ConstraintConfig {
            theta_max_deg,
            ..ConstraintConfig::default()
        }
    }

    fn angle_rad(robot: &Robot, task: &Task, q: &JointVector) -> f64 {
        tool_angle_deg(&robot.forward(q).tool_axis(), &task.n).to_radians()
    }

    #[test]
    fn the_tool_angle_gradient_matches_finite_differences() {
        let robot = fr3();
        let q = robot.mid_range();
        let task = task_at_angle(&robot, &q, 25.0);
        let gradient = tool_angle_gradient(&robot.forward(&q), &task.n).unwrap();
        let h = 1e-6;
        for j in 0..robot.dof() {
            let mut step = JointVector::zeros();
            step[j] = h;
            let fd = (angle_rad(&robot, &task, &(q + step))
                - angle_rad(&robot, &task, &(q - step)))
                / (2.0 * h);
            assert!(
                (fd - gradient[j]).abs() < 1e-7,
                "joint {j}: {fd} vs {}",
                gradient[j]
            );
        }
        assert!(
            gradient
                .rows(robot.dof(), gradient.len() - robot.dof())
                .iter()
                .all(|g| *g == 0.0)
        );
    }

    #[test]
    fn an_inset_turns_an_edge_configuration_inside_and_keeps_its_tcp() {
        let robot = fr3();
        let q = robot.mid_range();
        let theta_max_deg = 30.0;
        for outside_deg in [0.0, 0.001, 0.01] {
            let task = task_at_angle(&robot, &q, theta_max_deg + outside_deg);
            let turned = inset(&robot, &task, &cone(theta_max_deg), &q).unwrap();
            let angle_deg = angle_rad(&robot, &task, &turned).to_degrees();
            assert!(
                (angle_deg - (theta_max_deg - CONE_INSET_DEG)).abs() <= INSET_TOLERANCE_DEG,
                "{angle_deg}"
            );
            let moved_m = (robot.forward(&turned).tcp() - robot.forward(&q).tcp()).norm();
            assert!(moved_m < 1e-6, "the TCP moved {moved_m} m");
        }
        // A configuration already that far inside stays as it is.
        let task = task_at_angle(&robot, &q, theta_max_deg - 2.0 * CONE_INSET_DEG);
        assert_eq!(inset(&robot, &task, &cone(theta_max_deg), &q), Some(q));
    }

    #[test]
    fn an_inset_moves_joints_off_their_limits() {
        let robot = fr3();
        let limits = robot.limits();
        let mut q = robot.mid_range();
        q[6] = limits.upper[6];
        q[0] = limits.lower[0] + 0.5 * JOINT_INSET_RAD;
        let task = task_at_angle(&robot, &q, 10.0);
        let moved = inset(&robot, &task, &cone(30.0), &q).unwrap();
        assert_eq!(moved[6], limits.upper[6] - JOINT_INSET_RAD);
        assert_eq!(moved[0], limits.lower[0] + JOINT_INSET_RAD);
        assert_eq!(moved.rows(1, 5), q.rows(1, 5));
    }

    #[test]
    fn an_inset_moves_grazing_links_apart_and_keeps_its_tcp() {
        let robot = fr3();
        let q = robot.mid_range();
        let task = task_at_angle(&robot, &q, 10.0);
        let clearance = links_clearance(&robot, &robot.forward(&q));
        // The links graze once the collision margin is their clearance, or a hair more.
        for short_m in [0.0, 1e-6, 1e-5] {
            let constraints = ConstraintConfig {
                collision_margin_m: clearance + short_m,
                ..cone(30.0)
            };
            let moved = inset(&robot, &task, &constraints, &q).unwrap();
            let kinematics = robot.forward(&moved);
            let beyond_m = links_clearance(&robot, &kinematics) - constraints.collision_margin_m;
            assert!(
                (CLEARANCE_INSET_M - CLEARANCE_TOLERANCE_M..1.01 * CLEARANCE_INSET_M)
                    .contains(&beyond_m),
                "{beyond_m} m beyond the margin"
            );
            let moved_m = (kinematics.tcp() - robot.forward(&q).tcp()).norm();
            assert!(moved_m < 1e-6, "the TCP moved {moved_m} m");
        }
        // Links that far clear stay where they are.
        let constraints = ConstraintConfig {
            collision_margin_m: clearance - 2.0 * CLEARANCE_INSET_M,
            ..cone(30.0)
        };
        assert_eq!(inset(&robot, &task, &constraints, &q), Some(q));
    }

    #[test]
    fn the_clearance_gradient_predicts_a_small_move() {
        let robot = fr3();
        let q = robot.mid_range();
        let gradient = clearance_gradient(&robot, &q);
        let clearance = |q: &JointVector| links_clearance(&robot, &robot.forward(q));
        let step = gradient.normalize() * 1e-4;
        let predicted = gradient.dot(&step);
        let actual = clearance(&(q + step)) - clearance(&q);
        assert!(predicted > 1e-6, "{predicted}");
        assert!(
            (actual - predicted).abs() < 1e-3 * predicted,
            "{actual} vs {predicted}"
        );
    }
}
