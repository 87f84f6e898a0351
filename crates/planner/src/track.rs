//! A reference motion along the line and the null-space action that follows it.
//!
//! The reachability scan (`crate::reach`) holds a valid configuration at every grid point of
//! the line; joined into chains that stay on one self-motion branch (`witness_chains`), they
//! show a motion the whole way that no greedy controller need find: the branch that survives
//! to the far end is known before the motion starts. A rollout follows such a chain: at every
//! step the action moves the configuration towards the chain's configuration one step
//! further along the line. The rollout goes through the one control step like every other,
//! and the checker re-checks it like every other.

use emg_control::{NullAction, StepContext};
use emg_kinematics::JointVector;

/// Configurations along the line, in increasing progress `s = (p − p0)·d` of the forward task.
#[derive(Clone, Debug)]
pub(crate) struct Reference {
    progress_m: Vec<f64>,
    configurations: Vec<JointVector>,
}

impl Reference {
    /// The configurations `chain`, one per point of a grid of spacing `grid_m` from `p0`.
    /// `None` when it holds fewer than two.
    pub(crate) fn along_grid(chain: &[JointVector], grid_m: f64) -> Option<Self> {
        let progress_m = (0..chain.len()).map(|k| k as f64 * grid_m).collect();
        Self::along(progress_m, chain.to_vec())
    }

    /// `configurations` at the progress `progress_m` (one each, strictly increasing). `None`
    /// when they hold fewer than two.
    pub(crate) fn along(progress_m: Vec<f64>, configurations: Vec<JointVector>) -> Option<Self> {
        debug_assert_eq!(progress_m.len(), configurations.len());
        debug_assert!(progress_m.windows(2).all(|pair| pair[0] < pair[1]));
        (configurations.len() >= 2).then_some(Self {
            progress_m,
            configurations,
        })
    }

    /// The configuration at progress `s`, linearly interpolated between its neighbours; `None`
    /// outside the covered range.
    pub(crate) fn at(&self, s: f64) -> Option<JointVector> {
        let last = self.progress_m.len() - 1;
        if !(self.progress_m[0]..=self.progress_m[last]).contains(&s) {
            return None;
        }
        let above = self.progress_m.partition_point(|&p| p < s).clamp(1, last);
        let (s0, s1) = (self.progress_m[above - 1], self.progress_m[above]);
        let t = (s - s0) / (s1 - s0);
        let (q0, q1) = (&self.configurations[above - 1], &self.configurations[above]);
        Some(q0 + (q1 - q0) * t)
    }
}

/// The action that steers the step at `step` towards `target`, the configuration the motion
/// should reach one step later: the null-space coordinates of the joint velocity that reaches
/// `target` in one control period, less the task command's own part `J⁺ẋ` (Eq. 2), clipped
/// like every controller's.
pub(crate) fn tracking_action(step: &StepContext<'_>, target: &JointVector) -> NullAction {
    let wanted = (target - step.q) / step.config.dt_s;
    let secondary = wanted - step.pseudo_inverse.matrix * step.task_velocity();
    step.action_from_secondary(&secondary)
}

/// The progress `step` is commanded to make in one control period (m).
pub(crate) fn progress_per_step(step: &StepContext<'_>) -> f64 {
    step.config.speed_m_per_s * step.config.dt_s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{demo, fr3};
    use emg_control::RolloutConfig;

    #[test]
    fn a_reference_interpolates_between_its_grid_points_and_nowhere_else() {
        let (a, b) = (JointVector::zeros(), JointVector::repeat(1.0));
        let reference = Reference::along_grid(&[a, b, a], 0.01).expect("three points");
        assert_eq!(reference.at(0.0), Some(a));
        let between = reference.at(0.0025).expect("inside");
        assert!((between - JointVector::repeat(0.25)).amax() < 1e-12);
        assert!((reference.at(0.015).expect("inside") - JointVector::repeat(0.5)).amax() < 1e-12);
        assert_eq!(reference.at(0.02), Some(a));
        assert_eq!(reference.at(-1e-9), None);
        assert_eq!(reference.at(0.0201), None);
        assert!(Reference::along_grid(&[a], 0.01).is_none());
    }

    #[test]
    fn the_tracking_action_recovers_the_action_that_reaches_the_target() {
        let robot = fr3();
        let (task, q) = demo(&robot);
        let config = RolloutConfig::default();
        let step = StepContext::new(
            &robot,
            &task,
            &config,
            0,
            robot.forward(&q),
            NullAction::zeros(),
        );
        assert_eq!(progress_per_step(&step), 0.2 * 0.05);
        // The configuration one step of `action` reaches, as the rollout integrates it (Eq. 2).
        let action = NullAction::new(0.3, -0.7, 0.1, 0.9);
        let target = q + step.joint_velocity(&action) * config.dt_s;
        let tracked = tracking_action(&step, &target);
        assert!(
            (tracked - action).amax() < 1e-9,
            "{tracked} against {action}"
        );
        // A target out of reach in one step saturates the action.
        let far = q + step.basis.columns.column(0) * 10.0;
        assert_eq!(tracking_action(&step, &far)[0], 1.0);
    }
}
