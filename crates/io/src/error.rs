//! The one error of every trajectory-file reader and writer: it names the field (or CSV cell)
//! and what is wrong with it.

/// A trajectory file that cannot be read or written; names the field (or CSV cell) and what is
/// wrong with it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FormatError {
    /// The text is not JSON at all (the message gives the line and column).
    #[error("not valid JSON: {0}")]
    Json(String),
    /// The content is in none of the layouts.
    #[error("not a trajectory file: {0}")]
    Unrecognised(String),
    /// A field is missing, of the wrong type or holds a wrong value.
    #[error("field '{field}' {problem}")]
    Field {
        /// Path of the field, e.g. `points[3].positions`.
        field: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The CSV header does not hold the expected columns.
    #[error("CSV header: {0}")]
    CsvHeader(String),
    /// A CSV cell (1-based line and column; the header is line 1) cannot be read.
    #[error("CSV line {line}, column {column} ('{name}'): {problem}")]
    CsvCell {
        /// 1-based line number (the header is line 1).
        line: usize,
        /// 1-based column number.
        column: usize,
        /// Column name from the header.
        name: String,
        /// What is wrong with the cell.
        problem: String,
    },
}

/// [`FormatError::Field`] of `field`.
pub(crate) fn field_error(field: impl Into<String>, problem: impl Into<String>) -> FormatError {
    FormatError::Field {
        field: field.into(),
        problem: problem.into(),
    }
}
