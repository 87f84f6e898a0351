//! Configurations moved a hair inside the joint limits and the tool cone, as knots of the
//! smooth path. A plan that rides a joint limit or the cone's edge has waypoints on it; a spline
//! through such knots overshoots a limit it follows, and, the cone not being convex in joint
//! space, a spline (or a chord) between two waypoints on its edge bows out of it by a few
//! ten-thousandths of a degree. Knots held [`JOINT_INSET_RAD`] inside the joint limits and
//! turned [`CONE_INSET_DEG`] inside the cone leave the spline between them room to stay inside.

use emg_control::{Task, tool_angle_deg};
use emg_kinematics::{JointVector, Kinematics, Robot, Vec3};

/// Distance (rad) inside its position limits to which each joint of the smooth path's inner
/// knots is moved where it lies closer to them.
pub const JOINT_INSET_RAD: f64 = 1e-4;

/// Depth (degrees) inside the tool cone to which the smooth path's inner knots are turned where
/// they lie closer to its edge.
pub const CONE_INSET_DEG: f64 = 0.005;

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

/// The joint direction that turns the tool angle by one radian (to first order) and moves the
/// TCP not at all: the gradient projected into the null space of the position Jacobian `J`,
/// `N∇θ / (∇θᵀ N ∇θ)` with `N = I − Jᵀ(JJᵀ)⁻¹J`. `None` at a singular `J` or where the null
/// space cannot turn the angle.
fn angle_turn(kinematics: &Kinematics, n: &Vec3) -> Option<JointVector> {
    let gradient = tool_angle_gradient(kinematics, n)?;
    let jacobian = kinematics.jacobian();
    let inverse_gram = kinematics.jacobian_gram().try_inverse()?;
    let projected = gradient - jacobian.transpose() * (inverse_gram * (jacobian * gradient));
    let gain = gradient.dot(&projected);
    (gain > 1e-12).then(|| projected / gain)
}

/// `q` with every joint at least [`JOINT_INSET_RAD`] inside its limits (where the range is
/// wider than twice that), then, where its tool axis lies less than [`CONE_INSET_DEG`] inside
/// the task's cone of half-angle `theta_max_deg`, turned about its TCP (Newton steps along
/// [`angle_turn`]) until it lies that far inside; `None` when the turn fails. The turn moves
/// the TCP only to second order (tens of nanometres for a hundredth of a degree); no
/// constraint is checked here.
pub(crate) fn inset(
    robot: &Robot,
    task: &Task,
    theta_max_deg: f64,
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
    let target_deg = theta_max_deg - CONE_INSET_DEG;
    for _ in 0..=INSET_STEPS {
        let kinematics = robot.forward(&q);
        let angle_deg = tool_angle_deg(&kinematics.tool_axis(), &task.n);
        if angle_deg <= target_deg + INSET_TOLERANCE_DEG {
            return Some(q);
        }
        q -= angle_turn(&kinematics, &task.n)? * (angle_deg - target_deg).to_radians();
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
            let turned = inset(&robot, &task, theta_max_deg, &q).unwrap();
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
        assert_eq!(inset(&robot, &task, theta_max_deg, &q), Some(q));
    }

    #[test]
    fn an_inset_moves_joints_off_their_limits() {
        let robot = fr3();
        let limits = robot.limits();
        let mut q = robot.mid_range();
        q[6] = limits.upper[6];
        q[0] = limits.lower[0] + 0.5 * JOINT_INSET_RAD;
        let task = task_at_angle(&robot, &q, 10.0);
        let moved = inset(&robot, &task, 30.0, &q).unwrap();
        assert_eq!(moved[6], limits.upper[6] - JOINT_INSET_RAD);
        assert_eq!(moved[0], limits.lower[0] + JOINT_INSET_RAD);
        assert_eq!(moved.rows(1, 5), q.rows(1, 5));
    }
}
