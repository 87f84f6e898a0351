//! How far a six-joint arm with a spherical wrist reaches, and where a drawing goes by default
//! on an arm whose reach is not the FR3's.

use emg_io::Placement;
use emg_kinematics::{JointVector, Robot, Vec3};
use nalgebra::UnitQuaternion;

/// How far a six-joint arm with a spherical wrist reaches: its wrist centre at most the
/// stretched elbow's distance from axis 2. A controller that interpolates in Cartesian space
/// faults where its path leaves that, and a plan that reaches as far as the arm does runs
/// along its edge, where a straight line between two of its poses may step over it.
#[derive(Clone, Copy, Debug)]
pub struct WristReach {
    /// The TCP's distance from the wrist centre along the tool axis (m).
    wrist_back_m: f64,
    /// The stretched elbow's distance from axis 2's origin to the wrist centre (m).
    reach_m: f64,
}

/// How far (m) beyond the stretched elbow's reach a point of the controller's path may lie: the
/// plan's own poses stand on that edge to rounding.
const REACH_ROUNDING_M: f64 = 1e-7;

impl WristReach {
    /// The reach of `robot`, whose wrist centre is axis 5's origin and whose TCP lies on axis 6
    /// (checked at the calibration pose; `None` where it does not).
    pub fn of(robot: &Robot) -> Option<Self> {
        if robot.dof() != 6 {
            return None;
        }
        let kinematics = robot.forward(&robot.joint_vector(&[0.0; 6]));
        let (o2, o3, wrist) = (
            kinematics.joint_origin(1),
            kinematics.joint_origin(2),
            kinematics.joint_origin(4),
        );
        let offset = kinematics.tcp() - wrist;
        let axis = kinematics.tool_axis();
        (offset.cross(&axis).norm() < 1e-9).then(|| Self {
            wrist_back_m: offset.dot(&axis),
            reach_m: (o3 - o2).norm() + (wrist - o3).norm(),
        })
    }

    /// Whether the TCP at `position` turned by `rotation` keeps its wrist centre within reach
    /// of axis 2 where it stands at the configuration `near`.
    pub(crate) fn holds(
        &self,
        robot: &Robot,
        (position, rotation): (&Vec3, &UnitQuaternion<f64>),
        near: &JointVector,
    ) -> bool {
        let wrist = position - rotation * Vec3::z() * self.wrist_back_m;
        let shoulder = robot.forward(near).joint_origin(1);
        (wrist - shoulder).norm() <= self.reach_m + REACH_ROUNDING_M
    }
}

/// Where the default placement's drawing goes (m, base frame): in front of the FR3, where the
/// shipped arms' results were measured.
const FR3_ORIGIN_M: [f64; 3] = [0.45, 0.0, 0.25];

/// The share of its reach a default drawing's wrist centre stands from axis 2, at most and
/// at least: nearer the arm folds, farther it stretches.
const COMFORTABLE_REACH: (f64, f64) = (0.5, 0.9);

/// The share of its reach a drawing's wrist centre stands from axis 2 where the default place
/// is chosen by the arm's reach.
const DEFAULT_REACH_SHARE: f64 = 0.7;

/// The default placement of an SVG drawing on `robot` (pen down, 0.2 m wide): the FR3's
/// ([`Placement::default`], 0.45 m in front, 0.25 m up) where the arm's wrist centre stands
/// there between [`COMFORTABLE_REACH`] of its reach from axis 2 (or where the arm's reach is not
/// a spherical wrist's, [`WristReach::of`]); else in front of the arm at its shoulder's height,
/// the wrist centre [`DEFAULT_REACH_SHARE`] of its reach out, the pen straight below it.
pub fn default_placement(robot: &Robot) -> Placement {
    let placement = Placement::default();
    let Some(reach) = WristReach::of(robot) else {
        return placement;
    };
    let shoulder = robot
        .forward(&robot.joint_vector(&[0.0; 6]))
        .joint_origin(1);
    let wrist_over = |origin: Vec3| origin + Vec3::z() * reach.wrist_back_m;
    let share = (wrist_over(Vec3::from(FR3_ORIGIN_M)) - shoulder).norm() / reach.reach_m;
    if (COMFORTABLE_REACH.0..=COMFORTABLE_REACH.1).contains(&share) {
        return placement;
    }
    let forward = Vec3::new(shoulder.x, shoulder.y, 0.0)
        .try_normalize(1e-9)
        .unwrap_or(Vec3::x());
    let wrist = shoulder + forward * (DEFAULT_REACH_SHARE * reach.reach_m);
    let origin = wrist - Vec3::z() * reach.wrist_back_m;
    Placement {
        origin_m: [round_mm(origin.x), round_mm(origin.y), round_mm(origin.z)],
        ..placement
    }
}

/// `value` (m) rounded to the millimetre.
fn round_mm(value: f64) -> f64 {
    (value * 1e3).round() / 1e3
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shipped(file: &str) -> Robot {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data/robots")
            .join(file);
        Robot::from_chain_file(path).expect("a shipped robot")
    }

    #[test]
    fn the_shipped_arms_keep_the_fr3s_place_and_a_larger_arm_gets_its_own() {
        for file in [
            "fr3_pen.urdf",
            "iiwa14_pen.urdf",
            "ur5e_pen.urdf",
            "irb120_pen.urdf",
        ] {
            assert_eq!(
                default_placement(&shipped(file)).origin_m,
                FR3_ORIGIN_M,
                "{file}"
            );
        }
        // The IRB 120 scaled up three times over reaches three times as far: its place moves
        // out and up with it.
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../data/robots/irb120_pen.urdf"),
        )
        .unwrap();
        let tripled = text
            .replace("xyz=\"0 0 0.29\"", "xyz=\"0 0 0.87\"")
            .replace("xyz=\"0 0 0.27\"", "xyz=\"0 0 0.81\"")
            .replace("xyz=\"0 0 0.07\"", "xyz=\"0 0 0.21\"")
            .replace("xyz=\"0.302 0 0\"", "xyz=\"0.906 0 0\"");
        let large = Robot::from_chain_str(&tripled).unwrap();
        let origin = default_placement(&large).origin_m;
        let reach = WristReach::of(&large).unwrap();
        assert!(origin[0] > 0.9 && origin[2] > 0.5, "{origin:?}");
        let wrist = Vec3::from(origin) + Vec3::z() * reach.wrist_back_m;
        let share = (wrist - Vec3::new(0.0, 0.0, 0.87)).norm() / reach.reach_m;
        assert!((share - DEFAULT_REACH_SHARE).abs() < 0.01, "{share}");
    }
}
