//! How a long evaluation reports its progress (a progress bar in the binaries).

/// Receives the progress of the protocol's stages, one stage at a time.
pub trait Progress: Sync {
    /// A stage of `total` items called `what` begins.
    fn begin(&self, what: &str, total: usize);
    /// One item of the current stage is done (called from any thread).
    fn advance(&self);
    /// The current stage is over.
    fn end(&self);
}

/// Reports nothing.
pub struct Silent;

impl Progress for Silent {
    fn begin(&self, _: &str, _: usize) {}
    fn advance(&self) {}
    fn end(&self) {}
}
