//! A stroke drawn in a direction: what an order is a sequence of.

use emg_control::Path;
use serde::{Deserialize, Serialize};

/// A stroke drawn in a direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Oriented {
    /// The stroke's index: among the drawn strokes ([`Ordering::drawn`]) in an ordering's
    /// sequence, among the job's in a [`Chain`].
    pub stroke: usize,
    /// Whether it is drawn from its end to its start.
    pub reversed: bool,
}

impl Oriented {
    /// The stroke as drawn, from `strokes` (the list it indexes): reversed where it is drawn
    /// from its end (only reversible strokes are, [`order_strokes`]).
    pub fn path(&self, strokes: &[Path]) -> Path {
        let stroke = &strokes[self.stroke];
        if self.reversed {
            stroke
                .reversed()
                .expect("only reversible strokes are reversed")
        } else {
            stroke.clone()
        }
    }
}
