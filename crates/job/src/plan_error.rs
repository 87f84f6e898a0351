//! Why a job's plan cannot be written: a leaf module the stages and the placement share.

use crate::spec::JobError;
use crate::watch::Stopped;

/// Why a planned job cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum JobPlanError {
    /// No part of any stroke could be drawn with a safe move to it.
    #[error(
        "no stroke of the job can be drawn: {0} (move the drawing where the arm reaches it, or \
         change its size or normal)"
    )]
    NothingDrawn(String),
    /// The program is too long for the trajectory format.
    #[error("the program lasts longer than a joint trajectory file holds")]
    TooLong,
    /// The watcher asked the job to stop.
    #[error(transparent)]
    Stopped(#[from] Stopped),
    /// The job's corner tolerance leaves nothing of the planner's line tolerance.
    #[error(transparent)]
    Job(#[from] JobError),
}
