//! What a reader of a controller's own program checks against the job's plan, whatever the
//! program's language (`emg-ur-check` reads URScript, `emg-rapid-check` RAPID, `emg-krl-check`
//! KRL): the plan's
//! stroke parts as the checker reads them ([`PlanChecks::new`]), every configuration the arm
//! passes within the joint limits and clear of itself and the part
//! ([`PlanChecks::configuration`]), the TCP on its stroke within the tolerance and the cone while
//! the tool is on, measured from the stretch of the stroke it has reached
//! ([`PlanChecks::on_task`]), the tool switched on at each stroke part's start and off at its
//! end ([`PlanChecks::switch_on`], [`PlanChecks::switch_off`], [`PlanChecks::finish`]), and
//! the strokes covered as far as the plan draws them ([`PlanChecks::covered`]). A reader interprets its language's moves and
//! solves its arm's kinematics; each refusal here is a problem its reader puts at a line. The
//! industrial controllers' interpolation, which the RAPID and KRL readers share, is
//! [`Controller`]'s.
//!
//! **Invariant:** shares no code with the programs' writers (`emg_job::ur_program`,
//! `emg_job::rapid_program`, `emg_job::krl_program`): the plan's data types and the checker
//! are all it reads.

mod controller;
mod opw;
mod plan;

pub use controller::{
    CORNER_SAMPLES, CartesianTarget, ClosedForm, Controller, Drawn, JOINT_STEP_RAD, JointTarget,
    MAX_JOINT_JUMP_RAD, PATH_STEP_M, PlanConfigurations, Pose, ReadError, TARGET_MATCH_RAD,
    TOOL_MATCH, fail, largest_change,
};
pub use opw::{BOUNDARY_SLACK, OpwArm, REACH_SLACK_M, on_side};
pub use plan::{COVERAGE_ALLOWANCE_M, Covered, Drawing, PlanChecks, checker_joints};
