//! The hybrid controller: the switch of Eq. 8 choosing, step by step, between a learned policy and
//! the classical controller; both act through the same basis `B(q)`, so they are interchangeable.

use emg_control::{
    ActingController, ClassicalController, NullAction, NullSpaceController, StepContext, Trajectory,
};

use crate::boundary::BoundaryMeasure;
use crate::switch::{HysteresisSwitch, Regime};

/// Learned policy in the interior, classical controller in the boundary shell (Sec. 4.3).
#[derive(Clone)]
pub struct HybridController<L> {
    classical: ClassicalController,
    learned: L,
    switch: HysteresisSwitch,
    measure: BoundaryMeasure,
}

impl<L: NullSpaceController> HybridController<L> {
    /// Combines `learned` and `classical` under `switch`, comparing `measure` with its thresholds.
    pub fn new(
        learned: L,
        classical: ClassicalController,
        switch: HysteresisSwitch,
        measure: BoundaryMeasure,
    ) -> Self {
        Self {
            classical,
            learned,
            switch,
            measure,
        }
    }
}

impl<L: NullSpaceController> NullSpaceController for HybridController<L> {
    fn reset(&mut self, first: &StepContext<'_>) {
        self.switch.start(self.measure.evaluate(first));
        self.learned.reset(first);
        self.classical.reset(first);
    }

    fn act(&mut self, step: &StepContext<'_>) -> (NullAction, ActingController) {
        match self.switch.update(self.measure.evaluate(step)) {
            Regime::Learned => self.learned.act(step),
            Regime::Classical => self.classical.act(step),
        }
    }
}

/// Number of hand-overs between controllers recorded in a trajectory.
pub fn count_switches(trajectory: &Trajectory) -> usize {
    let acting: Vec<ActingController> = trajectory
        .steps
        .iter()
        .filter_map(|s| s.controller)
        .collect();
    acting.windows(2).filter(|pair| pair[0] != pair[1]).count()
}
