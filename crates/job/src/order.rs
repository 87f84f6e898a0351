//! The order stage: strokes that meet end to end merged into one ([`merge`]), then the
//! sequence and directions the drawn strokes are drawn in, chosen to shorten the pen-up travel:
//! nearest neighbour over a grid of the stroke ends ([`near`]), then ([`tour`]) 2-opt moves (a
//! run of strokes reversed, each stroke's direction with it) and Or-opt moves (a run of up to
//! [`MAX_RUN`] strokes moved elsewhere, either way round) among each end's [`NEIGHBOURS`]
//! nearest ends, spanning [`MAX_SPAN`] strokes at most, each stroke looked at [`MAX_ROUNDS`]
//! times at most on average. The work grows near-linearly with the strokes and is counted
//! ([`order_strokes_counted`]).

use emg_control::Path;
use emg_kinematics::Vec3;
use serde::{Deserialize, Serialize};

use crate::spec::Order;

pub mod merge;
pub mod near;
pub mod oriented;
pub mod tour;

pub use merge::{Chain, merge_strokes};
use near::Grid;
pub use near::NEIGHBOURS;
pub use oriented::Oriented;
use tour::{Legs, Tour};
pub use tour::{MAX_ROUNDS, MAX_RUN, MAX_SPAN};

/// The strokes drawn, the order chosen and the pen-up travel it saves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ordering {
    /// The drawn strokes in drawing order (indices into `drawn`).
    pub sequence: Vec<Oriented>,
    /// The drawn strokes, each the job's strokes it joins end to end ([`merge`]); absent
    /// from programs written before strokes were merged, where each job stroke is drawn alone.
    #[serde(default)]
    pub drawn: Vec<Chain>,
    /// Σ straight distance from each of the job's strokes' end to the next one's start, in the
    /// given order (m).
    pub travel_given_m: f64,
    /// The same between the drawn strokes in the chosen order (m).
    pub travel_m: f64,
}

impl Ordering {
    /// The drawn strokes' paths, from the job's `strokes`.
    pub fn drawn_paths(&self, strokes: &[Path]) -> Vec<Path> {
        if self.drawn.is_empty() {
            return strokes.to_vec();
        }
        self.drawn
            .iter()
            .map(|chain| {
                chain
                    .path(strokes)
                    .expect("a drawn stroke's strokes join, as when they were merged")
            })
            .collect()
    }

    /// The job's strokes merged with others, and the drawn strokes they make.
    pub fn merged(&self) -> (usize, usize) {
        self.drawn
            .iter()
            .filter(|chain| chain.0.len() > 1)
            .fold((0, 0), |(strokes, drawn), chain| {
                (strokes + chain.0.len(), drawn + 1)
            })
    }
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

    fn new(path: &Path) -> Self {
        Self {
            start: path.point_at(0.0),
            end: path.point_at(path.length_m()),
            reversible: path.reversed().is_some(),
        }
    }
}

/// The order of `strokes`, each drawn alone: as given, or the shortest found
/// ([`Order::Shortest`]); see the module documentation. A stroke whose reverse is not a valid
/// path ([`Path::reversed`]) keeps its direction. Deterministic.
pub fn order_strokes(strokes: &[Path], order: Order) -> Ordering {
    order_strokes_counted(strokes, order, None).0
}

/// [`order_strokes`] with the strokes that meet end to end within `tolerance_m` (the job's line
/// tolerance) drawn as one ([`merge_strokes`]; in the given order only each with the one listed
/// before it), what a job draws.
pub fn merge_and_order(strokes: &[Path], order: Order, tolerance_m: f64) -> Ordering {
    order_strokes_counted(strokes, order, Some(tolerance_m)).0
}

/// [`order_strokes`], merged within `merge_within_m` where given ([`merge_and_order`]), and
/// the work it took: the points and grid cells its searches visited, the distances it measured
/// and the strokes its moves shifted.
pub fn order_strokes_counted(
    strokes: &[Path],
    order: Order,
    merge_within_m: Option<f64>,
) -> (Ordering, usize) {
    let (merged, mut work) = match merge_within_m {
        Some(tolerance_m) => merge_strokes(strokes, order, tolerance_m),
        None => (
            strokes
                .iter()
                .enumerate()
                .map(|(stroke, path)| {
                    let alone = Oriented {
                        stroke,
                        reversed: false,
                    };
                    (Chain(vec![alone]), path.clone())
                })
                .collect(),
            0,
        ),
    };
    let given_ends: Vec<(Vec3, Vec3)> = strokes
        .iter()
        .map(|path| (path.point_at(0.0), path.point_at(path.length_m())))
        .collect();
    let travel_given_m = given_ends
        .windows(2)
        .map(|pair| (pair[1].0 - pair[0].1).norm())
        .fold(0.0, |total, leg| total + leg);
    let ends: Vec<Ends> = merged.iter().map(|(_, path)| Ends::new(path)).collect();
    let given: Vec<Oriented> = (0..ends.len())
        .map(|stroke| Oriented {
            stroke,
            reversed: false,
        })
        .collect();
    let sequence = match order {
        Order::Given => given,
        Order::Shortest => {
            let (sequence, nearest_work) = nearest_neighbour(&ends);
            let (neighbours, neighbours_work) = nearest_ends(&ends);
            let legs = Travel(&ends);
            let mut tour = Tour::new(&legs, sequence, neighbours);
            tour.improve();
            work += nearest_work + neighbours_work + tour.work;
            tour.sequence
        }
    };
    let ordering = Ordering {
        travel_m: travel(&sequence, &ends),
        sequence,
        drawn: merged.into_iter().map(|(chain, _)| chain).collect(),
        travel_given_m,
    };
    (ordering, work)
}

/// Σ distance from each stroke's end to the next one's start (0, not the empty sum's −0, for a
/// single stroke).
fn travel(sequence: &[Oriented], ends: &[Ends]) -> f64 {
    sequence
        .windows(2)
        .map(|pair| (Ends::of(pair[1], ends).0 - Ends::of(pair[0], ends).1).norm())
        .fold(0.0, |total, leg| total + leg)
}

/// The pen-up travel between strokes drawn in the directions chosen: the straight distance from
/// where one is lifted to where the next is set down (none before the first or after the last).
struct Travel<'a>(&'a [Ends]);

impl Legs for Travel<'_> {
    fn cost(&self, from: Option<usize>, to: Option<usize>) -> f64 {
        let point = |end: usize| {
            let e = &self.0[end / 2];
            if end.is_multiple_of(2) {
                e.start
            } else {
                e.end
            }
        };
        from.zip(to)
            .map_or(0.0, |(a, b)| (point(b) - point(a)).norm())
    }

    fn reversible(&self, stroke: usize) -> bool {
        self.0[stroke].reversible
    }
}

/// Each stroke end's [`NEIGHBOURS`] nearest ends of other strokes, nearest first, with their
/// distances, and the grid's work.
fn nearest_ends(ends: &[Ends]) -> (Vec<Vec<(f64, usize)>>, usize) {
    let mut grid = ends_grid(ends);
    let neighbours = (0..2 * ends.len())
        .map(|point| {
            let at = grid.point(point);
            grid.nearest(at, NEIGHBOURS, f64::INFINITY, |other| {
                other / 2 != point / 2
            })
        })
        .collect();
    (neighbours, grid.work())
}

/// The grid of the strokes' ends: point 2i is stroke i's start, 2i + 1 its end.
fn ends_grid(ends: &[Ends]) -> Grid {
    Grid::new(ends.iter().flat_map(|e| [e.start, e.end]).collect())
}

/// From the first stroke, always the nearest start (or end, drawn reversed) not yet drawn (of
/// equally near ones the first listed, its start first), with the grid's work.
fn nearest_neighbour(ends: &[Ends]) -> (Vec<Oriented>, usize) {
    let mut grid = ends_grid(ends);
    let mut sequence = Vec::with_capacity(ends.len());
    let mut next = ends.first().map(|_| 0);
    while let Some(point) = next {
        grid.remove(point);
        grid.remove(point ^ 1);
        let oriented = Oriented {
            stroke: point / 2,
            reversed: point % 2 == 1,
        };
        sequence.push(oriented);
        let here = Ends::of(oriented, ends).1;
        let accept = |point: usize| point.is_multiple_of(2) || ends[point / 2].reversible;
        next = grid
            .nearest(here, 1, f64::INFINITY, accept)
            .first()
            .map(|&(_, point)| point);
    }
    (sequence, grid.work())
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
