//! Capsule self-collision between bodies of the chain.

use arrayvec::ArrayVec;

use crate::broad_phase::{ClearanceFloor, PairGroup};
use crate::capsule::{CollisionHit, CollisionPair, MAX_CAPSULES, segment_distance};
use crate::clearance_floor::clearance_floor;
use crate::fk::Kinematics;
use crate::robot::Robot;
use crate::vectors::{MAX_DOF, Vec3};

#[cfg(test)]
mod tests;

/// Slack (m) kept by the bounding-sphere tests and the clearance floors, far above their rounding
/// error: a pair is skipped only when it is clearly apart.
const SKIP_SLACK_M: f64 = 1e-9;

/// The centres of every capsule's bounding sphere at one configuration (one transform each).
type CapsuleCentres = ArrayVec<Vec3, MAX_CAPSULES>;

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

    /// The centre of each segment's sphere of the broad phase at `kin` (segments without capsules included: no
    /// group refers to them).
    fn segment_centres(&self, kin: &Kinematics) -> [Vec3; MAX_DOF + 1] {
        std::array::from_fn(|s| kin.segment_point(s, &self.broad_phase.segment_centres[s]))
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
        let segment_centres = self.segment_centres(kin);
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
