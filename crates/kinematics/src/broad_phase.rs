//! The broad phase of the self-collision test as loading a robot fixes it: bounding spheres
//! and the clearance floors of segment pairs.

use crate::capsule::{Capsule, CollisionPair};
use crate::vectors::{MAX_DOF, Vec3};

/// The outcome of one floor search (`crate::clearance_floor`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ClearanceFloor {
    /// No configuration brings the pairs closer than this (m); `−∞` when not searched.
    pub(crate) floor: f64,
    /// The smallest clearance measured on the way (m): a configuration attains it, so the floor
    /// is never above it.
    pub(crate) smallest_measured: f64,
}

impl ClearanceFloor {
    /// The floor of segment pairs with too many joints between them to search.
    pub(crate) const UNSEARCHED: Self = Self {
        floor: f64::NEG_INFINITY,
        smallest_measured: f64::INFINITY,
    };
}

/// The checked capsule pairs between two rigid segments.
#[derive(Clone, Debug)]
pub(crate) struct PairGroup {
    /// The two segments.
    pub(crate) segments: (usize, usize),
    /// Indices into [`Robot::collision_pairs`](crate::Robot::collision_pairs), ascending.
    pub(crate) pairs: Vec<usize>,
    /// The certified floor of the pairs' clearance wherever the joints between the two segments
    /// are within their limits (`crate::clearance_floor`); `−∞` until the robot is loaded, and
    /// for segments too many joints apart.
    pub(crate) floor: ClearanceFloor,
}

/// The broad phase of the self-collision test, fixed at load time: a certified clearance floor
/// per segment pair (segments one or two joints apart whose capsules never come close), one
/// bounding sphere per rigid segment enclosing its capsules, then one per capsule. A check skips
/// the segment pairs whose floor clears the margin, places the segment spheres (one transform
/// each) and tests the remaining segment pairs, then the capsule spheres of the segment pairs
/// that may touch, and transforms the axis end points only of the capsule pairs that pass every
/// test.
#[derive(Clone, Debug)]
pub(crate) struct BroadPhase {
    /// Centre of each capsule's bounding sphere (its axis midpoint), in its segment's frame.
    pub(crate) capsule_centres: Vec<Vec3>,
    /// Radius of each capsule's bounding sphere (half its axis length plus its radius).
    pub(crate) capsule_radii: Vec<f64>,
    /// Centre, in its segment's frame, of each segment's sphere (unused for segments without
    /// capsules).
    pub(crate) segment_centres: [Vec3; MAX_DOF + 1],
    /// Radius of each segment's sphere (0 for segments without capsules).
    pub(crate) segment_radii: [f64; MAX_DOF + 1],
    /// The checked pairs grouped by segment pair.
    pub(crate) groups: Vec<PairGroup>,
}

impl BroadPhase {
    /// The hierarchy of `capsules` for the checked `pairs`.
    pub(crate) fn new(capsules: &[Capsule], pairs: &[CollisionPair]) -> Self {
        let capsule_centres = capsules.iter().map(|c| (c.start + c.end) * 0.5).collect();
        let capsule_radii = capsules
            .iter()
            .map(|c| 0.5 * (c.end - c.start).norm() + c.radius)
            .collect();
        let mut segment_centres = [Vec3::zeros(); MAX_DOF + 1];
        let mut segment_radii = [0.0; MAX_DOF + 1];
        for segment in 0..=MAX_DOF {
            let members = || capsules.iter().filter(move |c| c.segment == segment);
            let Some(first) = members().next() else {
                continue;
            };
            let (mut low, mut high) = (first.start, first.start);
            for c in members() {
                for point in [c.start, c.end] {
                    low = low.inf(&point);
                    high = high.sup(&point);
                }
            }
            let centre = (low + high) * 0.5;
            segment_centres[segment] = centre;
            segment_radii[segment] = members()
                .map(|c| (c.start - centre).norm().max((c.end - centre).norm()) + c.radius)
                .fold(0.0, f64::max);
        }
        let mut groups: Vec<PairGroup> = Vec::new();
        for (index, pair) in pairs.iter().enumerate() {
            let segments = (capsules[pair.first].segment, capsules[pair.second].segment);
            match groups.iter_mut().find(|group| group.segments == segments) {
                Some(group) => group.pairs.push(index),
                None => groups.push(PairGroup {
                    segments,
                    pairs: vec![index],
                    floor: ClearanceFloor::UNSEARCHED,
                }),
            }
        }
        Self {
            capsule_centres,
            capsule_radii,
            segment_centres,
            segment_radii,
            groups,
        }
    }
}
