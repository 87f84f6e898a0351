//! What the crate's unit tests share: the shipped FR3 and its demo task.

use emg_control::Task;
use emg_kinematics::{JointVector, Robot};

/// The shipped FR3 with the pen, read from the workspace's `data/`.
pub(crate) fn fr3() -> Robot {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data");
    Robot::from_chain_file(data.join("robots/fr3_pen.urdf")).expect("the FR3 loads")
}

/// `robot`'s demo task (`crate::demo_task`) and the configuration it starts from.
pub(crate) fn demo(robot: &Robot) -> (Task, JointVector) {
    let task = crate::demo_task(robot).expect("the demo task");
    let q = task.q0_seed.expect("the demo task has its configuration");
    (task, q)
}
