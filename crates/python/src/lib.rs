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
mod export;
mod job;
mod planner;
mod robot;
mod timing;

use std::path::{Path, PathBuf};

use emg_planner::DataDir;
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyOSError};
use pyo3::prelude::*;

create_exception!(
    extreme_line_motion,
    Error,
    PyException,
    "Base class of every error the package raises."
);
create_exception!(
    extreme_line_motion,
    InputError,
    Error,
    "Bad input: a robot file, model, configuration, task or option that cannot be used; the message names it and what is wrong."
);
create_exception!(
    extreme_line_motion,
    PlanningError,
    Error,
    "A valid task that cannot be planned (no seed could be prepared)."
);
create_exception!(
    extreme_line_motion,
    CheckFailed,
    Error,
    "A trajectory file that does not hold up under the independent checker; the message names the point and the constraint."
);

/// The shipped data: `$EMG_DATA` when set, else the copy compiled into the module
/// ([`emg_planner::embedded::extracted`]), so an installed wheel needs no checkout.
fn data_dir() -> PyResult<DataDir> {
    match std::env::var_os(DataDir::ENV) {
        Some(dir) if !dir.is_empty() => Ok(DataDir::new(dir)),
        _ => emg_planner::embedded::extracted().map_err(|e| {
            PyOSError::new_err(format!(
                "cannot write the shipped robots and models to the cache directory: {e} (set \
                 XDG_CACHE_HOME to a writable directory, or EMG_DATA to a copy of data/)"
            ))
        }),
    }
}

/// The robot file a `robot` argument selects: a shipped robot's name or a path.
fn robot_file(robot: &Path) -> PyResult<PathBuf> {
    Ok(data_dir()?.robot_file(&robot.to_string_lossy()))
}

/// `error` and its causes, each once, joined by `": "`.
fn message(error: &(dyn std::error::Error + 'static)) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        let cause_text = cause.to_string();
        if !text.contains(&cause_text) {
            text.push_str(": ");
            text.push_str(&cause_text);
        }
        source = cause.source();
    }
    text
}

/// An [`InputError`] saying what `context` names and why it cannot be used.
fn input_error(
    context: impl std::fmt::Display,
    error: &(dyn std::error::Error + 'static),
) -> PyErr {
    InputError::new_err(format!("{context}: {}", message(error)))
}

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
