//! Why the reader refuses a module.

/// Why the reader refuses a module: the line (1-based; 0 for the module as a whole) and what
/// failed there.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{problem}", if *.line == 0 { "the module: ".to_string() } else { format!("line {}: ", .line) })]
pub struct ReadError {
    /// The line.
    pub line: usize,
    /// What failed.
    pub problem: String,
}

impl ReadError {
    /// A refusal at `line`.
    pub fn at(line: usize, problem: impl Into<String>) -> Self {
        Self {
            line,
            problem: problem.into(),
        }
    }
}

/// A [`ReadError`] at `line`.
pub(crate) fn fail<T>(line: usize, problem: impl Into<String>) -> Result<T, ReadError> {
    Err(ReadError::at(line, problem))
}
