//! Stopping cleanly on SIGINT or SIGTERM: the signal is recorded; `emg plan` finishes the task
//! being planned, writes its files whole and starts no further task; `emg job` and `emg place`
//! stop their job between strokes (or places) and write nothing. Without this a signal could
//! end the process between writing a file's `.partial` sibling and renaming it.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use anyhow::{Context, Result};
use signal_hook::consts::{SIGINT, SIGTERM};

/// The signals the commands stop on.
const SIGNALS: [(i32, &str); 2] = [(SIGINT, "SIGINT"), (SIGTERM, "SIGTERM")];

/// Records SIGINT and SIGTERM instead of letting them end the process.
pub struct Interrupt(Arc<AtomicUsize>);

impl Interrupt {
    /// Installs the handlers; from now on the first of these signals only sets a flag, and a
    /// second one ends the process at once (with 128 + its number), for a stage that does not
    /// stop soon enough.
    pub fn install() -> Result<Self> {
        let received = Arc::new(AtomicUsize::new(0));
        let stopping = Arc::new(AtomicBool::new(false));
        for (signal, name) in SIGNALS {
            let value = usize::try_from(signal).context("signal numbers are positive")?;
            // Handlers run in the order they were registered: the shutdown sees the flag the
            // earlier signal set.
            signal_hook::flag::register_conditional_shutdown(
                signal,
                128 + signal,
                Arc::clone(&stopping),
            )
            .and_then(|_| signal_hook::flag::register(signal, Arc::clone(&stopping)))
            .and_then(|_| signal_hook::flag::register_usize(signal, Arc::clone(&received), value))
            .with_context(|| format!("cannot install the {name} handler"))?;
        }
        Ok(Self(received))
    }

    /// The signal received since [`Interrupt::install`], if any.
    pub fn received(&self) -> Option<Interrupted> {
        let number = self.0.load(Ordering::SeqCst);
        SIGNALS
            .iter()
            .find(|(signal, _)| usize::try_from(*signal) == Ok(number))
            .map(|&(signal, name)| Interrupted { signal, name })
    }
}

/// The error a run stopped by a signal ends with; the process exits with 128 + the signal's
/// number, as a shell reports a process the signal ended.
#[derive(Debug, thiserror::Error)]
#[error("stopped by {name}")]
pub struct Interrupted {
    signal: i32,
    name: &'static str,
}

impl Interrupted {
    /// The exit status: 128 + the signal number (130 for SIGINT, 143 for SIGTERM).
    pub fn exit_code(&self) -> u8 {
        u8::try_from(128 + self.signal).unwrap_or(u8::MAX)
    }
}

/// A long job watched from the terminal: its stages on a progress bar, stopped by a signal
/// [`Interrupt`] recorded.
pub struct Watched<'a> {
    bar: indicatif::ProgressBar,
    interrupt: &'a Interrupt,
}

impl<'a> Watched<'a> {
    /// Shows the job's stages on `bar`, asks it to stop once `interrupt` records a signal.
    pub fn new(bar: indicatif::ProgressBar, interrupt: &'a Interrupt) -> Self {
        Self { bar, interrupt }
    }

    /// Clears the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }

    /// What the job watched came to: its value, the bar cleared; its error; or, where it stopped
    /// on request (an error `is_stop` tells), the error of [`Watched::stopped`].
    pub fn outcome<T, E>(&self, result: Result<T, E>, is_stop: impl Fn(&E) -> bool) -> Result<T>
    where
        E: std::error::Error + Send + Sync + 'static,
    {
        match result {
            Err(e) if is_stop(&e) => Err(self.stopped()),
            result => {
                let value = result?;
                self.finish();
                Ok(value)
            }
        }
    }

    /// The error a job stopped on request ends with: the signal received, and that nothing was
    /// written.
    pub fn stopped(&self) -> anyhow::Error {
        self.finish();
        match self.interrupt.received() {
            Some(stop) => anyhow::Error::new(stop).context("nothing was written"),
            None => anyhow::anyhow!("the job stopped before it finished; nothing was written"),
        }
    }
}

impl emg_job::Watch for Watched<'_> {
    fn progress(&self, stage: &str, done: usize, total: usize) {
        // The unit and the counts first: the bar redraws on each change.
        self.bar.set_prefix(match stage {
            "planning" => "mm",
            "screen" | "refine" | "certify" => "places",
            _ => "strokes",
        });
        self.bar.set_length(total as u64);
        self.bar.set_position(done as u64);
        self.bar.set_message(stage.to_string());
    }

    fn stop_requested(&self) -> bool {
        self.interrupt.received().is_some()
    }
}
