//! A joint polyline with its corners rounded: the path a blended move follows.

use emg_kinematics::JointVector;

use crate::dynamics::TimedSample;
use crate::profile::SmoothedProfile;
use crate::sampling::{at_rest, push_samples};

/// Largest turn (degrees) at a vertex that a blend rounds: a sharper corner (the path nearly
/// turning back) gives no blended move.
pub const MAX_BLEND_TURN_DEG: f64 = 170.0;

/// One piece of a blended path, parameterised by its joint-space arc length from 0.
#[derive(Clone, Debug)]
pub(crate) enum Piece {
    /// `from + direction·s`.
    Line {
        from: JointVector,
        direction: JointVector,
        length: f64,
    },
    /// The quintic from `from` (leaving along `incoming`) to `to` (arriving along `outgoing`)
    /// with no second derivative at either end, parameterised by `s = t·length`, `t ∈ [0, 1]`:
    /// its first and second derivatives by `s` meet the lines' (unit, zero) at both ends, so the
    /// path's curvature is continuous and a motion along it has finite jerk.
    Blend {
        from: JointVector,
        to: JointVector,
        incoming: JointVector,
        outgoing: JointVector,
        length: f64,
    },
}

impl Piece {
    pub(crate) fn length(&self) -> f64 {
        match self {
            Self::Line { length, .. } => *length,
            Self::Blend { length, .. } => *length,
        }
    }

    /// The point, its first and its second derivative by arc length at `s`.
    pub(crate) fn eval(&self, s: f64) -> (JointVector, JointVector, JointVector) {
        match self {
            Self::Line {
                from, direction, ..
            } => (from + direction * s, *direction, JointVector::zeros()),
            Self::Blend {
                from,
                to,
                incoming,
                outgoing,
                length,
            } => {
                // Quintic Hermite basis (end accelerations zero): weights of `from`, of the
                // incoming velocity `length·incoming`, of the outgoing one and of `to`, with
                // their first and second derivatives by `t`.
                let t = s / length;
                let (t2, t3, t4, t5) = (t * t, t * t * t, t * t * t * t, t * t * t * t * t);
                let h = [
                    1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5,
                    t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5,
                    -4.0 * t3 + 7.0 * t4 - 3.0 * t5,
                    10.0 * t3 - 15.0 * t4 + 6.0 * t5,
                ];
                let dh = [
                    -30.0 * t2 + 60.0 * t3 - 30.0 * t4,
                    1.0 - 18.0 * t2 + 32.0 * t3 - 15.0 * t4,
                    -12.0 * t2 + 28.0 * t3 - 15.0 * t4,
                    30.0 * t2 - 60.0 * t3 + 30.0 * t4,
                ];
                let ddh = [
                    -60.0 * t + 180.0 * t2 - 120.0 * t3,
                    -36.0 * t + 96.0 * t2 - 60.0 * t3,
                    -24.0 * t + 84.0 * t2 - 60.0 * t3,
                    60.0 * t - 180.0 * t2 + 120.0 * t3,
                ];
                let (vin, vout) = (incoming * *length, outgoing * *length);
                let combine = |w: &[f64; 4]| from * w[0] + vin * w[1] + vout * w[2] + to * w[3];
                (
                    combine(&h),
                    combine(&dh) / *length,
                    combine(&ddh) / (length * length),
                )
            }
        }
    }
}

/// The polyline `vertices` with its corners rounded, each arc starting `share` of the shorter
/// of its two edges before its vertex; `None` where a corner turns by more than
/// [`MAX_BLEND_TURN_DEG`].
fn blended_pieces(vertices: &[JointVector], share: f64) -> Option<Vec<Piece>> {
    let mut points: Vec<JointVector> = Vec::with_capacity(vertices.len());
    for v in vertices {
        if points.last().is_none_or(|last| (v - last).norm() > 1e-9) {
            points.push(*v);
        }
    }
    let edges: Vec<(JointVector, f64)> = points
        .windows(2)
        .map(|pair| {
            let chord = pair[1] - pair[0];
            (chord / chord.norm(), chord.norm())
        })
        .collect();
    // Each inner vertex's blend: how far before it the arc starts, and the arc.
    let mut cut = vec![0.0; points.len()];
    let mut arcs: Vec<Option<Piece>> = vec![None; points.len()];
    for k in 1..points.len().saturating_sub(1) {
        let (incoming, before) = edges[k - 1];
        let (outgoing, after) = edges[k];
        let turn = libm::acos(incoming.dot(&outgoing).clamp(-1.0, 1.0));
        if turn.to_degrees() > MAX_BLEND_TURN_DEG {
            return None;
        }
        if turn < 1e-6 {
            continue;
        }
        let distance = share * before.min(after);
        cut[k] = distance;
        arcs[k] = Some(Piece::Blend {
            from: points[k] - incoming * distance,
            to: points[k] + outgoing * distance,
            incoming,
            outgoing,
            length: 2.0 * distance,
        });
    }
    let mut pieces = Vec::new();
    for (k, &(direction, length)) in edges.iter().enumerate() {
        let straight = length - cut[k] - cut[k + 1];
        if straight > 1e-12 {
            pieces.push(Piece::Line {
                from: points[k] + direction * cut[k],
                direction,
                length: straight,
            });
        }
        if let Some(arc) = arcs[k + 1].take() {
            pieces.push(arc);
        }
    }
    Some(pieces)
}

/// A polyline with its corners rounded, parameterised by its joint-space arc length from 0.
pub(crate) struct BlendedPath {
    /// Its pieces in order.
    pub(crate) pieces: Vec<Piece>,
    /// Where each piece starts.
    pub(crate) starts: Vec<f64>,
    /// The polyline's first and last vertex.
    ends: [JointVector; 2],
}

impl BlendedPath {
    /// The polyline `vertices` with its corners rounded, each arc starting `share` (at most ½)
    /// of the shorter of its two edges before its vertex; `None` where a corner turns by more
    /// than [`MAX_BLEND_TURN_DEG`] or the polyline has no length.
    pub(crate) fn new(vertices: &[JointVector], share: f64) -> Option<Self> {
        let pieces = blended_pieces(vertices, share.clamp(0.0, 0.5))?;
        let mut at = 0.0;
        let starts = pieces
            .iter()
            .map(|piece| {
                let start = at;
                at += piece.length();
                start
            })
            .collect();
        let ends = [*vertices.first()?, *vertices.last()?];
        (!pieces.is_empty()).then_some(Self {
            pieces,
            starts,
            ends,
        })
    }

    /// The point, its first and its second derivative by arc length at `s`.
    fn eval(&self, s: f64) -> (JointVector, JointVector, JointVector) {
        let index = self.starts.partition_point(|start| *start <= s).max(1) - 1;
        self.pieces[index].eval(s - self.starts[index])
    }

    /// The samples at `rate_hz` of the motion along the path by `profile`, from rest at the
    /// first vertex to rest at the last.
    pub(crate) fn samples(&self, profile: &SmoothedProfile, rate_hz: f64) -> Vec<TimedSample> {
        let [first, end] = self.ends;
        let mut samples = vec![at_rest(first)];
        push_samples(profile, rate_hz, 0, &end, &mut samples, |s| self.eval(s));
        samples
    }
}
