//! Certified clearance floors of segment pairs, searched once when a robot is loaded.
//!
//! The capsules of two rigid segments `a < b` move relative to each other only through the
//! joints between them (joints `a+1 ..= b`). When those are few, the smallest clearance of the
//! pair's capsules over every configuration can be bounded from below by a Lipschitz branch and
//! bound over those joints' angles. Turning joint `j` by `δ` moves no point of segment `b` by
//! more than `r_j |δ|`, where `r_j` bounds the point's distance from joint `j`'s axis, and the
//! distance between two segments changes by no more than their points move. So a clearance `c`
//! measured at the centre of a box of half-width `h` holds at least `c − h Σ_j r_j` everywhere
//! in the box. The search covers the joints' position limits, so a floor holds wherever those
//! joints are within their limits.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::broad_phase::ClearanceFloor;
use crate::capsule::CollisionPair;
use crate::robot::Robot;
use crate::vectors::{JointVector, Vec3};

/// Most joints between two segments for which a floor is searched (a cell splits into
/// `2^joints` children).
pub(crate) const MAX_FLOOR_JOINTS: usize = 2;

/// The search stops once its floor is within this of the smallest clearance it measured (m).
pub(crate) const FLOOR_TOLERANCE_M: f64 = 1e-3;

/// Most cells one search measures; a search stopped by it keeps the (lower) floor it has.
const MAX_CELLS: usize = 4096;

/// A box of joint angles (half-widths `half` about `centre`) and what it guarantees.
#[derive(Clone, Copy, Debug)]
struct Cell {
    centre: [f64; MAX_FLOOR_JOINTS],
    half: [f64; MAX_FLOOR_JOINTS],
    /// Clearance at the centre minus the most the box's angles can take from it.
    bound: f64,
    /// Order of measurement: ties of `bound` are popped first-measured first.
    index: usize,
}

impl PartialEq for Cell {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Cell {}

impl PartialOrd for Cell {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Cell {
    /// Reversed, so that the max-heap pops the lowest bound first.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .bound
            .total_cmp(&self.bound)
            .then(other.index.cmp(&self.index))
    }
}

/// The certified floor of the clearance of `pairs`, the checked capsule pairs between
/// `segments = (a, b)` (`a < b`; each pair's first capsule on `a`, its second on `b`), over
/// every position of the joints between them within their limits. Deterministic: the same
/// robot gives the same floor.
pub(crate) fn clearance_floor(
    robot: &Robot,
    (a, b): (usize, usize),
    pairs: &[CollisionPair],
) -> ClearanceFloor {
    let joints = b - a;
    if joints > MAX_FLOOR_JOINTS || pairs.is_empty() {
        return ClearanceFloor::UNSEARCHED;
    }
    // Joint index `a + k` (0-based) turns segments `a + k + 1` onwards. The last one, `b − 1`,
    // turns segment `b` about its own z axis; an earlier one turns it about an axis through
    // its own origin, from which segment `b`'s origin is at most the links between them away.
    let farthest = |distance: fn(&Vec3) -> f64| {
        pairs
            .iter()
            .flat_map(|pair| {
                let capsule = &robot.capsules[pair.second];
                [distance(&capsule.start), distance(&capsule.end)]
            })
            .fold(0.0, f64::max)
    };
    let from_axis = farthest(|p| p.xy().norm());
    let from_origin = farthest(|p| p.norm());
    // Lever and position range of each searched joint (zero past the last one).
    let levers: [f64; MAX_FLOOR_JOINTS] = std::array::from_fn(|k| {
        if k + 1 == joints {
            return from_axis;
        }
        if k >= joints {
            return 0.0;
        }
        let links: f64 = robot.joints[a + k + 1..b]
            .iter()
            .map(|joint| joint.translation.norm())
            .sum();
        links + from_origin
    });
    let limits = robot.limits();
    let range = |k: usize| {
        if k < joints {
            (limits.lower[a + k], limits.upper[a + k])
        } else {
            (0.0, 0.0)
        }
    };
    let clearance_at = |centre: &[f64; MAX_FLOOR_JOINTS]| {
        let mut q = JointVector::zeros();
        for (k, angle) in centre.iter().take(joints).enumerate() {
            q[a + k] = *angle;
        }
        let kin = robot.forward(&q);
        pairs
            .iter()
            .map(|&pair| robot.pair_clearance(&kin, pair))
            .fold(f64::INFINITY, f64::min)
    };
    let (mut measured, mut smallest_measured) = (0, f64::INFINITY);
    let measure = |centre: [f64; MAX_FLOOR_JOINTS],
                   half: [f64; MAX_FLOOR_JOINTS],
                   measured: &mut usize,
                   smallest: &mut f64| {
        let clearance = clearance_at(&centre);
        *smallest = smallest.min(clearance);
        *measured += 1;
        let slack: f64 = half.iter().zip(&levers).map(|(h, lever)| h * lever).sum();
        Cell {
            centre,
            half,
            bound: clearance - slack,
            index: *measured,
        }
    };
    let root = measure(
        std::array::from_fn(|k| {
            let (low, high) = range(k);
            0.5 * (low + high)
        }),
        std::array::from_fn(|k| {
            let (low, high) = range(k);
            0.5 * (high - low)
        }),
        &mut measured,
        &mut smallest_measured,
    );
    let mut cells = BinaryHeap::from([root]);
    loop {
        let cell = cells.pop().expect("a split cell leaves its children");
        if cell.bound >= smallest_measured - FLOOR_TOLERANCE_M || measured >= MAX_CELLS {
            return ClearanceFloor {
                floor: cell.bound,
                smallest_measured,
            };
        }
        let half = cell.half.map(|h| 0.5 * h);
        for corner in 0..1usize << joints {
            let mut centre = cell.centre;
            for (k, angle) in centre.iter_mut().take(joints).enumerate() {
                *angle += if corner >> k & 1 == 1 {
                    half[k]
                } else {
                    -half[k]
                };
            }
            cells.push(measure(centre, half, &mut measured, &mut smallest_measured));
        }
    }
}
