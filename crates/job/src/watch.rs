//! What a long job tells the one who started it, and how it is asked to stop: each stage's
//! progress, and a stop request checked between units of work (a search's rollouts, a stroke,
//! a place), so that a job stops within about one unit's time and returns nothing half-done.

/// Someone watching a job: told each stage's progress, asked whether to go on.
pub trait Watch: Sync {
    /// `done` of `total` units of `stage` are finished ("ordering" counts the job's strokes,
    /// "planning" the millimetres of the strokes searched along, "connecting" the strokes drawn
    /// once those meeting end to end are merged, "reordering" them again where they are
    /// connected again in the order of least estimated pen-up time (from 0, as the order is
    /// sought), and "branches" them again where they are connected again on the branches chosen
    /// for the job; "screen", "refine" and "certify"
    /// count places).
    fn progress(&self, stage: &str, done: usize, total: usize);

    /// A stroke's searches have looked `metres` further along it (drawn, or skipped as out of
    /// reach); told after each search.
    fn searched(&self, _metres: f64) {}

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

/// The "planning" stage of a job in millimetres of its strokes: each stroke's searches counted
/// as they go, at most its length (a stroke searched again another way adds nothing more), the
/// rest counted once it is planned ([`PlanningProgress::stroke`]).
pub(crate) struct PlanningProgress<'a> {
    watch: &'a dyn Watch,
    done_mm: std::sync::atomic::AtomicUsize,
    total_mm: usize,
}

impl<'a> PlanningProgress<'a> {
    /// The stage for strokes `lengths_m` long, told to `watch` (at 0 of their length).
    pub(crate) fn new(watch: &'a dyn Watch, lengths_m: impl Iterator<Item = f64>) -> Self {
        let total_mm = lengths_m.map(millimetres).sum();
        watch.progress("planning", 0, total_mm);
        Self {
            watch,
            done_mm: 0.into(),
            total_mm,
        }
    }

    /// The watch one stroke `length_m` long is planned under; [`StrokeProgress::finish`] counts
    /// what its searches did not.
    pub(crate) fn stroke(&self, length_m: f64) -> StrokeProgress<'_, 'a> {
        StrokeProgress {
            job: self,
            left_mm: std::sync::atomic::AtomicUsize::new(millimetres(length_m)),
        }
    }

    fn add(&self, mm: usize) {
        if mm > 0 {
            let done = self
                .done_mm
                .fetch_add(mm, std::sync::atomic::Ordering::Relaxed)
                + mm;
            self.watch.progress("planning", done, self.total_mm);
        }
    }
}

/// One stroke's share of [`PlanningProgress`].
pub(crate) struct StrokeProgress<'p, 'a> {
    job: &'p PlanningProgress<'a>,
    /// Millimetres of the stroke not counted yet.
    left_mm: std::sync::atomic::AtomicUsize,
}

impl StrokeProgress<'_, '_> {
    /// Takes up to `mm` of what is left of the stroke.
    fn take(&self, mm: usize) -> usize {
        let ordering = std::sync::atomic::Ordering::Relaxed;
        let previous = self
            .left_mm
            .fetch_update(ordering, ordering, |left| Some(left - left.min(mm)))
            .unwrap_or(0);
        previous.min(mm)
    }

    /// Counts what is left of the stroke: it is planned.
    pub(crate) fn finish(&self) {
        self.job.add(self.take(usize::MAX));
    }
}

impl Watch for StrokeProgress<'_, '_> {
    fn progress(&self, stage: &str, done: usize, total: usize) {
        self.job.watch.progress(stage, done, total);
    }

    fn stop_requested(&self) -> bool {
        self.job.watch.stop_requested()
    }

    fn searched(&self, metres: f64) {
        self.job.add(self.take(millimetres(metres)));
    }
}

/// `metres` in whole millimetres (0 for nothing or less).
fn millimetres(metres: f64) -> usize {
    (metres.max(0.0) * 1e3).round() as usize
}

/// A job stopped on request before it finished: nothing of it was returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("stopped on request before the job was planned whole; nothing was kept")]
pub struct Stopped;
