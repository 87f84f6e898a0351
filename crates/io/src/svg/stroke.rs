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
//! * With a corner tolerance, each run of lines first drops, of the vertices whose corner
//!   cannot be rounded as it is, those within [`SIMPLIFYING_SHARE`] of the corner tolerance of
//!   the line replacing them ([`simplified`]: a jagged outline keeps its shape and gets lines
//!   long enough to round).
//! * Every other corner is rounded within the corner tolerance (0 keeps it) less what the
//!   simplification spent beside it: two lines by the arc tangent to both, a corner where an
//!   arc meets by the biarc between points of its two sides, each rounding taking at most half
//!   of each piece; a corner whose rounding would be shorter than the shortest piece or tighter
//!   than [`MIN_CORNER_RADIUS_M`] (a reversal, a sharp turn between short legs) stays one.
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
use super::simplify::{Simplified, simplified};

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
/// smooth and corners rounded within `corner_tolerance` (see the module documentation). Empty
/// when nothing of it is that long; a lone piece shorter than that may remain.
pub(crate) fn pieces(
    subpath: &Subpath,
    tolerance: f64,
    smooth_join_rad: f64,
    corner_tolerance: f64,
) -> Vec<Piece> {
    let mut items = items(subpath);
    let smooth_limit = smooth_join_limit(tolerance, smooth_join_rad);
    smooth_joints(&mut items, smooth_limit);
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
    let allowance = JoinAllowance {
        smooth_rad: smooth_join_rad,
        smooth_m: tolerance.max(corner_tolerance),
        corner_m: corner_tolerance,
    };
    // Only joints that cannot be rounded as they are may go: a flattened curve's vertices
    // round as they are, and dropping some would leave sharper corners.
    let simple = if corner_tolerance > 0.0 {
        simplified(&out, SIMPLIFYING_SHARE * corner_tolerance, |k| {
            rounding(&out[k - 1], &out[k], &allowance, 0.0).is_some()
        })
    } else {
        Simplified::unchanged(out)
    };
    rounded(&simple, &allowance)
}

/// The share of the corner tolerance a run of lines may be simplified within
/// ([`simplified`]); what its rounding may leave the simplified corners by is the rest.
pub(crate) const SIMPLIFYING_SHARE: f64 = 0.75;

/// The smallest radius (m) a corner is rounded with: a tighter arc is passed quicker, but the
/// timed motion through it leaves the tolerance more often, and its part is cut there.
pub(crate) const MIN_CORNER_RADIUS_M: f64 = 1e-3;

/// How far the rounding of a joint may leave it: joints turning less than `smooth_rad` are
/// ones the drawing means smooth and may be left by `smooth_m` (m), sharper ones (corners) by
/// `corner_m` (0 keeps them) with arcs of [`MIN_CORNER_RADIUS_M`] or more.
struct JoinAllowance {
    smooth_rad: f64,
    smooth_m: f64,
    corner_m: f64,
}

impl JoinAllowance {
    /// How far the joint turning by `turn` (rad) may be left (m), and the smallest radius its
    /// rounding may have.
    fn at(&self, turn: f64) -> (f64, f64) {
        if turn < self.smooth_rad {
            (self.smooth_m, SHORTEST)
        } else {
            (self.corner_m, MIN_CORNER_RADIUS_M)
        }
    }
}

/// A joint's rounding: how far along each of its two pieces it reaches from the joint, and the
/// arcs in place of what it takes of them.
struct Rounding {
    reach: f64,
    arcs: Vec<Piece>,
}

/// `chain`'s pieces with each joint where they turn rounded within its allowance less what
/// the simplification spent on either side of it ([`rounding`]; the rounding leaves the
/// simplified joint by at most the rest, which leaves the drawing by at most the allowance);
/// the chain's ends stay where they are.
fn rounded(chain: &Simplified, allowance: &JoinAllowance) -> Vec<Piece> {
    let pieces = &chain.pieces;
    let roundings: Vec<Option<Rounding>> = (0..pieces.len())
        .map(|index| {
            (index > 0)
                .then(|| {
                    // A rounding takes at most half of each piece: the halves beside the joint.
                    let spent = chain.deviation[index - 1][1].max(chain.deviation[index][0]);
                    rounding(&pieces[index - 1], &pieces[index], allowance, spent)
                })
                .flatten()
        })
        .collect();
    let reach = |index: usize| {
        roundings
            .get(index)
            .and_then(Option::as_ref)
            .map_or(0.0, |r| r.reach)
    };
    let mut out = Vec::with_capacity(pieces.len());
    for (index, piece) in pieces.iter().enumerate() {
        if let Some(rounding) = &roundings[index] {
            out.extend(rounding.arcs.iter().copied());
        }
        out.push(piece.trimmed(reach(index), reach(index + 1)));
    }
    out
}

/// The rounding of the joint where `before` ends and `after` starts, leaving it by at most its
/// allowance less `spent` (m), taking at most half of each piece less half the shortest piece
/// (so each keeps a length); `None` where the joint is smooth already, no allowance is left, or
/// the rounding would be shorter than the shortest piece or tighter than its least radius (a
/// reversal, a sharp corner, or no room): the corner stays.
///
/// Two lines are joined by the arc tangent to both: one of radius `r` on lines turning by `θ`
/// reaches `r tan(θ/2)` along each and passes `r (1/cos(θ/2) − 1) = r 2 sin²(θ/4) / cos(θ/2)`
/// inside the corner, so the allowance `e` lets it reach `e sin(θ/2) / (2 sin²(θ/4))`. Where an
/// arc meets, the two pieces are trimmed by that reach and their new ends joined by the biarc
/// between them (their tangents kept), the reach halved until the biarc lies within the
/// allowance of what it replaces.
fn rounding(
    before: &Piece,
    after: &Piece,
    allowance: &JoinAllowance,
    spent: f64,
) -> Option<Rounding> {
    let (a, b) = (before.end_tangent(), after.start_tangent());
    let turn = libm::acos(a.dot(&b).clamp(-1.0, 1.0));
    let (allowed, least_radius) = allowance.at(turn);
    let allowed = allowed - spent;
    if turn <= emg_control::CORNER_RAD || allowed <= 0.0 {
        return None;
    }
    let half = 0.5 * turn;
    let quarter_sin = libm::sin(0.5 * half);
    let within = allowed * libm::sin(half) / (2.0 * quarter_sin * quarter_sin);
    let room = 0.5 * (before.length().min(after.length()) - SHORTEST);
    let mut reach = within.min(room);
    if let (Piece::Line { .. }, Piece::Line { .. }) = (before, after) {
        let radius = reach / libm::tan(half);
        if radius < least_radius || radius * turn < SHORTEST {
            return None;
        }
        let arc = arc_from(before.end() - a * reach, a, after.start() + b * reach)?;
        return Some(Rounding {
            reach,
            arcs: vec![arc],
        });
    }
    while reach >= SHORTEST {
        let taken = [
            before.trimmed(before.length() - reach, 0.0),
            after.trimmed(0.0, after.length() - reach),
        ];
        let (from, to) = (taken[0].start(), taken[1].end());
        if let Some(pair) = biarc(from, taken[0].start_tangent(), to, taken[1].end_tangent())
            && pair
                .iter()
                .all(|p| !is_short(p) && p.radius().is_none_or(|radius| radius >= least_radius))
            && apart(&pair, &taken) <= allowed
        {
            return Some(Rounding {
                reach,
                arcs: pair.to_vec(),
            });
        }
        reach *= 0.5;
    }
    None
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
        let pieces = pieces(&square, 5e-5, 0.1, 0.0);
        assert_eq!(pieces.len(), 4);
        assert!(chained(&pieces));
        assert_eq!(pieces[3].end(), V2::new(0.0, 0.0));
        // Closed already: no closing line of zero length.
        let closed = subpath(
            (0.0, 0.0),
            vec![line(0.01, 0.0), line(0.01, 0.01), line(0.0, 0.0)],
            true,
        );
        assert_eq!(super::pieces(&closed, 5e-5, 0.1, 0.0).len(), 3);
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
        let pieces = super::pieces(&nearly, 5e-5, 0.1, 0.0);
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
        let pieces = pieces(&jagged, 5e-5, 0.1, 0.0);
        assert!(chained(&pieces));
        assert!(pieces.iter().all(|p| p.length() >= MIN_SEGMENT_M));
        assert_eq!(pieces[0].start(), V2::new(0.0, 0.0));
        assert!((pieces.last().unwrap().end() - V2::new(0.02, 5e-5)).norm() < 1e-12);
        // A path shorter than the shortest segment leaves one short piece.
        let tiny = subpath((0.0, 0.0), vec![line(5e-5, 0.0)], false);
        let pieces = super::pieces(&tiny, 5e-5, 0.1, 0.0);
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
        let curve = Cubic::from_xy([
            (0.01, 0.0),
            (0.02, 0.01 * libm::tan(0.05)),
            (0.03, 0.01),
            (0.03, 0.02),
        ]);
        let path = subpath(
            (0.0, 0.0),
            vec![line(0.01, 0.0), Segment::Cubic(curve)],
            false,
        );
        let pieces = pieces(&path, 5e-5, 0.1, 0.0);
        assert!(chained(&pieces));
        assert!(turns(&pieces).iter().all(|t| *t < emg_control::CORNER_RAD));
        let curve_pieces: Vec<Piece> = pieces[1..].to_vec();
        assert!(super::super::biarc::deviation(&curve, &curve_pieces) <= 5e-5);
        // Below the threshold asked for, the joint stays a corner.
        let pieces = super::pieces(&path, 5e-5, 0.04, 0.0);
        assert!((turns(&pieces)[0] - 0.05).abs() < 1e-9);
        // At 1 µm there is no room to bend the curve by 0.05 rad: the limit is 0.005 rad.
        assert!((smooth_join_limit(1e-6, 0.1) - 0.005).abs() < 1e-15);
        let pieces = super::pieces(&path, 1e-6, 0.1, 0.0);
        assert!((turns(&pieces)[0] - 0.05).abs() < 1e-9);
        // A real corner stays one.
        let corner = subpath((0.0, 0.0), vec![line(0.01, 0.0), line(0.01, 0.01)], false);
        let pieces = super::pieces(&corner, 5e-5, 0.1, 0.0);
        let turn = libm::acos(pieces[0].end_tangent().dot(&pieces[1].start_tangent()));
        assert!((turn - PI / 2.0).abs() < 1e-12);
    }

    /// The largest distance from a point of `pieces` to `polyline` and from a vertex of
    /// `polyline` to `pieces`, each sampled.
    fn deviation_from(pieces: &[Piece], polyline: &[V2]) -> (f64, f64) {
        let lines: Vec<Piece> = polyline
            .windows(2)
            .map(|w| Piece::Line {
                from: w[0],
                to: w[1],
            })
            .collect();
        let outward = pieces
            .iter()
            .flat_map(|piece| (0..=64).map(|i| piece.point(i as f64 / 64.0)))
            .map(|p| distance_to(&lines, p))
            .fold(0.0, f64::max);
        let vertices = polyline
            .iter()
            .map(|v| distance_to(pieces, *v))
            .fold(0.0, f64::max);
        (outward, vertices)
    }

    fn polyline(points: &[V2]) -> Subpath {
        subpath(
            (points[0].x, points[0].y),
            points[1..].iter().map(|p| line(p.x, p.y)).collect(),
            false,
        )
    }

    #[test]
    fn corners_are_rounded_within_the_corner_tolerance() {
        let corner = 2.5e-4;
        // A flattened circle of 5 mm radius (a vertex every 20°), a square of 1 cm sides, and
        // random polylines with legs of 0.3 mm to 5 mm turning up to 170°.
        let mut cases: Vec<Vec<V2>> = vec![
            (0..=18)
                .map(|k| {
                    let a = k as f64 * PI / 9.0;
                    V2::new(5e-3 * libm::cos(a), 5e-3 * libm::sin(a))
                })
                .collect(),
            vec![
                V2::new(0.0, 0.0),
                V2::new(0.01, 0.0),
                V2::new(0.01, 0.01),
                V2::new(0.0, 0.01),
                V2::new(0.0, 0.0),
            ],
        ];
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(78);
        for _ in 0..40 {
            let mut at = V2::zeros();
            let mut heading: f64 = 0.0;
            let mut points = vec![at];
            for _ in 0..12 {
                heading += rng.random_range(-170f64..170.0).to_radians();
                at +=
                    V2::new(libm::cos(heading), libm::sin(heading)) * rng.random_range(3e-4..5e-3);
                points.push(at);
            }
            cases.push(points);
        }
        // Jagged outlines: a circle of 20 mm radius with a vertex every 0.3 mm, each moved by
        // up to 0.1 mm across it.
        for _ in 0..4 {
            let jagged: Vec<V2> = (0..=400)
                .map(|k| {
                    let a = k as f64 * 2.0 * PI / 400.0;
                    let r = 0.02 + rng.random_range(-1e-4..1e-4);
                    V2::new(r * libm::cos(a), r * libm::sin(a))
                })
                .collect();
            cases.push(jagged);
        }
        for points in &cases {
            let sharp = pieces(&polyline(points), 5e-5, 0.0, 0.0);
            let round = pieces(&polyline(points), 5e-5, 0.0, corner);
            assert!(chained(&round));
            assert!(round.iter().all(|p| p.length() >= MIN_SEGMENT_M));
            assert_eq!(round[0].start(), sharp[0].start());
            assert!((round.last().unwrap().end() - sharp.last().unwrap().end()).norm() < 1e-12);
            let (outward, vertices) = deviation_from(&round, points);
            assert!(outward <= corner + 1e-12, "{outward}");
            assert!(vertices <= corner + 1e-9, "{vertices}");
            let sharp_turns = turns(&sharp);
            assert!(
                turns(&round)
                    .iter()
                    .filter(|t| **t > emg_control::CORNER_RAD)
                    .count()
                    <= sharp_turns
                        .iter()
                        .filter(|t| **t > emg_control::CORNER_RAD)
                        .count()
            );
        }
        // The jagged outlines are simplified: they stop at far fewer corners.
        for jagged in &cases[cases.len() - 4..] {
            let sharp = turns(&pieces(&polyline(jagged), 5e-5, 0.0, 0.0));
            let round = turns(&pieces(&polyline(jagged), 5e-5, 0.0, corner));
            let corners = |turns: &[f64]| {
                turns
                    .iter()
                    .filter(|t| **t > emg_control::CORNER_RAD)
                    .count()
            };
            assert!(
                corners(&round) * 3 < corners(&sharp),
                "{} of {}",
                corners(&round),
                corners(&sharp)
            );
        }
        // The flattened circle is passed without a corner; the square's corners, whose
        // rounding would be 0.6 mm in radius, tighter than MIN_CORNER_RADIUS_M, stay corners.
        let circle = pieces(&polyline(&cases[0]), 5e-5, 0.0, corner);
        assert!(turns(&circle).iter().all(|t| *t <= emg_control::CORNER_RAD));
        let square = pieces(&polyline(&cases[1]), 5e-5, 0.0, corner);
        assert_eq!(square.len(), 4);
        assert!(turns(&square).iter().all(|t| (t - PI / 2.0).abs() < 1e-9));
        // Within 1 mm, they are rounded too.
        let square = pieces(&polyline(&cases[1]), 5e-5, 0.0, 1e-3);
        assert!(turns(&square).iter().all(|t| *t <= emg_control::CORNER_RAD));
        assert!(deviation_from(&square, &cases[1]).1 <= 1e-3 + 1e-9);
        // A 173° reversal stays a corner: its rounding would be shorter than a piece.
        let back = 173f64.to_radians();
        let zigzag = [
            V2::zeros(),
            V2::new(0.01, 0.0),
            V2::new(0.01 + 0.01 * libm::cos(back), 0.01 * libm::sin(back)),
        ];
        let round = pieces(&polyline(&zigzag), 5e-5, 0.0, corner);
        assert_eq!(round.len(), 2);
        assert!((turns(&round)[0] - back).abs() < 1e-9);
    }

    fn unsimplified(chain: &[Piece]) -> Simplified {
        Simplified::unchanged(chain.to_vec())
    }

    #[test]
    fn a_corner_where_an_arc_meets_is_rounded_by_a_biarc_within_the_tolerance() {
        // A line, then a quarter circle of 5 mm radius leaving it at a right angle.
        let line_to = V2::new(0.01, 0.0);
        let arc = Piece::Arc {
            from: line_to,
            centre: line_to + V2::new(-5e-3, 0.0),
            sweep: PI / 2.0,
        };
        let chain = [
            Piece::Line {
                from: V2::zeros(),
                to: line_to,
            },
            arc,
        ];
        let allowance = JoinAllowance {
            smooth_rad: 0.0,
            smooth_m: 0.0,
            corner_m: 2e-3,
        };
        let round = rounded(&unsimplified(&chain), &allowance);
        assert!(chained(&round));
        assert!(
            turns(&round).iter().all(|t| *t <= emg_control::CORNER_RAD),
            "{round:?}"
        );
        assert!(apart(&round, &chain) <= 2e-3);
        assert!(distance_to(&round, line_to) > 1e-5);
        assert!(
            round
                .iter()
                .filter_map(Piece::radius)
                .all(|r| r >= MIN_CORNER_RADIUS_M)
        );
        // Within 0.25 mm the rounding would be tighter than a millimetre: the corner stays.
        let tight = JoinAllowance {
            corner_m: 2.5e-4,
            ..allowance
        };
        assert_eq!(rounded(&unsimplified(&chain), &tight), chain.to_vec());
        // Within 2 mm less 0.5 mm a simplification spent beside the joint: within 1.5 mm.
        let spent = Simplified {
            pieces: chain.to_vec(),
            deviation: vec![[0.0, 5e-4], [0.0; 2]],
        };
        let round = rounded(&spent, &allowance);
        assert!(turns(&round).iter().all(|t| *t <= emg_control::CORNER_RAD));
        assert!(apart(&round, &chain) <= 1.5e-3);
        // No allowance (none, or all of it spent), no rounding.
        let none = JoinAllowance {
            corner_m: 0.0,
            ..allowance
        };
        assert_eq!(rounded(&unsimplified(&chain), &none), chain.to_vec());
        let all_spent = Simplified {
            pieces: chain.to_vec(),
            deviation: vec![[0.0; 2], [2e-3, 0.0]],
        };
        assert_eq!(rounded(&all_spent, &allowance), chain.to_vec());
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
