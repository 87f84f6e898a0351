//! `extreme_line_motion`: the Python module of extreme straight-line motion (PyO3), thin over
//! `emg-planner`, `emg-io` and `emg-verify`; no algorithm lives here.
//!
//! * [`planner::Planner`]: a robot (shipped name or robot file), its models and a configuration;
//!   `plan(p0, d, n, …)` one task, `plan_many(tasks, …)` many in parallel with the GIL released;
//! * [`planner::Plan`]: the planned motion as numpy arrays, `timed(…)` the motion timed rest to
//!   rest ([`timing::Motion`]), `save(stem, …)` writing the files `emg plan` writes, byte for
//!   byte;
//! * [`robot::Robot`]: forward kinematics and the position Jacobian;
//! * [`check::check`]: a trajectory file or a job's program verified by the independent
//!   checker, as a report;
//! * [`planner::load_tasks`]: a task file (JSON or `EMGTASKS`);
//! * [`export::export`]: a joint trajectory exported for a robot's own stack (ROS 2 MCAP,
//!   URScript).
//!
//! Errors raise [`Error`] subclasses whose messages are the library's: [`InputError`] for bad
//! input (naming the argument, field and value), [`PlanningError`] when a task cannot be
//! planned, [`CheckFailed`] when a file does not hold up; failed file writes raise `OSError`.

mod check;
mod data;
mod errors;
mod export;
mod job;
mod planner;
mod robot;
mod timing;

use pyo3::prelude::*;

use errors::{CheckFailed, Error, InputError, PlanningError};

/// Plan, check and inspect extreme straight-line motions of redundant robot arms.
#[pymodule]
fn extreme_line_motion(module: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = module.py();
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    module.add("Error", py.get_type::<Error>())?;
    module.add("InputError", py.get_type::<InputError>())?;
    module.add("PlanningError", py.get_type::<PlanningError>())?;
    module.add("CheckFailed", py.get_type::<CheckFailed>())?;
    module.add_class::<planner::Planner>()?;
    module.add_class::<job::JobPlan>()?;
    module.add_class::<job::JobPlacement>()?;
    module.add_class::<planner::Plan>()?;
    module.add_class::<planner::Task>()?;
    module.add_class::<timing::Motion>()?;
    module.add_class::<robot::Robot>()?;
    module.add_class::<check::CheckReport>()?;
    module.add_class::<check::JobCheckReport>()?;
    module.add_function(wrap_pyfunction!(planner::load_tasks, module)?)?;
    module.add_function(wrap_pyfunction!(check::check, module)?)?;
    module.add_class::<export::ExportReport>()?;
    module.add_function(wrap_pyfunction!(export::export, module)?)?;
    Ok(())
}
