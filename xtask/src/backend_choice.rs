//! `--backend` of the training commands: the Burn backends a run can use.

use emg_learning::Backend;

/// The Burn backends `--backend` accepts.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum BackendChoice {
    /// Burn's pure-Rust flex backend.
    Flex,
    /// Burn's ndarray backend.
    Ndarray,
}

impl From<BackendChoice> for Backend {
    fn from(choice: BackendChoice) -> Self {
        match choice {
            BackendChoice::Flex => Backend::Flex,
            BackendChoice::Ndarray => Backend::Ndarray,
        }
    }
}
