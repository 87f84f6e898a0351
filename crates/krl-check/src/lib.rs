//! An independent reader of the KRL programs written for the KUKA KR 16-2 (`emg job --export
//! krl`: a `.src` file and its `.dat`), checked against the job's plan they were written from.
//!
//! It parses both files ([`parse_src`], [`parse_dat`]), solves every Cartesian target with the
//! arm's own closed-form inverse kinematics (`rs-opw-kinematics` from KUKA's published
//! dimensions, [`Kr16`] on `emg_program_check::OpwArm`) and picks the solution its Status and
//! Turn name by KUKA's definition, computed here from that geometry; it runs the statements as
//! the controller does (KRL's `REAL`s in single precision; `LIN` on straight lines keeping the
//! Status the arm stands in, each `C_DIS` corner's path inside the triangle of the points where
//! the TCP enters and leaves the approximation distance and the target, taken as the parabola
//! tangent to both lines there, bounded by `$APO.CDIS` and by half of each neighbouring line;
//! `PTP` linear in joint space to an exact stop; `$OUT`, `WAIT SEC` and `PTP` stopping the
//! advance run); and checks what the arm does against the plan with the independent checker
//! (`emg_verify`): every target a configuration of the plan, the joint limits, self-collision
//! and the part along every move, the tolerance and the cone while the tool is on, the tool
//! switched on where each stroke part starts and off where it ends, and the coverage the plan
//! claims ([`read_krl`]).
//!
//! **Invariant:** the reader shares no code with the writer (`emg_job::krl_program`, its
//! targets and its Status and Turn): the plan's data types, the checker and the readers' shared
//! controller (`emg_program_check`) are all it reads besides the program, so a writer's mistake
//! cannot cancel out in its reading.

mod arm;
mod parse;
mod read;

pub use arm::{Kr16, StatusTurn, kr16_parameters, kuka_pose, ros_frame};
pub use emg_program_check::{Drawn, Pose, ReadError};
pub use parse::{Action, DataList, Declaration, Motion, Program, Statement, parse_dat, parse_src};
pub use read::{KrlReport, MIN_TARGET_SPACING_M, read_krl};
