//! One subpath (in the drawing's plane, metres) as a chain of lines and arcs the path format
//! accepts.
//!
//! * Straight segments stay lines; curves become biarcs within the tolerance ([`fit_cubic`]).
//! * Where two segments meet at a turn below the smooth-join threshold (drawings round their
//!   coordinates, and leave joints they mean to be smooth a few degrees off), both take one
//!   tangent (a line's, or their mean) and the curves are fitted to it within the tolerance, so
//!   the path passes there without a corner. Where two lines meet so, the corner is rounded by
//!   the arc tangent to both that leaves it by at most the tolerance, taking at most half of
//!   each line (a polyline that flattens a curve is drawn without a stop at every vertex).
//! * A `Z` adds the closing line back to the start when it is at least [`MIN_SEGMENT_M`]
//!   long; a shorter gap stays open (the stroke ends that close to its start).
//! * An arc of radius under [`MIN_SEGMENT_M`] (a dot) becomes its chord; a piece shorter than
//!   [`MIN_SEGMENT_M`] is merged with its neighbour: the two become one line or arc where that
//!   keeps both outer tangents, else one biarc between their outer ends and tangents where that
//!   stays within the tolerance of them, otherwise one arc keeping the outer tangent of the
//!   longer side (the drawing there is finer than the path format holds; the path may leave
//!   it by about the length merged).

use emg_control::MIN_SEGMENT_M;

use super::bezier::{Cubic, V2};
use super::biarc::{PIECE_SAMPLES, UNSPLIT_PIECES, fit_cubic};
use super::outline::{Segment, Subpath};
use super::piece::{Piece, STRAIGHT_RAD, arc_from, arc_to, biarc, distance_to};

/// The shortest piece or radius produced: the path format's, with a margin for rounding.
const SHORTEST: f64 = MIN_SEGMENT_M * (1.0 + 1e-6);

/// A drawn segment with the tangents it leaves and arrives along.
#[derive(Clone, Copy, Debug)]
enum Item {
    Line { from: V2, to: V2 },
    Curve { curve: Cubic, start: V2, end: V2 },
}

impl Item {
    fn start_tangent(&self) -> V2 {
        match *self {
            Item::Line { from, to } => (to - from).normalize(),
            Item::Curve { start, .. } => start,
        }
    }

    fn end_tangent(&self) -> V2 {
        match *self {
            Item::Line { from, to } => (to - from).normalize(),
            Item::Curve { end, .. } => end,
        }
    }
}

/// The largest turn (rad) between two segments made smooth at `tolerance` when the option
/// asks for `smooth_join_rad`: bending a curve's end by `φ` within the tolerance takes about
/// `4 tolerance / φ` of it, which must not fall below the shortest part the curve fitter
/// splits (0.8 mm, [`UNSPLIT_PIECES`] shortest segments), so at most `tolerance / 0.2 mm`.
pub(crate) fn smooth_join_limit(tolerance: f64, smooth_join_rad: f64) -> f64 {
    smooth_join_rad.min(4.0 * tolerance / (UNSPLIT_PIECES * MIN_SEGMENT_M))
}

/// The pieces of `subpath` (plane coordinates in metres), each at least [`MIN_SEGMENT_M`]
/// long, following it within `tolerance`, joints turning less than `smooth_join_rad` made
/// smooth (see the module documentation). Empty when nothing of it is that long; a lone piece
/// shorter than that may remain.
pub(crate) fn pieces(subpath: &Subpath, tolerance: f64, smooth_join_rad: f64) -> Vec<Piece> {
    let mut items = items(subpath);
    smooth_joints(&mut items, smooth_join_limit(tolerance, smooth_join_rad));
    let mut raw = Vec::new();
    for item in &items {
        match *item {
            Item::Line { from, to } => raw.push(Piece::Line { from, to }),
            Item::Curve { curve, start, end } => {
                fit_cubic(&curve, start, end, tolerance, SHORTEST, &mut raw)
            }
        }
    }
    // A shorter closing line would move the last piece's end by its length (merged): left
    // open, the gap is half as far from the drawing's closing line.
    if let Some(last) = raw.last()
        && subpath.closed
        && (subpath.start - last.end()).norm() >= SHORTEST
    {
        raw.push(Piece::Line {
            from: last.end(),
            to: subpath.start,
        });
    }
    let mut out: Vec<Piece> = Vec::with_capacity(raw.len());
    for piece in raw {
        out.push(without_dot(piece));
        settle(&mut out, tolerance);
    }
    filleted(&out, tolerance, smooth_join_rad)
}

/// `pieces` with every corner where two lines meet turning by less than `limit` (rad) rounded
/// by the arc tangent to both lines that leaves the corner by at most `tolerance`; each arc
/// takes at most half of each line less half the shortest piece, so the lines keep a length.
/// A corner whose arc would be shorter than the shortest piece keeps its corner.
fn filleted(pieces: &[Piece], tolerance: f64, limit: f64) -> Vec<Piece> {
    // How far each corner's arc reaches along its two lines (0 where it keeps its corner).
    let mut reach = vec![0.0; pieces.len()];
    for index in 1..pieces.len() {
        if let (Piece::Line { .. }, Piece::Line { .. }) = (pieces[index - 1], pieces[index]) {
            reach[index] = fillet_reach(&pieces[index - 1], &pieces[index], tolerance, limit);
        }
    }
    let mut out = Vec::with_capacity(pieces.len());
    for (index, piece) in pieces.iter().enumerate() {
        let Piece::Line { from, to } = *piece else {
            out.push(*piece);
            continue;
        };
        let direction = (to - from).normalize();
        let (head, tail) = (reach[index], reach.get(index + 1).copied().unwrap_or(0.0));
        if head > 0.0 {
            let previous = pieces[index - 1].start_tangent();
            let start = from - previous * head;
            out.extend(arc_from(start, previous, from + direction * head));
        }
        out.push(Piece::Line {
            from: from + direction * head,
            to: to - direction * tail,
        });
    }
    out
}

/// How far from the corner where `before` meets `after` (two lines) their rounding arc starts
/// and ends along each (see [`filleted`]); 0 when the corner is kept.
///
/// An arc of radius `r` tangent to lines turning by `θ` reaches `r tan(θ/2)` along each and
/// passes `r (1/cos(θ/2) − 1) = r 2 sin²(θ/4) / cos(θ/2)` inside the corner.
fn fillet_reach(before: &Piece, after: &Piece, tolerance: f64, limit: f64) -> f64 {
    let (a, b) = (before.end_tangent(), after.start_tangent());
    let turn = libm::acos(a.dot(&b).clamp(-1.0, 1.0));
    if turn <= emg_control::CORNER_RAD || turn >= limit {
        return 0.0;
    }
    let half = 0.5 * turn;
    let quarter_sin = libm::sin(0.5 * half);
    let within_tolerance = tolerance * libm::cos(half) / (2.0 * quarter_sin * quarter_sin);
    let room = 0.5 * (before.length().min(after.length()) - SHORTEST);
    let reach = (within_tolerance * libm::tan(half)).min(room);
    let radius = reach / libm::tan(half);
    if radius * turn < SHORTEST {
        return 0.0;
    }
    reach
}

/// The segments of `subpath` that have a length and a direction, with their own tangents.
fn items(subpath: &Subpath) -> Vec<Item> {
    let mut items = Vec::new();
    let mut at = subpath.start;
    for segment in &subpath.segments {
        match segment {
            Segment::Line(to) => {
                // Below a femtometre a line has no direction (and no length worth drawing).
                if (to - at).norm() > 1e-15 {
                    items.push(Item::Line { from: at, to: *to });
                }
            }
            Segment::Cubic(curve) => {
                let curve = Cubic {
                    p: [at, curve.p[1], curve.p[2], curve.p[3]],
                };
                if let (Some(start), Some(end)) = (curve.start_tangent(), curve.end_tangent()) {
                    items.push(Item::Curve { curve, start, end });
                }
            }
        }
        at = segment.end();
    }
    items
}

/// Gives the two sides of every joint that turns less than `limit` (rad) one tangent: a
/// line's direction where a side is a line, the mean of the two otherwise.
fn smooth_joints(items: &mut [Item], limit: f64) {
    for index in 1..items.len() {
        let (before, after) = (items[index - 1], items[index]);
        let (a, b) = (before.end_tangent(), after.start_tangent());
        let turn = libm::acos(a.dot(&b).clamp(-1.0, 1.0));
        if turn >= limit {
            continue;
        }
        let common = match (before, after) {
            (Item::Line { .. }, _) => a,
            (_, Item::Line { .. }) => b,
            _ => (a + b).normalize(),
        };
        if let Item::Curve { end, .. } = &mut items[index - 1] {
            *end = common;
        }
        if let Item::Curve { start, .. } = &mut items[index] {
            *start = common;
        }
    }
}

/// An arc of radius under the path format's shortest segment as its chord.
fn without_dot(piece: Piece) -> Piece {
    match piece.radius() {
        Some(radius) if radius < SHORTEST => Piece::Line {
            from: piece.start(),
            to: piece.end(),
        },
        _ => piece,
    }
}

fn is_short(piece: &Piece) -> bool {
    piece.length() < SHORTEST
}

/// Merges the last pieces of `out` while the last one (or a lone first one) is too short.
fn settle(out: &mut Vec<Piece>, tolerance: f64) {
    while out.len() >= 2 {
        let n = out.len();
        let (first, second) = (out[n - 2], out[n - 1]);
        if !is_short(&first) && !is_short(&second) {
            return;
        }
        out.truncate(n - 2);
        let merged = merged(&first, &second, tolerance);
        let done = merged.len() == 2;
        out.extend(merged);
        if done {
            return;
        }
    }
}

/// One or two pieces from `first`'s start to `second`'s end in place of the two (see the
/// module documentation); none when those ends meet.
fn merged(first: &Piece, second: &Piece, tolerance: f64) -> Vec<Piece> {
    let (a, ta) = (first.start(), first.start_tangent());
    let (b, tb) = (second.end(), second.end_tangent());
    if (b - a).norm() < 1e-12 {
        return Vec::new();
    }
    let old = [*first, *second];
    let one = if first.length() >= second.length() {
        arc_from(a, ta, b)
    } else {
        arc_to(a, b, tb)
    }
    .map(without_dot)
    .unwrap_or(Piece::Line { from: a, to: b });
    // One piece where it keeps both outer tangents (two lines in line, two arcs of one
    // circle), two tangent arcs otherwise.
    let turn = |u: V2, v: V2| libm::acos(u.dot(&v).clamp(-1.0, 1.0));
    if turn(one.start_tangent(), ta).max(turn(one.end_tangent(), tb)) <= STRAIGHT_RAD
        && apart(&[one], &old) <= tolerance
    {
        return vec![one];
    }
    if let Some(pair) = biarc(a, ta, b, tb)
        && pair.iter().all(|p| !is_short(p) && without_dot(*p) == *p)
        && apart(&pair, &old) <= tolerance
    {
        return pair.to_vec();
    }
    vec![one]
}

/// How far apart two chains lie, each sampled against the other.
fn apart(one: &[Piece], other: &[Piece]) -> f64 {
    let sampled = |pieces: &[Piece], against: &[Piece]| {
        pieces
            .iter()
            .flat_map(|piece| {
                (0..=PIECE_SAMPLES).map(|i| piece.point(i as f64 / PIECE_SAMPLES as f64))
            })
            .map(|p| distance_to(against, p))
            .fold(0.0, f64::max)
    };
    sampled(one, other).max(sampled(other, one))
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;

    fn subpath(start: (f64, f64), segments: Vec<Segment>, closed: bool) -> Subpath {
        Subpath {
            element: String::new(),
            start: V2::new(start.0, start.1),
            segments,
            closed,
        }
    }

    fn line(x: f64, y: f64) -> Segment {
        Segment::Line(V2::new(x, y))
    }

    fn chained(pieces: &[Piece]) -> bool {
        pieces
            .windows(2)
            .all(|w| (w[0].end() - w[1].start()).norm() < 1e-12)
    }

    #[test]
    fn a_closed_square_gets_its_closing_line_and_keeps_its_corners() {
        let square = subpath(
            (0.0, 0.0),
            vec![line(0.01, 0.0), line(0.01, 0.01), line(0.0, 0.01)],
            true,
        );
        let pieces = pieces(&square, 5e-5, 0.1);
        assert_eq!(pieces.len(), 4);
        assert!(chained(&pieces));
        assert_eq!(pieces[3].end(), V2::new(0.0, 0.0));
        // Closed already: no closing line of zero length.
        let closed = subpath(
            (0.0, 0.0),
            vec![line(0.01, 0.0), line(0.01, 0.01), line(0.0, 0.0)],
            true,
        );
        assert_eq!(super::pieces(&closed, 5e-5, 0.1).len(), 3);
        // A gap of 20 µm is too short for a closing line: it stays open.
        let nearly = subpath(
            (0.0, 0.0),
            vec![
                line(0.01, 0.0),
                line(0.01, 0.01),
                line(0.0, 0.01),
                line(0.0, 2e-5),
            ],
            true,
        );
        let pieces = super::pieces(&nearly, 5e-5, 0.1);
        assert_eq!(pieces.len(), 4);
        assert_eq!(pieces[3].end(), V2::new(0.0, 2e-5));
    }

    #[test]
    fn short_pieces_are_merged_into_a_valid_chain() {
        // A 50 µm jog between two lines, and a 30 µm line at the start.
        let jagged = subpath(
            (0.0, 0.0),
            vec![
                line(3e-5, 0.0),
                line(0.01, 0.0),
                line(0.01, 5e-5),
                line(0.02, 5e-5),
            ],
            false,
        );
        let pieces = pieces(&jagged, 5e-5, 0.1);
        assert!(chained(&pieces));
        assert!(pieces.iter().all(|p| p.length() >= MIN_SEGMENT_M));
        assert_eq!(pieces[0].start(), V2::new(0.0, 0.0));
        assert!((pieces.last().unwrap().end() - V2::new(0.02, 5e-5)).norm() < 1e-12);
        // A path shorter than the shortest segment leaves one short piece.
        let tiny = subpath((0.0, 0.0), vec![line(5e-5, 0.0)], false);
        let pieces = super::pieces(&tiny, 5e-5, 0.1);
        assert_eq!(pieces.len(), 1);
        assert!(pieces[0].length() < MIN_SEGMENT_M);
    }

    /// The turns between consecutive pieces (rad).
    fn turns(pieces: &[Piece]) -> Vec<f64> {
        pieces
            .windows(2)
            .map(|pair| {
                let (a, b) = (pair[0].end_tangent(), pair[1].start_tangent());
                libm::acos(a.dot(&b).clamp(-1.0, 1.0))
            })
            .collect()
    }

    #[test]
    fn nearly_smooth_joints_are_made_smooth_within_the_tolerance() {
        // A line, then a curve leaving 0.05 rad (2.9°) off the line's direction.
        let curve = Cubic {
            p: [
                V2::new(0.01, 0.0),
                V2::new(0.02, 0.01 * libm::tan(0.05)),
                V2::new(0.03, 0.01),
                V2::new(0.03, 0.02),
            ],
        };
        let path = subpath(
            (0.0, 0.0),
            vec![line(0.01, 0.0), Segment::Cubic(curve)],
            false,
        );
        let pieces = pieces(&path, 5e-5, 0.1);
        assert!(chained(&pieces));
        assert!(turns(&pieces).iter().all(|t| *t < emg_control::CORNER_RAD));
        let curve_pieces: Vec<Piece> = pieces[1..].to_vec();
        assert!(super::super::biarc::deviation(&curve, &curve_pieces) <= 5e-5);
        // Below the threshold asked for, the joint stays a corner.
        let pieces = super::pieces(&path, 5e-5, 0.04);
        assert!((turns(&pieces)[0] - 0.05).abs() < 1e-9);
        // At 1 µm there is no room to bend the curve by 0.05 rad: the limit is 0.005 rad.
        assert!((smooth_join_limit(1e-6, 0.1) - 0.005).abs() < 1e-15);
        let pieces = super::pieces(&path, 1e-6, 0.1);
        assert!((turns(&pieces)[0] - 0.05).abs() < 1e-9);
        // A real corner stays one.
        let corner = subpath((0.0, 0.0), vec![line(0.01, 0.0), line(0.01, 0.01)], false);
        let pieces = super::pieces(&corner, 5e-5, 0.1);
        let turn = libm::acos(pieces[0].end_tangent().dot(&pieces[1].start_tangent()));
        assert!((turn - PI / 2.0).abs() < 1e-12);
    }

    #[test]
    fn a_dot_becomes_its_chord() {
        let dot = Piece::Arc {
            from: V2::new(5e-5, 0.0),
            centre: V2::zeros(),
            sweep: 3.0,
        };
        assert!(matches!(without_dot(dot), Piece::Line { .. }));
    }
}
