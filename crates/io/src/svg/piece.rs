//! The pieces a stroke is made of in the drawing's plane (metres): straight lines and circular
//! arcs, with the constructions that join them tangentially.
//!
//! The plane's coordinates `(a, b)` map to the work surface along `x_axis` and `n × x_axis`, so
//! counter-clockwise in the plane (positive `sweep`) is counter-clockwise about `n`, the sign of
//! the path format's `sweep_deg`.

use std::f64::consts::PI;

use super::bezier::{V2, cross};

/// A turn (rad) at each end of an arc below which the arc is drawn as the straight line
/// between its ends: half the path format's corner threshold, so the line meets the
/// neighbours' tangents as smoothly as the arc did.
pub(crate) const STRAIGHT_RAD: f64 = emg_control::CORNER_RAD / 2.0;

/// One piece of a stroke.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Piece {
    /// A straight line.
    Line {
        /// Start.
        from: V2,
        /// End.
        to: V2,
    },
    /// A circular arc from `from` about `centre` through the signed angle `sweep` (rad,
    /// counter-clockwise positive).
    Arc {
        /// Start.
        from: V2,
        /// Centre.
        centre: V2,
        /// Signed angle swept (rad).
        sweep: f64,
    },
}

/// `v` turned counter-clockwise by `angle` (rad).
fn rotated(v: V2, angle: f64) -> V2 {
    let (sin, cos) = libm::sincos(angle);
    V2::new(cos * v.x - sin * v.y, sin * v.x + cos * v.y)
}

/// `v` turned a quarter turn counter-clockwise.
fn left(v: V2) -> V2 {
    V2::new(-v.y, v.x)
}

/// The distance from `p` to the segment from `a` to `b`.
pub(crate) fn segment_distance(p: V2, a: V2, b: V2) -> f64 {
    let ab = b - a;
    let length2 = ab.norm_squared();
    let t = if length2 > 0.0 {
        ((p - a).dot(&ab) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

impl Piece {
    /// Where the piece starts.
    pub fn start(&self) -> V2 {
        match *self {
            Piece::Line { from, .. } | Piece::Arc { from, .. } => from,
        }
    }

    /// Where the piece ends.
    pub fn end(&self) -> V2 {
        match *self {
            Piece::Line { to, .. } => to,
            Piece::Arc {
                from,
                centre,
                sweep,
            } => centre + rotated(from - centre, sweep),
        }
    }

    /// The arc's radius (`None` for a line).
    pub fn radius(&self) -> Option<f64> {
        match *self {
            Piece::Line { .. } => None,
            Piece::Arc { from, centre, .. } => Some((from - centre).norm()),
        }
    }

    /// The piece's length.
    pub fn length(&self) -> f64 {
        match *self {
            Piece::Line { from, to } => (to - from).norm(),
            Piece::Arc {
                from,
                centre,
                sweep,
            } => (from - centre).norm() * sweep.abs(),
        }
    }

    /// The point a share `f ∈ [0, 1]` of the way along.
    pub fn point(&self, f: f64) -> V2 {
        match *self {
            Piece::Line { from, to } => from + (to - from) * f,
            Piece::Arc {
                from,
                centre,
                sweep,
            } => centre + rotated(from - centre, sweep * f),
        }
    }

    /// The unit direction of travel at the start.
    pub fn start_tangent(&self) -> V2 {
        match *self {
            Piece::Line { from, to } => (to - from).normalize(),
            Piece::Arc {
                from,
                centre,
                sweep,
            } => left(from - centre).normalize() * sweep.signum(),
        }
    }

    /// The unit direction of travel at the end.
    pub fn end_tangent(&self) -> V2 {
        match *self {
            Piece::Line { from, to } => (to - from).normalize(),
            Piece::Arc { centre, sweep, .. } => {
                left(self.end() - centre).normalize() * sweep.signum()
            }
        }
    }

    /// The piece less `head` of its length at its start and `tail` at its end (`head + tail`
    /// at most its length).
    pub fn trimmed(&self, head: f64, tail: f64) -> Piece {
        match *self {
            Piece::Line { from, to } => {
                let direction = (to - from).normalize();
                Piece::Line {
                    from: from + direction * head,
                    to: to - direction * tail,
                }
            }
            Piece::Arc {
                from,
                centre,
                sweep,
            } => {
                let radius = (from - centre).norm();
                let sign = sweep.signum();
                Piece::Arc {
                    from: centre + rotated(from - centre, sign * head / radius),
                    centre,
                    sweep: sweep - sign * (head + tail) / radius,
                }
            }
        }
    }

    /// The same points travelled the other way.
    pub fn reversed(&self) -> Piece {
        match *self {
            Piece::Line { from, to } => Piece::Line { from: to, to: from },
            Piece::Arc { centre, sweep, .. } => Piece::Arc {
                from: self.end(),
                centre,
                sweep: -sweep,
            },
        }
    }

    /// The distance from `p` to the nearest point of the piece.
    pub fn distance(&self, p: V2) -> f64 {
        match *self {
            Piece::Line { from, to } => segment_distance(p, from, to),
            Piece::Arc {
                from,
                centre,
                sweep,
            } => {
                let (u, w) = (from - centre, p - centre);
                let angle = libm::atan2(cross(&u, &w), u.dot(&w)) * sweep.signum();
                if angle.rem_euclid(2.0 * PI) <= sweep.abs() {
                    (w.norm() - u.norm()).abs()
                } else {
                    (p - from).norm().min((p - self.end()).norm())
                }
            }
        }
    }
}

/// The distance from `p` to the nearest of `pieces`.
pub(crate) fn distance_to(pieces: &[Piece], p: V2) -> f64 {
    pieces
        .iter()
        .map(|piece| piece.distance(p))
        .fold(f64::INFINITY, f64::min)
}

/// The arc that leaves `from` along the unit `tangent` and ends at `to` (a line when it turns
/// less than [`STRAIGHT_RAD`] at its ends); `None` when `to` is `from` or lies behind it on
/// the tangent's line, where no such arc exists.
pub(crate) fn arc_from(from: V2, tangent: V2, to: V2) -> Option<Piece> {
    let chord = to - from;
    let length = chord.norm();
    if length == 0.0 || !length.is_finite() {
        return None;
    }
    // The arc turns at each end by the angle between its tangent and its chord.
    let half = libm::atan2(cross(&tangent, &chord), tangent.dot(&chord));
    if half.abs() <= STRAIGHT_RAD {
        return Some(Piece::Line { from, to });
    }
    if half.abs() >= PI - STRAIGHT_RAD {
        return None;
    }
    let signed_radius = length / (2.0 * libm::sin(half));
    Some(Piece::Arc {
        from,
        centre: from + left(tangent) * signed_radius,
        sweep: 2.0 * half,
    })
}

/// The arc that starts at `from` and arrives at `to` along the unit `tangent` (see
/// [`arc_from`]).
pub(crate) fn arc_to(from: V2, to: V2, tangent: V2) -> Option<Piece> {
    arc_from(to, -tangent, from).map(|piece| piece.reversed())
}

/// The biarc from `a` (leaving along the unit `ta`) to `b` (arriving along the unit `tb`): two
/// arcs (or lines) tangent to each other where they meet, with equal tangent lengths `d`
/// from their ends to the joint's tangent (the joint is the midpoint of `a + d ta` and
/// `b − d tb`); `None` where no such pair exists.
pub(crate) fn biarc(a: V2, ta: V2, b: V2, tb: V2) -> Option<[Piece; 2]> {
    let v = b - a;
    let t = ta + tb;
    // |v − d t|² = (2d)²: (4 − t·t) d² + 2 (v·t) d − v·v = 0, positive root in its stable form.
    let (vt, vv) = (v.dot(&t), v.dot(&v));
    let spare = (4.0 - t.dot(&t)).max(0.0);
    let denominator = vt + (vt * vt + spare * vv).sqrt();
    if vv == 0.0 || denominator <= 0.0 {
        return None;
    }
    let d = vv / denominator;
    let joint = ((a + ta * d) + (b - tb * d)) * 0.5;
    let first = arc_from(a, ta, joint)?;
    let second = arc_to(joint, b, tb)?;
    Some([first, second])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: V2, b: V2) -> bool {
        (a - b).norm() < 1e-12
    }

    #[test]
    fn an_arc_from_a_tangent_reaches_its_end_counter_clockwise() {
        // From (1, 0) heading +y to (0, 1): a quarter turn about the origin, counter-clockwise.
        let arc = arc_from(V2::new(1.0, 0.0), V2::new(0.0, 1.0), V2::new(0.0, 1.0)).unwrap();
        let Piece::Arc { centre, sweep, .. } = arc else {
            panic!("not an arc: {arc:?}")
        };
        assert!(close(centre, V2::zeros()));
        assert!((sweep - PI / 2.0).abs() < 1e-12);
        assert!(close(arc.end(), V2::new(0.0, 1.0)));
        assert!(close(arc.end_tangent(), V2::new(-1.0, 0.0)));
        assert!((arc.length() - PI / 2.0).abs() < 1e-12);
        assert!(close(arc.point(0.5), V2::new(0.5f64.sqrt(), 0.5f64.sqrt())));
        // Heading −y instead turns clockwise the long way round: three quarters.
        let long = arc_from(V2::new(1.0, 0.0), V2::new(0.0, -1.0), V2::new(0.0, 1.0)).unwrap();
        let Piece::Arc { sweep, .. } = long else {
            panic!("not an arc")
        };
        assert!((sweep + 1.5 * PI).abs() < 1e-12);
        // Straight ahead is a line; straight behind has no arc.
        let line = arc_from(V2::zeros(), V2::new(1.0, 0.0), V2::new(2.0, 0.0)).unwrap();
        assert!(matches!(line, Piece::Line { .. }));
        assert!(arc_from(V2::zeros(), V2::new(1.0, 0.0), V2::new(-2.0, 0.0)).is_none());
    }

    #[test]
    fn a_trimmed_piece_loses_its_lengths_at_each_end() {
        let arc = Piece::Arc {
            from: V2::new(1.0, 0.0),
            centre: V2::zeros(),
            sweep: -PI / 2.0,
        };
        let trimmed = arc.trimmed(0.1, 0.2);
        assert!((trimmed.length() - (PI / 2.0 - 0.3)).abs() < 1e-12);
        assert!(close(trimmed.start(), arc.point(0.1 / (PI / 2.0))));
        assert!(close(trimmed.end(), arc.point(1.0 - 0.2 / (PI / 2.0))));
        let line = Piece::Line {
            from: V2::zeros(),
            to: V2::new(0.0, 2.0),
        };
        let trimmed = line.trimmed(0.5, 0.25);
        assert!(close(trimmed.start(), V2::new(0.0, 0.5)));
        assert!(close(trimmed.end(), V2::new(0.0, 1.75)));
    }

    #[test]
    fn the_distance_to_an_arc_respects_its_ends() {
        let arc = Piece::Arc {
            from: V2::new(1.0, 0.0),
            centre: V2::zeros(),
            sweep: PI / 2.0,
        };
        assert!((arc.distance(V2::new(2.0, 2.0)) - (8f64.sqrt() - 1.0)).abs() < 1e-12);
        // Beyond the arc's ends the nearest point is an end: here its start.
        assert!((arc.distance(V2::new(0.0, -2.0)) - 5f64.sqrt()).abs() < 1e-12);
        let clockwise = arc.reversed();
        assert!(close(clockwise.start(), V2::new(0.0, 1.0)));
        assert!(close(clockwise.end(), V2::new(1.0, 0.0)));
        assert!((clockwise.distance(V2::new(2.0, 2.0)) - (8f64.sqrt() - 1.0)).abs() < 1e-12);
        assert!((clockwise.distance(V2::new(0.0, -2.0)) - 5f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn a_biarc_meets_both_tangents_and_is_smooth_at_its_joint() {
        let cases = [
            (V2::new(0.0, 0.0), 0.3, V2::new(3.0, 1.0), -0.7),
            (V2::new(0.0, 0.0), 1.2, V2::new(1.0, 0.0), -1.2),
            (V2::new(0.0, 0.0), 0.5, V2::new(2.0, 0.0), 0.5),
            (V2::new(0.0, 0.0), 0.0, V2::new(2.0, 0.0), 0.0),
        ];
        for (a, angle_a, b, angle_b) in cases {
            let (ta, tb) = (
                rotated(V2::new(1.0, 0.0), angle_a),
                rotated(V2::new(1.0, 0.0), angle_b),
            );
            let [first, second] = biarc(a, ta, b, tb).unwrap();
            assert!(close(first.start(), a));
            assert!(close(first.start_tangent(), ta));
            assert!((first.end() - second.start()).norm() < 1e-12);
            assert!((first.end_tangent() - second.start_tangent()).norm() < 1e-12);
            assert!(close(second.end(), b));
            assert!(close(second.end_tangent(), tb));
        }
    }
}
