//! The exceptions the module raises, and the messages they carry.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
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

/// `error` and its causes, each once, joined by `": "`.
pub(crate) fn message(error: &(dyn std::error::Error + 'static)) -> String {
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
pub(crate) fn input_error(
    context: impl std::fmt::Display,
    error: &(dyn std::error::Error + 'static),
) -> PyErr {
    InputError::new_err(format!("{context}: {}", message(error)))
}
