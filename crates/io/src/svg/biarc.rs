//! Fitting a cubic Bézier with biarcs: pairs of tangent circular arcs within a tolerance.
//!
//! The curve is cut at its inflections, then each part is fitted with one biarc that leaves
//! and arrives along the given tangents; a part the biarc misses by more than the tolerance is
//! halved and each half fitted again. The tolerance is checked both ways: the curve at
//! [`CURVE_SAMPLES`] parameters against the biarc, and each arc at [`PIECE_SAMPLES`] points
//! against the curve (a polyline of [`POLYLINE_SEGMENTS`] chords, whose own sag only makes the
//! check stricter). A part that is straight within the tolerance, and leaves and arrives along
//! its chord, is one line.

use std::f64::consts::PI;

use super::bezier::{Cubic, V2};
use super::piece::{Piece, STRAIGHT_RAD, biarc, distance_to, segment_distance};

/// Parameters at which the curve is measured against its biarc.
pub(crate) const CURVE_SAMPLES: usize = 32;

/// Points at which each arc is measured against the curve.
pub(crate) const PIECE_SAMPLES: usize = 16;

/// Chords of the polyline that stands for the curve when arcs are measured against it.
const POLYLINE_SEGMENTS: usize = 64;

/// Halvings after which a part is taken as it fits.
const MAX_DEPTH: u32 = 24;

/// Parts whose control polygon is shorter than this many shortest pieces are not halved (nor
/// cut at an inflection): their halves' arcs would be too short to keep.
pub(crate) const UNSPLIT_PIECES: f64 = 8.0;

/// Appends to `out` the lines and arcs that follow `curve` within `tolerance`, leaving along
/// the unit `start_tangent` and arriving along the unit `end_tangent` (the curve's own, or a
/// neighbour's where the two meet smoothly), none shorter than `shortest` where the curve
/// allows. A part shorter than [`UNSPLIT_PIECES`] `× shortest` is not halved further: it takes
/// its biarc (or its chord) as it is.
pub(crate) fn fit_cubic(
    curve: &Cubic,
    start_tangent: V2,
    end_tangent: V2,
    tolerance: f64,
    shortest: f64,
    out: &mut Vec<Piece>,
) {
    let fit = Fit {
        tolerance,
        shortest,
        unsplit: UNSPLIT_PIECES * shortest,
    };
    let mut rest = *curve;
    let mut tangent = start_tangent;
    let mut consumed = 0.0;
    for t in curve.inflections() {
        // The parameter of the inflection within what is left of the curve.
        let local = (t - consumed) / (1.0 - consumed);
        let (part, after, joint) = rest.split(local);
        let Some(joint) = joint else {
            continue;
        };
        if part.hull_length() < fit.unsplit || after.hull_length() < fit.unsplit {
            continue;
        }
        fit.part(&part, tangent, joint, 0, out);
        rest = after;
        tangent = joint;
        consumed = t;
    }
    fit.part(&rest, tangent, end_tangent, 0, out);
}

/// What a fit aims at.
struct Fit {
    /// Largest distance between curve and pieces.
    tolerance: f64,
    /// Shortest piece wanted.
    shortest: f64,
    /// Control polygon length below which a part is not split.
    unsplit: f64,
}

impl Fit {
    /// Fits one part (see [`fit_cubic`]), halving it `depth` times so far.
    fn part(&self, curve: &Cubic, ta: V2, tb: V2, depth: u32, out: &mut Vec<Piece>) {
        let tolerance = self.tolerance;
        let [a, _, _, b] = curve.p;
        if curve.hull_length() == 0.0 {
            return;
        }
        if is_straight(curve, ta, tb, tolerance) {
            out.push(Piece::Line { from: a, to: b });
            return;
        }
        let fitted = biarc(a, ta, b, tb).filter(|pieces| {
            pieces.iter().all(|piece| match piece {
                Piece::Arc { sweep, .. } => sweep.abs() <= PI,
                Piece::Line { .. } => true,
            })
        });
        let fits = fitted.is_some_and(|pieces| {
            pieces.iter().all(|p| p.length() >= self.shortest)
                && deviation(curve, &pieces) <= tolerance
        });
        let last_halving = depth >= MAX_DEPTH || curve.hull_length() < self.unsplit;
        if fits || last_halving {
            match fitted {
                Some(pieces) => out.extend(pieces.into_iter().filter(|p| p.length() > 0.0)),
                None if a != b => out.push(Piece::Line { from: a, to: b }),
                None => {}
            }
            return;
        }
        let (left, right, joint) = curve.split(0.5);
        // At a cusp each half leaves or arrives along its own handles.
        let (left_end, right_start) = match joint {
            Some(joint) => (joint, joint),
            None => (
                left.end_tangent().unwrap_or(ta),
                right.start_tangent().unwrap_or(tb),
            ),
        };
        self.part(&left, ta, left_end, depth + 1, out);
        self.part(&right, right_start, tb, depth + 1, out);
    }
}

/// Whether the curve is its chord within `tolerance` (its handles lie that close to the chord,
/// so the whole curve does) and leaves and arrives along it.
fn is_straight(curve: &Cubic, ta: V2, tb: V2, tolerance: f64) -> bool {
    let [a, b, c, d] = curve.p;
    let chord = d - a;
    if chord.norm() == 0.0 {
        return false;
    }
    let along = chord.normalize();
    let turn = |t: V2| libm::atan2(super::bezier::cross(&t, &along), t.dot(&along)).abs();
    turn(ta) <= STRAIGHT_RAD
        && turn(tb) <= STRAIGHT_RAD
        && segment_distance(b, a, d) <= tolerance
        && segment_distance(c, a, d) <= tolerance
}

/// How far apart the curve and the pieces lie: the largest distance of a curve sample from
/// the pieces and of a piece sample from the curve's polyline.
pub(crate) fn deviation(curve: &Cubic, pieces: &[Piece]) -> f64 {
    let curve_to_pieces = (1..=CURVE_SAMPLES)
        .map(|i| curve.point(i as f64 / (CURVE_SAMPLES + 1) as f64))
        .map(|p| distance_to(pieces, p))
        .fold(0.0, f64::max);
    let polyline: Vec<V2> = (0..=POLYLINE_SEGMENTS)
        .map(|i| curve.point(i as f64 / POLYLINE_SEGMENTS as f64))
        .collect();
    let pieces_to_curve = farthest_from_polyline(
        pieces.iter().flat_map(|piece| {
            (1..=PIECE_SAMPLES).map(move |i| piece.point(i as f64 / (PIECE_SAMPLES + 1) as f64))
        }),
        &polyline,
    );
    curve_to_pieces.max(pieces_to_curve)
}

/// The largest distance of `points` from the polyline through `polyline`'s points.
fn farthest_from_polyline(points: impl Iterator<Item = V2>, polyline: &[V2]) -> f64 {
    points
        .map(|p| {
            polyline
                .windows(2)
                .map(|w| segment_distance(p, w[0], w[1]))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pieces fitted to `curve` with its own tangents.
    fn fitted(curve: &Cubic, tolerance: f64) -> Vec<Piece> {
        let mut out = Vec::new();
        fit_cubic(
            curve,
            curve.start_tangent().unwrap(),
            curve.end_tangent().unwrap(),
            tolerance,
            1e-4,
            &mut out,
        );
        out
    }

    /// The pieces are one chain from the curve's start to its end, tangent at every joint.
    fn assert_smooth_chain(curve: &Cubic, pieces: &[Piece]) {
        assert!((pieces[0].start() - curve.p[0]).norm() < 1e-12);
        assert!((pieces.last().unwrap().end() - curve.p[3]).norm() < 1e-12);
        assert!(
            (pieces[0].start_tangent() - curve.start_tangent().unwrap()).norm() < 1e-9,
            "start tangent"
        );
        for pair in pieces.windows(2) {
            assert!((pair[0].end() - pair[1].start()).norm() < 1e-12);
            let turn = libm::acos(
                pair[0]
                    .end_tangent()
                    .dot(&pair[1].start_tangent())
                    .clamp(-1.0, 1.0),
            );
            assert!(turn < emg_control::CORNER_RAD, "a corner of {turn} rad");
        }
    }

    /// The largest distance from the curve, sampled densely, to the pieces and back.
    fn dense_deviation(curve: &Cubic, pieces: &[Piece]) -> f64 {
        let n = 2000;
        let samples: Vec<V2> = (0..=n).map(|i| curve.point(i as f64 / n as f64)).collect();
        let there = samples
            .iter()
            .map(|p| distance_to(pieces, *p))
            .fold(0.0, f64::max);
        let back = farthest_from_polyline(
            pieces
                .iter()
                .flat_map(|piece| (0..=200).map(move |i| piece.point(i as f64 / 200.0))),
            &samples,
        );
        there.max(back)
    }

    #[test]
    fn curves_are_fitted_within_the_tolerance_as_smooth_chains() {
        let curves = [
            // An arch, an S (one inflection), a loop-like hook, a quarter circle as SVG writers
            // draw it, and a hairpin bend of 4 mm radius (metres, a drawing about 0.1 m
            // across).
            Cubic::from_xy([(0.0, 0.0), (0.0, 0.05), (0.05, 0.05), (0.05, 0.0)]),
            Cubic::from_xy([(0.0, 0.0), (0.03, 0.04), (0.06, -0.04), (0.09, 0.0)]),
            Cubic::from_xy([(0.0, 0.0), (0.1, 0.1), (-0.05, 0.1), (0.02, 0.0)]),
            Cubic::from_xy([(0.1, 0.0), (0.1, 0.055228), (0.055228, 0.1), (0.0, 0.1)]),
            Cubic::from_xy([(0.0, 0.0), (0.08, 0.0), (0.08, 0.02), (0.0, 0.04)]),
        ];
        for tolerance in [5e-5, 1e-5, 1e-6] {
            for curve in &curves {
                let pieces = fitted(curve, tolerance);
                assert!(!pieces.is_empty());
                assert_smooth_chain(curve, &pieces);
                let error = dense_deviation(curve, &pieces);
                assert!(
                    error <= tolerance * 1.02,
                    "{curve:?} at {tolerance}: off by {error}"
                );
            }
        }
    }

    #[test]
    fn a_tighter_tolerance_takes_more_arcs() {
        let s = Cubic::from_xy([(0.0, 0.0), (0.03, 0.04), (0.06, -0.04), (0.09, 0.0)]);
        let coarse = fitted(&s, 1e-4).len();
        let fine = fitted(&s, 1e-6).len();
        assert!(coarse >= 4, "an S takes at least two biarcs: {coarse}");
        assert!(fine > coarse, "{fine} pieces at 1 µm, {coarse} at 0.1 mm");
    }

    #[test]
    fn a_quarter_circle_becomes_arcs_of_its_radius() {
        // The standard cubic of a quarter circle of radius 0.1 m (off the circle by 2.7e-4 r).
        let k = 0.1 * 0.552_284_749_831;
        let quarter = Cubic::from_xy([(0.1, 0.0), (0.1, k), (k, 0.1), (0.0, 0.1)]);
        let pieces = fitted(&quarter, 5e-5);
        assert!(pieces.len() <= 4, "{} pieces", pieces.len());
        for piece in &pieces {
            let Piece::Arc { centre, sweep, .. } = piece else {
                panic!("a quarter circle holds a line: {piece:?}")
            };
            assert!(*sweep > 0.0, "the quarter turns counter-clockwise");
            assert!(centre.norm() < 1e-4, "centre {centre:?}");
            assert!((piece.radius().unwrap() - 0.1).abs() < 5e-5);
        }
    }

    #[test]
    fn a_straight_curve_is_one_line_and_a_nearly_straight_one_stays_smooth() {
        let straight = Cubic::from_xy([(0.0, 0.0), (0.01, 0.0), (0.02, 0.0), (0.03, 0.0)]);
        assert_eq!(
            fitted(&straight, 5e-5),
            vec![Piece::Line {
                from: V2::new(0.0, 0.0),
                to: V2::new(0.03, 0.0)
            }]
        );
        // Bowed by 10 µm: within the tolerance, but it leaves at an angle to its chord, so it
        // becomes large arcs that keep its tangents rather than a line with corners.
        let bowed = Cubic::from_xy([(0.0, 0.0), (0.01, 1e-5), (0.02, 1e-5), (0.03, 0.0)]);
        let pieces = fitted(&bowed, 5e-5);
        assert_smooth_chain(&bowed, &pieces);
        assert!(pieces.iter().all(|p| matches!(p, Piece::Arc { .. })));
    }

    #[test]
    fn a_cusp_is_fitted_on_both_sides() {
        // Handles crossed: the curve turns back sharply (a cusp-like point near its middle).
        let cusp = Cubic::from_xy([(0.0, 0.0), (0.06, 0.04), (0.0, 0.04), (0.06, 0.0)]);
        let mut out = Vec::new();
        let (ta, tb) = (cusp.start_tangent().unwrap(), cusp.end_tangent().unwrap());
        fit_cubic(&cusp, ta, tb, 5e-5, 1e-4, &mut out);
        assert!(dense_deviation(&cusp, &out) <= 5e-5 * 1.02);
        assert!((out.last().unwrap().end() - cusp.p[3]).norm() < 1e-12);
    }
}
