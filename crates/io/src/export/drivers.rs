//! The names and frames the vendors' ROS 2 drivers use for the shipped arms, as data: the joint
//! names a `JointTrajectory` message must carry for each driver, the controller topic it
//! listens on, and how the shipped robot file's base frame lies in the vendor's description.

/// How one shipped robot is driven from ROS 2.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DriverProfile {
    /// The shipped robot's name (`fr3`, `iiwa14`, `ur5e`).
    pub robot: &'static str,
    /// The ROS 2 driver the names come from.
    pub driver: &'static str,
    /// The shipped robot file's joint names, base to tip.
    pub file_joint_names: &'static [&'static str],
    /// The driver's joint names, in the same order.
    pub joint_names: &'static [&'static str],
    /// The trajectory controller's topic (`trajectory_msgs/msg/JointTrajectory`) in the driver's
    /// default launch; its `follow_joint_trajectory` action lies beside it.
    pub topic: &'static str,
    /// The vendor description's frame the shipped base frame is, or is turned from (the
    /// message's `header.frame_id`).
    pub base_frame: &'static str,
    /// How the shipped robot file's base frame relates to `base_frame`.
    pub base_relation: &'static str,
}

/// The FR3's joints, as the shipped robot file and franka_ros2 both name them.
const FR3_JOINT_NAMES: &[&str] = &[
    "fr3_joint1",
    "fr3_joint2",
    "fr3_joint3",
    "fr3_joint4",
    "fr3_joint5",
    "fr3_joint6",
    "fr3_joint7",
];

/// The Franka Research 3 through franka_ros2 (frankaemika/franka_ros2, its `fr3_arm_controller`
/// of `franka_moveit_config`): joints `fr3_joint1..7`, base `fr3_link0`.
const FR3: DriverProfile = DriverProfile {
    robot: "fr3",
    driver: "franka_ros2 (frankaemika/franka_ros2)",
    file_joint_names: FR3_JOINT_NAMES,
    joint_names: FR3_JOINT_NAMES,
    topic: "/fr3_arm_controller/joint_trajectory",
    base_frame: "fr3_link0",
    base_relation: "the shipped base frame link0 is franka_description's fr3_link0 (the same \
                    published kinematics; joint values are the driver's as they are)",
};

/// The KUKA LBR iiwa 14 R820 through the LBR-Stack (lbr-stack/lbr_fri_ros2_stack, robot name
/// `lbr`, its `joint_trajectory_controller`): joints `lbr_A1..A7`, base `lbr_link_0`. The shipped
/// file's `iiwa_joint_N` names match neither it nor IFL-CAMP's iiwa_stack (`iiwa_joint_N` there
/// too, but ROS 1 only).
const IIWA14: DriverProfile = DriverProfile {
    robot: "iiwa14",
    driver: "lbr_fri_ros2_stack (lbr-stack/lbr_fri_ros2_stack, robot_name lbr)",
    file_joint_names: &[
        "iiwa_joint_1",
        "iiwa_joint_2",
        "iiwa_joint_3",
        "iiwa_joint_4",
        "iiwa_joint_5",
        "iiwa_joint_6",
        "iiwa_joint_7",
    ],
    joint_names: &[
        "lbr_A1", "lbr_A2", "lbr_A3", "lbr_A4", "lbr_A5", "lbr_A6", "lbr_A7",
    ],
    topic: "/lbr/joint_trajectory_controller/joint_trajectory",
    base_frame: "lbr_link_0",
    base_relation: "the shipped base frame iiwa_link_0 is the arm's mounting flange, z up \
                    through joint A1, as lbr_description's lbr_link_0 (joint values are KUKA's \
                    axis angles A1..A7 as they are)",
};

/// The Universal Robots UR5e through Universal_Robots_ROS2_Driver (its default
/// `scaled_joint_trajectory_controller`): joints `shoulder_pan_joint ... wrist_3_joint`, whose
/// names the shipped file already uses. Its base frame is the controller's Base frame, which
/// ur_description calls `base`: its `base_link` turned π about z.
const UR5E: DriverProfile = DriverProfile {
    robot: "ur5e",
    driver: "Universal_Robots_ROS2_Driver (UniversalRobots/Universal_Robots_ROS2_Driver)",
    file_joint_names: UR_JOINT_NAMES,
    joint_names: UR_JOINT_NAMES,
    topic: "/scaled_joint_trajectory_controller/joint_trajectory",
    base_frame: "base",
    base_relation: "the shipped base frame base_link is the UR controller's Base frame, \
                    ur_description's `base`, which is ur_description's `base_link` turned π \
                    about z (x and y negated); joint values are the teach pendant's as they are",
};

/// The six joints of a Universal Robots arm, base to tip, as Universal Robots' descriptions and
/// drivers name them.
pub const UR_JOINT_NAMES: &[&str] = &[
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
];

/// The driver profile of every shipped robot.
pub const DRIVER_PROFILES: [DriverProfile; 3] = [FR3, IIWA14, UR5E];

impl DriverProfile {
    /// The profile of the shipped robot called `name`.
    pub fn for_shipped(name: &str) -> Option<&'static Self> {
        DRIVER_PROFILES.iter().find(|p| p.robot == name)
    }

    /// Whether the robot's base frame and its last joint's segment are a Universal Robots
    /// controller's Base frame and tool flange, so that a native UR program's poses and TCP
    /// mean on the controller what they mean here: the shipped UR5e's, authored so.
    pub fn has_ur_controller_frames(&self) -> bool {
        self.robot == UR5E.robot
    }
}

/// Whether `joint_names` are a Universal Robots arm's six.
pub fn is_universal_robots_arm(joint_names: &[String]) -> bool {
    joint_names.len() == UR_JOINT_NAMES.len()
        && joint_names.iter().zip(UR_JOINT_NAMES).all(|(a, b)| a == b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_profile_maps_each_joint() {
        for profile in DRIVER_PROFILES {
            assert_eq!(profile.file_joint_names.len(), profile.joint_names.len());
            assert!(matches!(profile.joint_names.len(), 6 | 7));
        }
        assert_eq!(
            DriverProfile::for_shipped("iiwa14").unwrap().joint_names[0],
            "lbr_A1"
        );
        assert!(DriverProfile::for_shipped("ur5").is_none());
        let ur: Vec<String> = UR_JOINT_NAMES.iter().map(|s| s.to_string()).collect();
        assert!(is_universal_robots_arm(&ur));
        assert!(!is_universal_robots_arm(&ur[..5]));
    }
}
