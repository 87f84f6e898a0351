//! What a long job tells the one who started it, and how it is asked to stop: each stage's
//! progress, and a stop request checked between units of work (a stroke, a place), so that a
//! job stops within about one unit's time and returns nothing half-done.

/// Someone watching a job: told each stage's progress, asked whether to go on.
pub trait Watch: Sync {
    /// `done` of `total` units of `stage` are finished ("ordering" counts the job's strokes,
    /// "planning" and "connecting" the strokes drawn once those meeting end to end are merged;
    /// "screen", "refine" and "certify" count places).
    fn progress(&self, stage: &str, done: usize, total: usize);

    /// Whether the job should stop now, returning [`Stopped`]; checked between units of work.
    fn stop_requested(&self) -> bool {
        false
    }
}

/// Nobody watching: no progress shown, never stopped.
#[derive(Clone, Copy, Debug, Default)]
pub struct Unwatched;

impl Watch for Unwatched {
    fn progress(&self, _stage: &str, _done: usize, _total: usize) {}
}

/// A watch that only passes on another's stop requests: a job run inside another (a place's
/// certification) stops with it without reporting its stages as the outer job's.
pub struct StopsWith<'a>(pub &'a dyn Watch);

impl Watch for StopsWith<'_> {
    fn progress(&self, _stage: &str, _done: usize, _total: usize) {}

    fn stop_requested(&self) -> bool {
        self.0.stop_requested()
    }
}

/// A job stopped on request before it finished: nothing of it was returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("stopped on request before the job was planned whole; nothing was kept")]
pub struct Stopped;
