//! The order stage: the sequence and directions the strokes are drawn in, chosen to shorten
//! the pen-up travel between them (nearest neighbour, then 2-opt with reversals).

use emg_control::Path;
use emg_kinematics::Vec3;
use serde::{Deserialize, Serialize};

use crate::spec::Order;

/// A stroke drawn in a direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Oriented {
    /// The stroke's index in the job.
    pub stroke: usize,
    /// Whether it is drawn from its end to its start.
    pub reversed: bool,
}

impl Oriented {
    /// The stroke as drawn, from `strokes` (the job's): reversed where it is drawn from its
    /// end (only reversible strokes are, [`order_strokes`]).
    pub fn path(&self, strokes: &[Path]) -> Path {
        let stroke = &strokes[self.stroke];
        if self.reversed {
            stroke
                .reversed()
                .expect("only reversible strokes are reversed")
        } else {
            stroke.clone()
        }
    }
}

/// The order chosen and the pen-up travel it saves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ordering {
    /// The strokes in drawing order.
    pub sequence: Vec<Oriented>,
    /// Σ straight distance from each stroke's end to the next one's start, in the given order
    /// (m).
    pub travel_given_m: f64,
    /// The same in the chosen order (m).
    pub travel_m: f64,
}

/// The start and end points of each stroke, and whether it may be reversed.
struct Ends {
    start: Vec3,
    end: Vec3,
    reversible: bool,
}

impl Ends {
    fn of(oriented: Oriented, ends: &[Ends]) -> (Vec3, Vec3) {
        let e = &ends[oriented.stroke];
        if oriented.reversed {
            (e.end, e.start)
        } else {
            (e.start, e.end)
        }
    }
}

/// Improvement passes of 2-opt at most.
const MAX_PASSES: usize = 50;

/// The order of `strokes`: as given, or the shortest found ([`Order::Shortest`]: nearest
/// neighbour from the first stroke's start, then 2-opt moves that reverse a run of strokes,
/// each stroke's direction with it, while any shortens the travel). A stroke whose reverse is
/// not a valid path ([`Path::reversed`]) keeps its direction. Deterministic.
pub fn order_strokes(strokes: &[Path], order: Order) -> Ordering {
    let ends: Vec<Ends> = strokes
        .iter()
        .map(|path| Ends {
            start: path.point_at(0.0),
            end: path.point_at(path.length_m()),
            reversible: path.reversed().is_some(),
        })
        .collect();
    let given: Vec<Oriented> = (0..strokes.len())
        .map(|stroke| Oriented {
            stroke,
            reversed: false,
        })
        .collect();
    let travel_given_m = travel(&given, &ends);
    let sequence = match order {
        Order::Given => given,
        Order::Shortest => two_opt(nearest_neighbour(&ends), &ends),
    };
    Ordering {
        travel_m: travel(&sequence, &ends),
        sequence,
        travel_given_m,
    }
}

/// Σ distance from each stroke's end to the next one's start (0, not the empty sum's −0, for a
/// single stroke).
fn travel(sequence: &[Oriented], ends: &[Ends]) -> f64 {
    sequence
        .windows(2)
        .map(|pair| (Ends::of(pair[1], ends).0 - Ends::of(pair[0], ends).1).norm())
        .fold(0.0, |total, leg| total + leg)
}

/// From the first stroke, always the nearest start (or end, drawn reversed) not yet drawn.
fn nearest_neighbour(ends: &[Ends]) -> Vec<Oriented> {
    let mut left: Vec<usize> = (1..ends.len()).collect();
    let mut sequence = vec![Oriented {
        stroke: 0,
        reversed: false,
    }];
    while !left.is_empty() {
        let here = Ends::of(*sequence.last().expect("a first stroke"), ends).1;
        let mut best: Option<(f64, usize, bool)> = None;
        for (slot, &stroke) in left.iter().enumerate() {
            let e = &ends[stroke];
            let options = [(e.start, false), (e.end, true)];
            for (point, reversed) in options {
                if reversed && !e.reversible {
                    continue;
                }
                let distance = (point - here).norm();
                if best.is_none_or(|(d, _, _)| distance < d) {
                    best = Some((distance, slot, reversed));
                }
            }
        }
        let (_, slot, reversed) = best.expect("a stroke is left");
        sequence.push(Oriented {
            stroke: left.remove(slot),
            reversed,
        });
    }
    sequence
}

/// 2-opt: reverses the run `i..=j` (order and directions) where that shortens the travel.
fn two_opt(mut sequence: Vec<Oriented>, ends: &[Ends]) -> Vec<Oriented> {
    let n = sequence.len();
    for _ in 0..MAX_PASSES {
        let mut improved = false;
        for i in 0..n {
            for j in i + 1..n {
                if !sequence[i..=j].iter().all(|o| ends[o.stroke].reversible) {
                    continue;
                }
                let (first_start, _) = Ends::of(sequence[i], ends);
                let (_, last_end) = Ends::of(sequence[j], ends);
                let before = i.checked_sub(1).map(|k| Ends::of(sequence[k], ends).1);
                let after = (j + 1 < n).then(|| Ends::of(sequence[j + 1], ends).0);
                let link = |a: Option<Vec3>, b: Vec3| a.map_or(0.0, |a| (b - a).norm());
                let link_after = |a: Vec3, b: Option<Vec3>| b.map_or(0.0, |b| (b - a).norm());
                let now = link(before, first_start) + link_after(last_end, after);
                let then = link(before, last_end) + link_after(first_start, after);
                if then < now - 1e-12 {
                    sequence[i..=j].reverse();
                    for o in &mut sequence[i..=j] {
                        o.reversed = !o.reversed;
                    }
                    improved = true;
                }
            }
        }
        if !improved {
            break;
        }
    }
    sequence
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(from: [f64; 3], to: [f64; 3]) -> Path {
        let from = Vec3::from(from);
        let to = Vec3::from(to);
        Path::straight(
            from,
            (to - from).normalize(),
            Vec3::new(0.0, 0.0, -1.0),
            (to - from).norm(),
        )
        .unwrap()
    }

    #[test]
    fn the_shortest_order_reverses_and_reorders_strokes_to_cut_the_travel() {
        // Three parallel hatch lines drawn all the same way, listed out of order.
        let strokes = vec![
            line([0.4, 0.0, 0.2], [0.5, 0.0, 0.2]),
            line([0.4, 0.02, 0.2], [0.5, 0.02, 0.2]),
            line([0.4, 0.01, 0.2], [0.5, 0.01, 0.2]),
        ];
        let given = order_strokes(&strokes, Order::Given);
        let shortest = order_strokes(&strokes, Order::Shortest);
        assert!((given.travel_m - given.travel_given_m).abs() < 1e-15);
        // Boustrophedon: 0, 2 reversed, 1: two steps of 1 cm.
        assert!((shortest.travel_m - 0.02).abs() < 1e-9, "{shortest:?}");
        assert!(shortest.travel_m < given.travel_m);
        assert_eq!(
            shortest
                .sequence
                .iter()
                .map(|o| o.stroke)
                .collect::<Vec<_>>(),
            vec![0, 2, 1]
        );
        assert!(shortest.sequence[1].reversed && !shortest.sequence[2].reversed);
    }

    #[test]
    fn a_single_stroke_travels_a_positive_zero() {
        let strokes = vec![line([0.4, 0.0, 0.2], [0.5, 0.0, 0.2])];
        for order in [Order::Given, Order::Shortest] {
            let ordering = order_strokes(&strokes, order);
            for travel in [ordering.travel_m, ordering.travel_given_m] {
                // `{:.3}` prints −0 as "-0.000".
                assert_eq!(format!("{travel:.3}"), "0.000", "{order:?}");
            }
        }
    }
}
