//! Capsule self-collision between bodies of the chain.

use arrayvec::ArrayVec;

use crate::Vec3;
use crate::fk::Kinematics;
use crate::robot::Robot;

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

/// Most capsules a robot may carry: the placed capsules of one check live on the stack.
pub const MAX_CAPSULES: usize = 64;

/// Slack (m) kept by the bounding-sphere tests, far above their rounding error: a pair is
/// skipped only when its spheres are clearly apart.
const SPHERE_SLACK_M: f64 = 1e-9;

/// A capsule placed at one configuration: its axis end points in the base frame and twice the
/// centre of its bounding sphere.
#[derive(Clone, Copy, Debug)]
struct PlacedCapsule {
    start: Vec3,
    end: Vec3,
    doubled_centre: Vec3,
}

/// Every capsule of the robot placed at one configuration, each transformed once.
type PlacedCapsules = ArrayVec<PlacedCapsule, MAX_CAPSULES>;

impl Robot {
    /// Places every capsule at `kin` into `placed` (cleared first).
    fn place_capsules(&self, kin: &Kinematics, placed: &mut PlacedCapsules) {
        placed.clear();
        for capsule in &self.capsules {
            let start = kin.segment_point(capsule.segment, &capsule.start);
            let end = kin.segment_point(capsule.segment, &capsule.end);
            placed.push(PlacedCapsule {
                start,
                end,
                doubled_centre: start + end,
            });
        }
    }

    /// Whether the bounding spheres of `pair` may be less than `threshold` apart (compared
    /// squared: no square root). `false` proves the pair's clearance exceeds `threshold`.
    #[inline]
    fn spheres_within(&self, placed: &PlacedCapsules, pair: CollisionPair, threshold: f64) -> bool {
        let reach = self.bounding_radii[pair.first] + self.bounding_radii[pair.second];
        let limit = 2.0 * (reach + threshold + SPHERE_SLACK_M);
        let gap = placed[pair.first].doubled_centre - placed[pair.second].doubled_centre;
        !(limit > 0.0 && gap.norm_squared() > limit * limit)
    }

    /// Surface clearance of `pair` (m), negative when the capsules interpenetrate.
    #[inline]
    fn placed_clearance(&self, placed: &PlacedCapsules, pair: CollisionPair) -> f64 {
        let (a, b) = (&placed[pair.first], &placed[pair.second]);
        let radii = self.capsules[pair.first].radius + self.capsules[pair.second].radius;
        segment_distance(&a.start, &a.end, &b.start, &b.end) - radii
    }

    /// The first checked capsule pair whose clearance is below `margin` (m), if any.
    ///
    /// Allocation-free: each capsule is placed once, and a bounding-sphere test skips the pairs
    /// that are clearly apart before the segment distance.
    pub fn first_collision(&self, kin: &Kinematics, margin: f64) -> Option<CollisionHit> {
        let mut placed = PlacedCapsules::new();
        self.place_capsules(kin, &mut placed);
        self.pairs.iter().find_map(|&pair| {
            if !self.spheres_within(&placed, pair, margin) {
                return None;
            }
            let clearance = self.placed_clearance(&placed, pair);
            (clearance < margin).then_some(CollisionHit { pair, clearance })
        })
    }

    /// Smallest clearance (m) over all checked pairs and the first pair that attains it.
    ///
    /// Allocation-free; pairs whose bounding spheres are farther apart than the smallest
    /// clearance found so far are skipped.
    pub fn min_clearance(&self, kin: &Kinematics) -> Option<CollisionHit> {
        let mut placed = PlacedCapsules::new();
        self.place_capsules(kin, &mut placed);
        let mut best: Option<CollisionHit> = None;
        for &pair in &self.pairs {
            let bound = best.map_or(f64::INFINITY, |hit| hit.clearance);
            if bound.is_finite() && !self.spheres_within(&placed, pair, bound) {
                continue;
            }
            let clearance = self.placed_clearance(&placed, pair);
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
