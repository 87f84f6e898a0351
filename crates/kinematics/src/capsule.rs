//! The capsules of a chain, the pairs checked against each other, and the distance between
//! their axes.

use crate::vectors::Vec3;

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

/// Two capsules (indices into [`Robot::capsules`](crate::Robot::capsules)) checked against each
/// other.
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
