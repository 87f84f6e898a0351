//! The path population: strokes a cell draws — rectangles, full circles, arcs and S-curves —
//! each starting at a task of the line population, along its direction `d` on its surface.
//!
//! Path `i` takes its shape from [`PathShape::ALL`] in turn (`i mod 4`) and its sizes and the
//! side it turns to from a random stream that depends only on the seed and `i`, so the
//! population is the same whatever the thread count. Sizes lie within the ranges below, which
//! keep a stroke within a few tenths of a metre of its start, where a 7-DoF arm of a metre's
//! reach can draw it.

use emg_kinematics::{Robot, Vec3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::path::{PATH_FORMAT_VERSION, Path, PathSpec, SegmentSpec};
use crate::task::{Task, TaskError};

/// A stroke's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PathShape {
    /// Four straight sides back to the start, `a ∈ [0.1, 0.4]` m along `d`, `b ∈ [0.05, 0.2]` m
    /// across; corners passed at rest.
    Rectangle,
    /// A full circle of radius `r ∈ [0.03, 0.12]` m, leaving its start along `d`.
    Circle,
    /// A circular arc of radius `r ∈ [0.05, 0.25]` m sweeping `[90°, 270°]`.
    Arc,
    /// Two half circles turning opposite ways, radii in `[0.04, 0.12]` m.
    SCurve,
}

impl PathShape {
    /// Every shape, in the order the population takes them.
    pub const ALL: [PathShape; 4] = [Self::Rectangle, Self::Circle, Self::Arc, Self::SCurve];

    /// The shape's name in result files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Rectangle => "rectangle",
            Self::Circle => "circle",
            Self::Arc => "arc",
            Self::SCurve => "s-curve",
        }
    }
}

/// Path `index` of the population of `seed`, starting at `anchor`'s `p0` along its `d` on its
/// surface (see the module documentation).
pub fn population_path(anchor: &Task, index: u64, seed: u64) -> (PathShape, Path) {
    let shape = PathShape::ALL[(index % PathShape::ALL.len() as u64) as usize];
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    let mut uniform = |low: f64, high: f64| low + (high - low) * rng.random::<f64>();
    let side = if uniform(0.0, 1.0) < 0.5 { 1.0 } else { -1.0 };
    let (p, d, n) = (anchor.p0, anchor.d, anchor.n);
    // Turning towards `side · e` with the start tangent `d`: a circle through `p` about
    // `p + side · r · e` leaves it along `d` when it turns by `side` about `n`.
    let e = n.cross(&d) * side;
    let line = |to: Vec3| SegmentSpec::Line { to: to.into() };
    let turn = |centre: Vec3, degrees: f64| SegmentSpec::Arc {
        centre: Some(centre.into()),
        through: None,
        to: None,
        sweep_deg: Some(degrees),
    };
    let segments = match shape {
        PathShape::Rectangle => {
            let (a, b) = (uniform(0.1, 0.4), uniform(0.05, 0.2));
            vec![
                line(p + d * a),
                line(p + d * a + e * b),
                line(p + e * b),
                line(p),
            ]
        }
        PathShape::Circle => {
            let r = uniform(0.03, 0.12);
            vec![turn(p + e * r, 360.0 * side)]
        }
        PathShape::Arc => {
            let (r, sweep) = (uniform(0.05, 0.25), uniform(90.0, 270.0));
            vec![turn(p + e * r, sweep * side)]
        }
        PathShape::SCurve => {
            let (r1, r2) = (uniform(0.04, 0.12), uniform(0.04, 0.12));
            vec![
                turn(p + e * r1, 180.0 * side),
                turn(p + e * (2.0 * r1 + r2), -180.0 * side),
            ]
        }
    };
    let spec = PathSpec {
        version: PATH_FORMAT_VERSION,
        start: p.into(),
        normal: n.into(),
        blend_radius_m: 0.0,
        segments,
    };
    let path = Path::new(spec).expect("the population's strokes are valid paths");
    (shape, path)
}

/// The path tasks of the population of `seed`, one per anchor (path `i` from `anchors[i]`,
/// keeping its generating configuration as the task's `q0_seed`).
pub fn path_tasks(
    robot: &Robot,
    anchors: &[Task],
    seed: u64,
) -> Result<Vec<(PathShape, Task)>, TaskError> {
    anchors
        .iter()
        .enumerate()
        .map(|(index, anchor)| {
            let (shape, path) = population_path(anchor, index as u64, seed);
            Ok((shape, Task::on_path(robot, path, anchor.q0_seed)?))
        })
        .collect()
}
