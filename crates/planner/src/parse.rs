//! Small value parsers shared by the seed sources and the binaries' arguments.

/// Parses exactly `N` comma-separated finite numbers (`x,y,z`, `v1,...,v7`).
pub fn numbers<const N: usize>(s: &str) -> Result<[f64; N], String> {
    let values = s
        .split(',')
        .map(|v| {
            let v = v.trim();
            match v.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(format!("'{v}' is not a finite number")),
            }
        })
        .collect::<Result<Vec<f64>, String>>()?;
    let count = values.len();
    values
        .try_into()
        .map_err(|_| format!("expected {N} comma-separated numbers, got {count}"))
}
