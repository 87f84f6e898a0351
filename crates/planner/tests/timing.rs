//! Plans that ride a joint limit or the tool cone's edge, timed rest to rest as `emg plan` times
//! them: the smooth path keeps the whole planned motion (no cut), and every sample of the timed
//! file holds every constraint, as `emg check` verifies it.

mod common;

use common::{TimedArm, data};
use emg_control::tool_angle_deg;
use emg_io::read_tasks;
use emg_planner::{PlanRequest, PlannerConfig, PlannerKind, ShippedRobot};

/// A waypoint near the cone's edge has its tool axis within this of it (degrees).
const EDGE_DEG: f64 = 0.01;

/// A waypoint whose links come within this of each other (m) grazes them.
const GRAZE_M: f64 = 1e-5;

/// What a plan rides: a joint limit, the cone's edge ([`EDGE_DEG`]), its links' grazing
/// ([`GRAZE_M`]).
struct Rides {
    joint_limit: bool,
    cone_edge: bool,
    grazing_links: bool,
}

/// Plans `arm`'s evaluation task `index` as `emg plan` does, times and writes it, and checks
/// the timed file; returns what the planned waypoints ride.
fn plan_time_and_check(arm: ShippedRobot, index: usize) -> Rides {
    let timed = TimedArm::new(arm, PlannerConfig::default());
    let planner = &timed.planner;
    let task = read_tasks(
        &arm.data_dir(&data()).join("tasks/eval-v1.tasks"),
        planner.robot(),
    )
    .expect("shipped tasks")
    .swap_remove(index);
    let request = PlanRequest {
        planner: PlannerKind::Search,
        ..PlanRequest::pipeline()
    };
    let plan = planner.plan(&task, &request).expect("a plan");
    let name = format!("{} task {index}", arm.name);
    let files = timed.checked_files(&name, &task, &plan, &request);
    let cut = &files.timing.cut_reason;
    assert!(files.timing.cut_at_point.is_none(), "{name}: cut, {cut:?}");
    let travel = files.timing.path_travel_m;
    let planned = plan.trajectory.path_length_m;
    assert!(
        travel > 0.95 * planned,
        "{name}: {travel} m timed of {planned} m planned"
    );
    let constraints = &planner.config().rollout.constraints;
    let robot = planner.robot();
    let limits = robot.limits();
    let steps = &plan.trajectory.steps;
    Rides {
        joint_limit: steps.iter().any(|s| {
            (0..robot.dof()).any(|j| s.q[j] == limits.lower[j] || s.q[j] == limits.upper[j])
        }),
        cone_edge: steps.iter().any(|s| {
            let axis = robot.forward(&s.q).tool_axis();
            tool_angle_deg(&axis, &task.n) > constraints.theta_max_deg - EDGE_DEG
        }),
        grazing_links: steps.iter().any(|s| {
            let margin = constraints.collision_margin_m;
            robot
                .min_clearance(&robot.forward(&s.q))
                .is_some_and(|hit| hit.clearance < margin + GRAZE_M)
        }),
    }
}

#[test]
fn a_plan_on_the_cone_edge_is_timed_inside_the_cone() {
    // FR3 evaluation task 4290: its waypoints come within 0.01° of the cone's edge, and the
    // smooth path, between two of its check points 1.8 mm apart, once left the cone by 0.0009°.
    let rides = plan_time_and_check(ShippedRobot::by_name("fr3").unwrap(), 4290);
    assert!(rides.cone_edge, "the plan comes near the cone's edge");
}

#[test]
fn a_plan_on_a_joint_limit_is_timed_whole_within_the_limits() {
    // FR3 evaluation task 9028 and iiwa 14 task 7680: their smooth paths, overshooting joint
    // 7's limit, were once cut to their first waypoint and to 0.010 m.
    for (arm, index) in [("fr3", 9028), ("iiwa14", 7680)] {
        let rides = plan_time_and_check(ShippedRobot::by_name(arm).unwrap(), index);
        assert!(
            rides.joint_limit,
            "{arm} task {index}: the plan rides a joint limit"
        );
    }
}

#[test]
fn a_plan_that_grazes_its_own_links_is_timed_clear_of_them() {
    // UR5e evaluation task 2004: its pen passes its shoulder at a clearance of a few
    // micrometres, and the smooth path between two such waypoints once cut into the shoulder.
    let rides = plan_time_and_check(ShippedRobot::by_name("ur5e").unwrap(), 2004);
    assert!(rides.grazing_links, "the plan grazes its own links");
}
