//! A job setting out of its range: a leaf module the settings' owners share.

/// A setting out of its range, named by its field.
#[derive(Debug, thiserror::Error)]
#[error("job field 'settings.{field}' must be {allowed}, got {value}")]
pub struct InvalidSetting {
    /// The field, as the job file names it under `settings`.
    pub field: &'static str,
    /// The value given.
    pub value: f64,
    /// The allowed range.
    pub allowed: &'static str,
}
