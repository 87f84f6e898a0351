//! The one interface every null-space controller implements to plug into [`crate::rollout`].

use serde::{Deserialize, Serialize};

use crate::step::{NullAction, StepContext};

/// Which controller produced a step's command (recorded per step).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ActingController {
    /// The classical null-space controller (Eq. 3).
    Classical,
    /// A learned policy.
    Learned,
    /// A planner's search: a detour it tried (a basis direction held for a few steps).
    Search,
}

impl ActingController {
    /// Lower-case name used in files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Classical => "classical",
            Self::Learned => "learned",
            Self::Search => "search",
        }
    }
}

/// A null-space controller: given the step's state, choose the action `a ∈ [−1, 1]⁴` in the
/// basis `B(q)`; the rollout adds `a_max B a` to the shared task term `J⁺ẋ` (Eq. 2).
pub trait NullSpaceController {
    /// Called once before a rollout starts from its seed.
    fn reset(&mut self, first: &StepContext<'_>);

    /// The action for this step and which controller chose it. Values outside `[−1, 1]` are
    /// clipped by the rollout.
    fn act(&mut self, step: &StepContext<'_>) -> (NullAction, ActingController);
}
