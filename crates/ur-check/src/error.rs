//! Why the reader refuses a program.

/// Why the reader refuses a program: the program (where several are read together), the line
/// (1-based; 0 for the program as a whole) and what failed there.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadError {
    /// The program's place (1-based) among those read together; `None` where one is read.
    pub program: Option<usize>,
    /// The line.
    pub line: usize,
    /// What failed.
    pub problem: String,
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let program = self
            .program
            .map_or(String::new(), |p| format!("program {p}, "));
        if self.line == 0 {
            write!(f, "{program}the program: {}", self.problem)
        } else {
            write!(f, "{program}line {}: {}", self.line, self.problem)
        }
    }
}

impl std::error::Error for ReadError {}

/// A [`ReadError`] at `line`.
pub(crate) fn fail<T>(line: usize, problem: impl Into<String>) -> Result<T, ReadError> {
    Err(ReadError {
        program: None,
        line,
        problem: problem.into(),
    })
}
