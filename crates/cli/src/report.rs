//! An error as the CLI prints it: its message, then each cause the message does not already
//! quote.

use std::fmt::Write;

/// `error` and its chain of causes joined by `": "`, like `{error:#}`, except that a cause
/// whose text the message so far already holds (an error that quotes its source, such as
/// "cannot time the joint trajectory: X" with source X) is not repeated.
pub fn error_text(error: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in error.chain() {
        let cause = cause.to_string();
        if text.is_empty() {
            text = cause;
        } else if !text.contains(&cause) {
            let _ = write!(text, ": {cause}");
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, thiserror::Error)]
    #[error("the knots do not converge")]
    struct Knots;

    #[derive(Debug, thiserror::Error)]
    #[error("cannot time the joint trajectory: {0}")]
    struct Timing(#[from] Knots);

    #[test]
    fn a_cause_the_message_quotes_is_printed_once_and_others_are_appended() {
        let quoted = anyhow::Error::from(Timing(Knots)).context("task 3");
        assert_eq!(
            error_text(&quoted),
            "task 3: cannot time the joint trajectory: the knots do not converge"
        );
        let plain = anyhow::Error::from(Knots).context("cannot write x.json");
        assert_eq!(
            error_text(&plain),
            "cannot write x.json: the knots do not converge"
        );
    }
}
