//! The learned null-space controller: the exported policy plugged into the shared rollout.

use emg_control::{ActingController, NullAction, NullSpaceController, StepContext};

use crate::inference::{PlainPolicy, PolicyScratch};
use crate::observation::{OBSERVATION_DIM, observe};
use crate::weights::PolicyWeights;

/// Acts with the deterministic action `tanh(μ(o))` of a trained policy (SPEC §5), computed by
/// the allocation-free plain-Rust forward.
#[derive(Clone, Debug)]
pub struct RlController {
    policy: PlainPolicy,
    scratch: PolicyScratch,
    observation: [f32; OBSERVATION_DIM],
}

impl RlController {
    /// A controller running `weights`.
    pub fn new(weights: &PolicyWeights) -> Self {
        Self::from_policy(PlainPolicy::new(weights))
    }

    /// A controller running an already built policy.
    pub fn from_policy(policy: PlainPolicy) -> Self {
        Self {
            scratch: policy.scratch(),
            policy,
            observation: [0.0; OBSERVATION_DIM],
        }
    }
}

impl NullSpaceController for RlController {
    fn reset(&mut self, _first: &StepContext<'_>) {}

    fn act(&mut self, step: &StepContext<'_>) -> (NullAction, ActingController) {
        observe(step, &mut self.observation);
        let action = self
            .policy
            .actor(&self.observation, &mut self.scratch)
            .deterministic_action();
        (
            NullAction::from_fn(|i, _| f64::from(action[i])),
            ActingController::Learned,
        )
    }
}
