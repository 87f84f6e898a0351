//! Runs of lines with fewer vertices: a jagged outline (a coastline, a map's border) has a
//! vertex every fraction of a millimetre, each turning a little, and rounded one by one its
//! corners have no room for an arc the tool can pass at speed. Dropping the vertices that lie
//! within a share of the corner tolerance of the line that replaces them (Douglas–Peucker)
//! leaves the outline's shape and longer lines, whose corners round wide.

use super::bezier::V2;
use super::piece::{Piece, segment_distance};

/// A chain of pieces after [`simplified`]: each with how far the drawing it replaces lies from
/// each half of it (m; 0 where it replaces nothing).
pub(crate) struct Simplified {
    /// The pieces, chained as before: the same ends, arcs as they were.
    pub pieces: Vec<Piece>,
    /// Per piece, the farthest the drawing it replaces lies from its first half and from its
    /// second half: of the lines it replaces, those whose projection on it reaches into that
    /// half (each lies within its farther end's distance, the band round a line being convex).
    pub deviation: Vec<[f64; 2]>,
}

impl Simplified {
    /// `pieces` as they are, nothing spent.
    pub(crate) fn unchanged(pieces: Vec<Piece>) -> Self {
        Simplified {
            deviation: vec![[0.0; 2]; pieces.len()],
            pieces,
        }
    }
}

/// `pieces` with each run of consecutive lines replaced by the fewest of its vertices (found
/// by Douglas–Peucker: the farthest vertex from the line between a run's ends is kept while it
/// lies farther than `within`, and each side is treated so) — every dropped vertex within
/// `within` of the line that replaces it. As every vertex of a run lies within `within` of the
/// replacing line, so does the whole run (the lines between them stay in the band round it),
/// and every point of the replacing line lies within that distance of the run (the run, seen
/// along the line, covers it from end to end): the two are within `within` of each other both
/// ways. Arcs, the chain's ends and the joints `keep` names (`keep(k)`: the one where piece `k`
/// starts) are kept; no line gets shorter.
pub(crate) fn simplified(
    pieces: &[Piece],
    within: f64,
    keep: impl Fn(usize) -> bool,
) -> Simplified {
    let mut out = Simplified {
        pieces: Vec::with_capacity(pieces.len()),
        deviation: Vec::with_capacity(pieces.len()),
    };
    let mut index = 0;
    while index < pieces.len() {
        let Piece::Line { from, .. } = pieces[index] else {
            out.pieces.push(pieces[index]);
            out.deviation.push([0.0; 2]);
            index += 1;
            continue;
        };
        let mut vertices = vec![from];
        while let Some(Piece::Line { to, .. }) = pieces.get(index) {
            vertices.push(*to);
            index += 1;
            if index < pieces.len() && keep(index) {
                break;
            }
        }
        let kept = kept_vertices(&vertices, within);
        for pair in kept.windows(2) {
            let replaced = &vertices[pair[0]..=pair[1]];
            let (a, b) = (replaced[0], replaced[replaced.len() - 1]);
            out.pieces.push(Piece::Line { from: a, to: b });
            out.deviation.push(deviation_by_half(replaced));
        }
    }
    out
}

/// How far the lines through `replaced` lie from each half of the line between its ends (see
/// [`Simplified::deviation`]).
fn deviation_by_half(replaced: &[V2]) -> [f64; 2] {
    let (a, b) = (replaced[0], replaced[replaced.len() - 1]);
    let chord = b - a;
    let length2 = chord.norm_squared().max(f64::MIN_POSITIVE);
    let along = |v: V2| (v - a).dot(&chord) / length2;
    let mut halves = [0.0_f64; 2];
    for edge in replaced.windows(2) {
        let far = segment_distance(edge[0], a, b).max(segment_distance(edge[1], a, b));
        let (t0, t1) = (along(edge[0]), along(edge[1]));
        if t0.min(t1) <= 0.5 {
            halves[0] = halves[0].max(far);
        }
        if t0.max(t1) >= 0.5 {
            halves[1] = halves[1].max(far);
        }
    }
    halves
}

/// The indices of `vertices` Douglas–Peucker keeps at `within` (m), in order; the first and
/// the last always.
fn kept_vertices(vertices: &[V2], within: f64) -> Vec<usize> {
    let last = vertices.len() - 1;
    let mut keep = vec![false; vertices.len()];
    keep[0] = true;
    keep[last] = true;
    let mut spans = vec![(0, last)];
    while let Some((first, end)) = spans.pop() {
        let farthest = (first + 1..end)
            .map(|i| {
                (
                    i,
                    segment_distance(vertices[i], vertices[first], vertices[end]),
                )
            })
            .fold(None, |best: Option<(usize, f64)>, (i, d)| match best {
                Some((_, top)) if top >= d => best,
                _ => Some((i, d)),
            });
        if let Some((i, d)) = farthest
            && d > within
        {
            keep[i] = true;
            spans.push((first, i));
            spans.push((i, end));
        }
    }
    (0..=last).filter(|&i| keep[i]).collect()
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    fn lines(points: &[V2]) -> Vec<Piece> {
        points
            .windows(2)
            .map(|w| Piece::Line {
                from: w[0],
                to: w[1],
            })
            .collect()
    }

    fn distance_to_chain(chain: &[Piece], p: V2) -> f64 {
        super::super::piece::distance_to(chain, p)
    }

    #[test]
    fn a_jagged_run_keeps_its_shape_within_the_share_both_ways() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        // A wavy line of 400 vertices 0.3 mm apart, jittered by up to 0.08 mm.
        let points: Vec<V2> = (0..400)
            .map(|i| {
                let x = i as f64 * 3e-4;
                V2::new(
                    x,
                    2e-3 * libm::sin(x * 60.0) + rng.random_range(-8e-5..8e-5),
                )
            })
            .collect();
        let run = lines(&points);
        let within = 6e-5;
        let simple = simplified(&run, within, |_| false);
        assert!(
            simple.pieces.len() < run.len() / 2,
            "{}",
            simple.pieces.len()
        );
        assert_eq!(simple.pieces.len(), simple.deviation.len());
        assert_eq!(simple.pieces[0].start(), points[0]);
        assert_eq!(simple.pieces.last().unwrap().end(), *points.last().unwrap());
        for pair in simple.pieces.windows(2) {
            assert_eq!(pair[0].end(), pair[1].start());
        }
        // Every point of the run lies within the share of the simplified chain, and every
        // point of that chain within it of the run (each sampled finely).
        let sample = |chain: &[Piece]| -> Vec<V2> {
            chain
                .iter()
                .flat_map(|p| (0..=20).map(move |i| p.point(i as f64 / 20.0)))
                .collect()
        };
        for p in sample(&run) {
            assert!(distance_to_chain(&simple.pieces, p) <= within + 1e-12);
        }
        for p in sample(&simple.pieces) {
            assert!(distance_to_chain(&run, p) <= within + 1e-12);
        }
        // The deviation recorded per half is within the share, and each half of a piece lies
        // within it of the run.
        let halves = simple.deviation.iter().flatten();
        assert!(halves.clone().all(|d| *d <= within));
        assert!(halves.clone().any(|d| *d > 0.5 * within));
        for (piece, deviation) in simple.pieces.iter().zip(&simple.deviation) {
            for (half, range) in [(0, 0..=10), (1, 10..=20)] {
                for i in range {
                    let p = piece.point(i as f64 / 20.0);
                    assert!(distance_to_chain(&run, p) <= deviation[half] + 1e-12);
                }
            }
        }
    }

    #[test]
    fn arcs_reversals_and_straight_runs() {
        // Three vertices on one line become one line, deviation 0.
        let straight = lines(&[V2::new(0.0, 0.0), V2::new(1e-3, 0.0), V2::new(3e-3, 0.0)]);
        let simple = simplified(&straight, 1e-5, |_| false);
        assert_eq!(simple.pieces.len(), 1);
        assert_eq!(simple.deviation, vec![[0.0; 2]]);
        // A reversal (out 2 mm and back) keeps its far end.
        let reversal = lines(&[V2::new(0.0, 0.0), V2::new(2e-3, 0.0), V2::new(0.0, 1e-4)]);
        assert_eq!(simplified(&reversal, 6e-5, |_| false).pieces.len(), 2);
        // An arc between two runs stays, and the runs on either side are simplified apart.
        let arc = super::super::piece::arc_from(
            V2::new(3e-3, 0.0),
            V2::new(1.0, 0.0),
            V2::new(4e-3, 1e-3),
        )
        .unwrap();
        let mut chain = straight.clone();
        chain.push(arc);
        chain.extend(lines(&[
            V2::new(4e-3, 1e-3),
            V2::new(4e-3, 2e-3),
            V2::new(4e-3, 3e-3),
        ]));
        let simple = simplified(&chain, 1e-5, |_| false);
        assert_eq!(simple.pieces.len(), 3);
        assert_eq!(simple.pieces[1], arc);
        // A joint named to be kept stays.
        let kept = simplified(&straight, 1e-5, |k| k == 1);
        assert_eq!(kept.pieces, straight);
        // A closed loop (first vertex = last) keeps a shape, not a point.
        let square = lines(&[
            V2::new(0.0, 0.0),
            V2::new(1e-2, 0.0),
            V2::new(1e-2, 1e-2),
            V2::new(0.0, 1e-2),
            V2::new(0.0, 0.0),
        ]);
        assert_eq!(simplified(&square, 1e-4, |_| false).pieces.len(), 4);
    }
}
