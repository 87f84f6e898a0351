//! Capsule self-collision between bodies of the chain.

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

impl Robot {
    /// The first checked capsule pair whose clearance is below `margin` (m), if any.
    ///
    /// Allocation-free; a bounding-sphere test skips pairs that are clearly apart.
    pub fn first_collision(&self, kin: &Kinematics, margin: f64) -> Option<CollisionHit> {
        self.pairs.iter().find_map(|&pair| {
            let clearance = self.pair_clearance(kin, pair, margin)?;
            (clearance < margin).then_some(CollisionHit { pair, clearance })
        })
    }

    /// Smallest clearance (m) over all checked pairs and the pair that attains it.
    pub fn min_clearance(&self, kin: &Kinematics) -> Option<CollisionHit> {
        self.pairs
            .iter()
            .map(|&pair| CollisionHit {
                pair,
                clearance: self
                    .pair_clearance(kin, pair, f64::INFINITY)
                    .unwrap_or(f64::INFINITY),
            })
            .min_by(|a, b| a.clearance.total_cmp(&b.clearance))
    }

    /// Clearance of one pair, or `None` when bounding spheres already show it exceeds `margin`.
    fn pair_clearance(&self, kin: &Kinematics, pair: CollisionPair, margin: f64) -> Option<f64> {
        let (a, b) = (&self.capsules[pair.first], &self.capsules[pair.second]);
        let (a0, a1) = (
            kin.segment_point(a.segment, &a.start),
            kin.segment_point(a.segment, &a.end),
        );
        let (b0, b1) = (
            kin.segment_point(b.segment, &b.start),
            kin.segment_point(b.segment, &b.end),
        );
        let radii = a.radius + b.radius;
        let spheres_apart = ((a0 + a1) - (b0 + b1)).norm() * 0.5
            - 0.5 * ((a1 - a0).norm() + (b1 - b0).norm())
            - radii;
        if spheres_apart > margin {
            return None;
        }
        Some(segment_distance(&a0, &a1, &b0, &b1) - radii)
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
