//! Stopping `emg plan` cleanly on SIGINT or SIGTERM: the signal is recorded, the task being
//! planned finishes and its files are written whole, and no further task starts. Without this a
//! signal could end the process between writing a file's `.partial` sibling and renaming it.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use anyhow::{Context, Result};
use signal_hook::consts::{SIGINT, SIGTERM};

/// The signals `emg plan` stops on.
const SIGNALS: [(i32, &str); 2] = [(SIGINT, "SIGINT"), (SIGTERM, "SIGTERM")];

/// Records SIGINT and SIGTERM instead of letting them end the process.
pub struct Interrupt(Arc<AtomicUsize>);

impl Interrupt {
    /// Installs the handlers; from now on these signals only set a flag.
    pub fn install() -> Result<Self> {
        let received = Arc::new(AtomicUsize::new(0));
        for (signal, name) in SIGNALS {
            let value = usize::try_from(signal).context("signal numbers are positive")?;
            signal_hook::flag::register_usize(signal, Arc::clone(&received), value)
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
