//! An independent reader of the RAPID modules written for the ABB IRB 120 (`emg job --export
//! rapid`), checked against the job's plan they were written from.
//!
//! It parses the module ([`parse_module`]), solves every Cartesian target with the arm's own
//! closed-form inverse kinematics (`rs-opw-kinematics` from ABB's published dimensions,
//! [`Irb120`] on `emg_program_check::OpwArm`) and picks the solution its configuration data name by ABB's definition, computed
//! here from that geometry; it interpolates the moves as the controller does (`MoveL` on
//! straight lines with each fly-by corner's path inside the triangle of the points where the
//! TCP enters and leaves the zone and the target, taken as the parabola tangent to both lines
//! there; `MoveAbsJ` linear in joint space), each zone bounded by its `zonedata` and by half
//! of each neighbouring line; and checks what the arm does against the plan with the
//! independent checker (`emg_verify`): every target a configuration of the plan, the joint
//! limits, self-collision and the part along every move, the tolerance and the cone while the
//! tool is on, the tool switched on where each stroke part starts and off where it ends, and
//! the coverage the plan claims ([`read_rapid`]).
//!
//! **Invariant:** the reader shares no code with the writer (`emg_job::rapid_program`, its
//! targets and its configuration data): the plan's data types and the checker are all it reads
//! besides the module, so a writer's mistake cannot cancel out in its reading.

mod arm;
mod parse;
mod read;

pub use arm::{Configuration, Irb120, rapid_pose};
pub use emg_program_check::{BOUNDARY_SLACK, Drawn, Pose, REACH_SLACK_M, ReadError};
pub use parse::{Argument, Declaration, Instruction, Module, Value, parse_module};
pub use read::{MIN_TARGET_SPACING_M, RapidReport, read_rapid};
