//! The bounding box of a drawing.

use serde::{Deserialize, Serialize};

/// The bounding box of a drawing's geometry, in its units (y downwards, as SVG draws it).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DrawingBounds {
    /// Smallest x and y.
    pub min: [f64; 2],
    /// Largest x and y.
    pub max: [f64; 2],
}

impl DrawingBounds {
    /// Extent along x.
    pub fn width(&self) -> f64 {
        self.max[0] - self.min[0]
    }

    /// Extent along y.
    pub fn height(&self) -> f64 {
        self.max[1] - self.min[1]
    }

    /// The centre: it goes to the placement's `origin_m`.
    pub fn centre(&self) -> [f64; 2] {
        [
            0.5 * (self.min[0] + self.max[0]),
            0.5 * (self.min[1] + self.max[1]),
        ]
    }
}
