//! Capsule self-collision between bodies of the chain.

use arrayvec::ArrayVec;

use crate::clearance_floor::{ClearanceFloor, clearance_floor};
use crate::fk::Kinematics;
use crate::robot::Robot;
use crate::{MAX_DOF, Vec3};

/// A capsule: the segment `start`–`end` (in its segment's frame) swept by `radius`.
#[derive(Clone, Debug, PartialEq)]
pub struct Capsule {
    /// Name of the link that carries it.
    pub link: String,
    /// Position of that link along the chain (base link = 0).
    pub chain_index: usize,
    /// Rigid segment it moves with (0 = base, `s` = after joint `s`).
    pub segment: usize,
    /// First end point of the axis segment, in the segment frame (m).
    pub start: Vec3,
    /// Second end point of the axis segment, in the segment frame (m).
    pub end: Vec3,
    /// Radius (m).
    pub radius: f64,
}

/// Two capsules (indices into [`Robot::capsules`]) checked against each other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CollisionPair {
    /// Index of the capsule nearer the base.
    pub first: usize,
    /// Index of the capsule nearer the tip.
    pub second: usize,
}

/// A pair found closer than the asked margin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollisionHit {
    /// The offending pair.
    pub pair: CollisionPair,
    /// Surface-to-surface clearance (m); negative when the capsules interpenetrate.
    pub clearance: f64,
}

#[cfg(test)]
mod tests;

/// Most capsules a robot may carry: the placed capsules of one check live on the stack.
pub const MAX_CAPSULES: usize = 64;

/// Slack (m) kept by the bounding-sphere tests and the clearance floors, far above their rounding
/// error: a pair is skipped only when it is clearly apart.
const SKIP_SLACK_M: f64 = 1e-9;

/// The centres of every capsule's bounding sphere at one configuration (one transform each).
type CapsuleCentres = ArrayVec<Vec3, MAX_CAPSULES>;

/// The checked capsule pairs between two rigid segments.
#[derive(Clone, Debug)]
struct PairGroup {
    /// The two segments.
    segments: (usize, usize),
    /// Indices into [`Robot::collision_pairs`], ascending.
    pairs: Vec<usize>,
    /// The certified floor of the pairs' clearance wherever the joints between the two segments
    /// are within their limits ([`clearance_floor`]); `−∞` until the robot is loaded, and for
    /// segments too many joints apart.
    floor: ClearanceFloor,
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
    capsule_centres: Vec<Vec3>,
    /// Radius of each capsule's bounding sphere (half its axis length plus its radius).
    capsule_radii: Vec<f64>,
    /// Centre, in its segment's frame, of each segment's sphere (unused for segments without
    /// capsules).
    segment_centres: [Vec3; MAX_DOF + 1],
    /// Radius of each segment's sphere (0 for segments without capsules).
    segment_radii: [f64; MAX_DOF + 1],
    /// The checked pairs grouped by segment pair.
    groups: Vec<PairGroup>,
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

    /// The centre of each segment's sphere at `kin` (segments without capsules included: no
    /// group refers to them).
    fn segment_centres(&self, kin: &Kinematics) -> [Vec3; MAX_DOF + 1] {
        std::array::from_fn(|s| kin.segment_point(s, &self.segment_centres[s]))
    }
}

/// Whether two spheres (centres `a`, `b`, radii summing to `reach`) may be less than
/// `threshold` apart (compared squared: no square root). `false` proves that everything inside
/// them is more than `threshold` apart.
#[inline]
fn spheres_within(a: &Vec3, b: &Vec3, reach: f64, threshold: f64) -> bool {
    let limit = reach + threshold + SKIP_SLACK_M;
    !(limit > 0.0 && (a - b).norm_squared() > limit * limit)
}

impl Robot {
    /// This robot with the clearance floor of each of its segment pairs searched
    /// ([`clearance_floor`]); the last step of loading a robot.
    pub(crate) fn with_clearance_floors(mut self) -> Self {
        let floors: Vec<ClearanceFloor> = self
            .broad_phase
            .groups
            .iter()
            .map(|group| {
                let pairs: Vec<CollisionPair> =
                    group.pairs.iter().map(|&index| self.pairs[index]).collect();
                clearance_floor(&self, group.segments, &pairs)
            })
            .collect();
        for (group, floor) in self.broad_phase.groups.iter_mut().zip(floors) {
            group.floor = floor;
        }
        self
    }

    /// Whether `group`'s clearance floor proves its pairs farther apart than `margin` at `kin`:
    /// the floor clears the margin and the joints between its segments are within their
    /// limits, where the floor holds.
    #[inline]
    fn floor_clears(&self, group: &PairGroup, kin: &Kinematics, margin: f64) -> bool {
        let (a, b) = group.segments;
        let q = kin.configuration();
        group.floor.floor > margin + SKIP_SLACK_M
            && (a..b).all(|j| self.limits.lower[j] <= q[j] && q[j] <= self.limits.upper[j])
    }

    /// Places the centres of the capsules' bounding spheres at `kin` into `centres` (which
    /// must be empty).
    fn place_centres(&self, kin: &Kinematics, centres: &mut CapsuleCentres) {
        for capsule in 0..self.capsules.len() {
            // Never full: a robot carries at most MAX_CAPSULES capsules.
            let _ = centres.try_push(self.capsule_centre(kin, capsule));
        }
    }

    /// The centre of `capsule`'s bounding sphere at `kin`.
    #[inline]
    fn capsule_centre(&self, kin: &Kinematics, capsule: usize) -> Vec3 {
        kin.segment_point(
            self.capsules[capsule].segment,
            &self.broad_phase.capsule_centres[capsule],
        )
    }

    /// Whether the bounding spheres of `pair` (centred at `centres`) may be less than
    /// `threshold` apart. `false` proves the pair's clearance exceeds `threshold`.
    #[inline]
    fn capsule_spheres_within(
        &self,
        (first, second): (&Vec3, &Vec3),
        pair: CollisionPair,
        threshold: f64,
    ) -> bool {
        let radii = &self.broad_phase.capsule_radii;
        let reach = radii[pair.first] + radii[pair.second];
        spheres_within(first, second, reach, threshold)
    }

    /// Surface clearance of `pair` at `kin` (m), negative when the capsules interpenetrate.
    pub(crate) fn pair_clearance(&self, kin: &Kinematics, pair: CollisionPair) -> f64 {
        let (a, b) = (&self.capsules[pair.first], &self.capsules[pair.second]);
        let (a0, a1) = (
            kin.segment_point(a.segment, &a.start),
            kin.segment_point(a.segment, &a.end),
        );
        let (b0, b1) = (
            kin.segment_point(b.segment, &b.start),
            kin.segment_point(b.segment, &b.end),
        );
        segment_distance(&a0, &a1, &b0, &b1) - (a.radius + b.radius)
    }

    /// The first checked capsule pair (in [`Robot::collision_pairs`] order) whose clearance is
    /// below `margin` (m), if any.
    ///
    /// Allocation-free: the [`BroadPhase`] skips the segment pairs whose clearance floor clears
    /// `margin`, then the segment pairs and the capsule pairs whose bounding spheres are clearly
    /// apart, before the exact distance.
    pub fn first_collision(&self, kin: &Kinematics, margin: f64) -> Option<CollisionHit> {
        let broad_phase = &self.broad_phase;
        let segment_centres = broad_phase.segment_centres(kin);
        let mut first: Option<(usize, CollisionHit)> = None;
        for group in &broad_phase.groups {
            if self.floor_clears(group, kin, margin) {
                continue;
            }
            let (a, b) = group.segments;
            let reach = broad_phase.segment_radii[a] + broad_phase.segment_radii[b];
            if !spheres_within(&segment_centres[a], &segment_centres[b], reach, margin) {
                continue;
            }
            for &index in &group.pairs {
                if first.is_some_and(|(found, _)| found < index) {
                    break;
                }
                let pair = self.pairs[index];
                let centres = (
                    self.capsule_centre(kin, pair.first),
                    self.capsule_centre(kin, pair.second),
                );
                if !self.capsule_spheres_within((&centres.0, &centres.1), pair, margin) {
                    continue;
                }
                let clearance = self.pair_clearance(kin, pair);
                if clearance < margin {
                    first = Some((index, CollisionHit { pair, clearance }));
                    break;
                }
            }
        }
        first.map(|(_, hit)| hit)
    }

    /// Smallest clearance (m) over all checked pairs and the first pair that attains it.
    ///
    /// Allocation-free; pairs whose bounding spheres are farther apart than the smallest
    /// clearance found so far are skipped.
    pub fn min_clearance(&self, kin: &Kinematics) -> Option<CollisionHit> {
        let mut centres = CapsuleCentres::new();
        self.place_centres(kin, &mut centres);
        let mut best: Option<CollisionHit> = None;
        for &pair in &self.pairs {
            let bound = best.map_or(f64::INFINITY, |hit| hit.clearance);
            let pair_centres = (&centres[pair.first], &centres[pair.second]);
            if bound.is_finite() && !self.capsule_spheres_within(pair_centres, pair, bound) {
                continue;
            }
            let clearance = self.pair_clearance(kin, pair);
            if best.is_none_or(|hit| clearance.total_cmp(&hit.clearance).is_lt()) {
                best = Some(CollisionHit { pair, clearance });
            }
        }
        best
    }
}

/// Shortest distance between segments `p0–p1` and `q0–q1` (closest-point parameters clamped
/// to both segments; handles degenerate and parallel segments).
pub fn segment_distance(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> f64 {
    const EPS: f64 = 1e-12;
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.dot(&d1), d2.dot(&d2), d2.dot(&r));
    let (s, t) = if a <= EPS && e <= EPS {
        (0.0, 0.0)
    } else if a <= EPS {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= EPS {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            // Any s is exact for parallel segments (t is then optimal for it, and a clamped t
            // re-optimises s), so only an exactly zero denominator needs a fallback; an absolute
            // threshold here cost up to L·sinθ (~1e-6 m) on nearly parallel segments.
            let mut s = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}
