//! Small value parsers shared by the seed sources and the binaries' arguments, with one typed
//! error.

/// A value given as text that cannot be read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ParseError {
    /// A list entry is not a finite number.
    #[error("'{0}' is not a finite number")]
    NotFinite(String),
    /// A list has the wrong number of entries.
    #[error("expected {expected} comma-separated numbers, got {found}")]
    Count {
        /// Entries needed.
        expected: usize,
        /// Entries given.
        found: usize,
    },
    /// Not the name of a controller.
    #[error("unknown controller '{0}': use classical, rl or hybrid")]
    Controller(String),
    /// Not the name of a planner.
    #[error("unknown planner '{0}': use controller or search")]
    Planner(String),
    /// Not the name of a seed source.
    #[error(
        "unknown seed source '{0}': use dp, generating, home, q_mu, q_jl or q=v1,...,vN (radians, \
         one per joint)"
    )]
    Seed(String),
}

/// Parses one to `most` comma-separated finite numbers (`v1,...,vN`).
pub fn number_list(s: &str, most: usize) -> Result<Vec<f64>, ParseError> {
    let values = finite_numbers(s)?;
    if values.len() > most {
        return Err(ParseError::Count {
            expected: most,
            found: values.len(),
        });
    }
    Ok(values)
}

/// Every comma-separated entry of `s` as a finite number.
fn finite_numbers(s: &str) -> Result<Vec<f64>, ParseError> {
    s.split(',')
        .map(|v| {
            let v = v.trim();
            match v.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(ParseError::NotFinite(v.to_string())),
            }
        })
        .collect()
}

/// Parses exactly `N` comma-separated finite numbers (`x,y,z`).
pub fn numbers<const N: usize>(s: &str) -> Result<[f64; N], ParseError> {
    let values = finite_numbers(s)?;
    let found = values.len();
    values
        .try_into()
        .map_err(|_| ParseError::Count { expected: N, found })
}
