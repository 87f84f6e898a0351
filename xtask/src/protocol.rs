//! The evaluation protocol as the pipelines run it: `emg_eval::Setup` with progress bars, and the
//! shipped models' default paths.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::Context;
use emg_eval::{Progress, Setup};
use indicatif::ProgressBar;

use crate::{progress, workspace};

/// Progress bars for the protocol's stages, one at a time.
#[derive(Default)]
struct Bars(Mutex<Option<ProgressBar>>);

impl Progress for Bars {
    fn begin(&self, what: &str, total: usize) {
        *self.0.lock().expect("the bar lock is never poisoned") =
            Some(progress::bar(total as u64, what));
    }

    fn advance(&self) {
        if let Some(bar) = &*self.0.lock().expect("the bar lock is never poisoned") {
            bar.inc(1);
        }
    }

    fn end(&self) {
        if let Some(bar) = self
            .0
            .lock()
            .expect("the bar lock is never poisoned")
            .take()
        {
            bar.finish_and_clear();
        }
    }
}

/// Loads the robot, its checker, the policy and the diffusion seeder, with progress bars.
pub fn load_setup(robot: &Path, policy: &Path, diffusion: &Path) -> anyhow::Result<Setup> {
    let setup = Setup::load(robot, policy, diffusion).context(
        "loading the protocol's setup (train the models with `cargo xtask train-diffusion` and \
         `cargo xtask train-ppo`)",
    )?;
    Ok(setup.with_progress(Box::new(Bars::default())))
}

/// Default path of the shipped policy weights.
pub fn default_policy() -> PathBuf {
    workspace::data(&format!("models/{}", emg_planner::POLICY_WEIGHTS_FILE))
}

/// Default path of the shipped diffusion weights.
pub fn default_diffusion() -> PathBuf {
    workspace::data(&format!("models/{}", emg_planner::DIFFUSION_WEIGHTS_FILE))
}
