//! The order stage: strokes that meet end to end merged into one ([`merge`]), then the
//! sequence and directions the drawn strokes are drawn in, chosen to shorten the pen-up travel:
//! nearest neighbour over a grid of the stroke ends ([`near`]), then 2-opt moves (a run
//! of strokes reversed, each stroke's direction with it) and Or-opt moves (a run of up to
//! [`MAX_RUN`] strokes moved elsewhere, either way round) among each end's [`NEIGHBOURS`]
//! nearest ends, spanning [`MAX_SPAN`] strokes at most, each stroke looked at [`MAX_ROUNDS`]
//! times at most on average. The work grows near-linearly with the strokes and is counted
//! ([`order_strokes_counted`]).

use std::collections::VecDeque;

use emg_control::Path;
use emg_kinematics::Vec3;
use serde::{Deserialize, Serialize};

use crate::spec::Order;

pub mod merge;
pub mod near;

pub use merge::{Chain, merge_strokes};
use near::Grid;

/// The ends of another stroke each stroke end keeps as candidates for a move.
pub const NEIGHBOURS: usize = 10;

/// Strokes a move shifts or reverses at most.
pub const MAX_SPAN: usize = 1000;

/// Strokes an Or-opt move takes at most.
pub const MAX_RUN: usize = 3;

/// Times each stroke is looked at for a move, on average, at most.
pub const MAX_ROUNDS: usize = 50;

/// A stroke drawn in a direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Oriented {
    /// The stroke's index: among the drawn strokes ([`Ordering::drawn`]) in an ordering's
    /// sequence, among the job's in a [`Chain`].
    pub stroke: usize,
    /// Whether it is drawn from its end to its start.
    pub reversed: bool,
}

impl Oriented {
    /// The stroke as drawn, from `strokes` (the list it indexes): reversed where it is drawn
    /// from its end (only reversible strokes are, [`order_strokes`]).
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
            let mut tour = Tour::new(&ends, sequence);
            tour.improve();
            work += nearest_work + tour.work;
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

/// A sequence of strokes being improved by moves among near ends.
struct Tour<'a> {
    ends: &'a [Ends],
    sequence: Vec<Oriented>,
    /// Each stroke's place in `sequence`.
    position: Vec<usize>,
    /// Each stroke end's nearest ends of other strokes (point 2i is stroke i's start, 2i + 1
    /// its end), nearest first, with their distances.
    neighbours: Vec<Vec<(f64, usize)>>,
    work: usize,
}

/// Gains smaller than this (m) are not taken.
const MIN_GAIN_M: f64 = 1e-12;

impl<'a> Tour<'a> {
    fn new(ends: &'a [Ends], sequence: Vec<Oriented>) -> Self {
        let mut grid = ends_grid(ends);
        let neighbours = (0..2 * ends.len())
            .map(|point| {
                let at = grid.point(point);
                grid.nearest(at, NEIGHBOURS, f64::INFINITY, |other| {
                    other / 2 != point / 2
                })
            })
            .collect();
        let mut position = vec![0; ends.len()];
        for (place, oriented) in sequence.iter().enumerate() {
            position[oriented.stroke] = place;
        }
        Self {
            ends,
            sequence,
            position,
            neighbours,
            work: grid.work(),
        }
    }

    /// Where the stroke at `place` is set down (`None` past the sequence's end).
    fn entry(&self, place: usize) -> Option<Vec3> {
        let oriented = self.sequence.get(place)?;
        Some(Ends::of(*oriented, self.ends).0)
    }

    /// Where the stroke at `place` is lifted (`None` before the sequence's start).
    fn exit(&self, place: Option<usize>) -> Option<Vec3> {
        let oriented = self.sequence.get(place?)?;
        Some(Ends::of(*oriented, self.ends).1)
    }

    /// The travel from `from` to `to`; none where either is missing (the sequence's ends).
    fn link(&mut self, from: Option<Vec3>, to: Option<Vec3>) -> f64 {
        self.work += 1;
        from.zip(to).map_or(0.0, |(a, b)| (b - a).norm())
    }

    /// Whether stroke end `point` is where its stroke is lifted as it is drawn now.
    fn is_exit(&self, point: usize) -> bool {
        let oriented = self.sequence[self.position[point / 2]];
        (point % 2 == 1) != oriented.reversed
    }

    /// Whether every stroke at `places` may be reversed (counted as work).
    fn reversible(&mut self, places: std::ops::RangeInclusive<usize>) -> bool {
        self.work += places.clone().count();
        self.sequence[places]
            .iter()
            .all(|o| self.ends[o.stroke].reversible)
    }

    /// Moves until none among near ends shortens the travel, or the rounds are spent.
    fn improve(&mut self) {
        let n = self.sequence.len();
        let mut queue: VecDeque<usize> = self.sequence.iter().map(|o| o.stroke).collect();
        let mut queued = vec![true; n];
        let mut looks = 0;
        while let Some(stroke) = queue.pop_front() {
            queued[stroke] = false;
            looks += 1;
            if looks > MAX_ROUNDS * n {
                break;
            }
            let touched = self.improve_at(self.position[stroke]);
            for stroke in touched {
                if !queued[stroke] {
                    queued[stroke] = true;
                    queue.push_back(stroke);
                }
            }
        }
    }

    /// The first move found at the stroke at `place` that shortens the travel, made; the
    /// strokes whose links it changed.
    fn improve_at(&mut self, place: usize) -> Vec<usize> {
        self.two_opt_at(place)
            .or_else(|| (1..=MAX_RUN).find_map(|run| self.or_opt_at(place, run)))
            .unwrap_or_default()
    }

    /// The strokes at `places` (those that are in the sequence).
    fn strokes_at(&self, places: &[Option<usize>]) -> Vec<usize> {
        places
            .iter()
            .filter_map(|p| self.sequence.get((*p)?))
            .map(|o| o.stroke)
            .collect()
    }

    /// A 2-opt move making a link between the stroke at `place`'s exit and another's exit, or
    /// its entry and another's entry, nearer than the link it has; the strokes whose links
    /// changed.
    fn two_opt_at(&mut self, place: usize) -> Option<Vec<usize>> {
        let oriented = self.sequence[place];
        for exit in [true, false] {
            let point = 2 * oriented.stroke + usize::from(exit != oriented.reversed);
            let current = if exit {
                let here = self.exit(Some(place));
                let there = self.entry(place + 1);
                self.link(here, there)
            } else {
                let before = self.exit(place.checked_sub(1));
                let here = self.entry(place);
                self.link(before, here)
            };
            for slot in 0..self.neighbours[point].len() {
                let (distance, other) = self.neighbours[point][slot];
                if distance >= current {
                    break;
                }
                if self.is_exit(other) != exit {
                    continue;
                }
                let there = self.position[other / 2];
                let (low, high) = (place.min(there), place.max(there));
                let (i, j) = if exit {
                    (low + 1, high)
                } else {
                    (low, high - 1)
                };
                if self.reverse_gain(i, j) > MIN_GAIN_M
                    && j - i < MAX_SPAN
                    && self.reversible(i..=j)
                {
                    self.work += j - i + 1;
                    self.sequence[i..=j].reverse();
                    for k in i..=j {
                        let o = &mut self.sequence[k];
                        o.reversed = !o.reversed;
                        self.position[o.stroke] = k;
                    }
                    return Some(self.strokes_at(&[
                        i.checked_sub(1),
                        Some(i),
                        Some(j),
                        Some(j + 1),
                    ]));
                }
            }
        }
        None
    }

    /// How much reversing the run `i..=j` shortens the travel.
    fn reverse_gain(&mut self, i: usize, j: usize) -> f64 {
        let before = self.exit(i.checked_sub(1));
        let after = self.entry(j + 1);
        let (first, last) = (self.entry(i), self.exit(Some(j)));
        let now = self.link(before, first) + self.link(last, after);
        let then = self.link(before, last) + self.link(first, after);
        now - then
    }

    /// An Or-opt move of the run of `run` strokes from `place` to between two strokes whose
    /// ends lie near the run's, either way round; the strokes whose links changed.
    fn or_opt_at(&mut self, place: usize, run: usize) -> Option<Vec<usize>> {
        let last = place + run - 1;
        if last >= self.sequence.len() {
            return None;
        }
        let (run_in, run_out) = (self.entry(place), self.exit(Some(last)));
        let before = self.exit(place.checked_sub(1));
        let after = self.entry(last + 1);
        let removed =
            self.link(before, run_in) + self.link(run_out, after) - self.link(before, after);
        if removed <= MIN_GAIN_M {
            return None;
        }
        let run_points = [
            2 * self.sequence[place].stroke + usize::from(self.sequence[place].reversed),
            2 * self.sequence[last].stroke + usize::from(!self.sequence[last].reversed),
        ];
        for (side, &point) in run_points.iter().enumerate() {
            for slot in 0..self.neighbours[point].len() {
                let other = self.neighbours[point][slot].1;
                let there = self.position[other / 2];
                if (place..=last).contains(&there) {
                    continue;
                }
                // After the stroke lifted near the run's end it joins, before the one set down
                // near it; flipped where the ends meeting are both entries or both exits.
                let other_exit = self.is_exit(other);
                let after_place = if other_exit {
                    Some(there)
                } else {
                    there.checked_sub(1)
                };
                let flipped = other_exit == (side == 1);
                // Just before the run or within it: where it is already.
                if after_place.map_or(place == 0, |a| a + 1 >= place && a <= last) {
                    continue;
                }
                let (into_in, into_out) = if flipped {
                    (run_out, run_in)
                } else {
                    (run_in, run_out)
                };
                let from = self.exit(after_place);
                let to = self.entry(after_place.map_or(0, |p| p + 1));
                let added =
                    self.link(from, into_in) + self.link(into_out, to) - self.link(from, to);
                if removed - added > MIN_GAIN_M && (!flipped || self.reversible(place..=last)) {
                    return self.shift_run(place, run, after_place, flipped);
                }
            }
        }
        None
    }

    /// Moves the run of `run` strokes at `place` to just after `after_place` (`None`: to the
    /// front), reversed where `flipped`, if it spans [`MAX_SPAN`] strokes at most; the strokes
    /// whose links changed.
    fn shift_run(
        &mut self,
        place: usize,
        run: usize,
        after_place: Option<usize>,
        flipped: bool,
    ) -> Option<Vec<usize>> {
        let (range, landed) = match after_place {
            Some(target) if target > place => (place..=target, target + 1 - run),
            target => {
                let first = target.map_or(0, |t| t + 1);
                (first..=place + run - 1, first)
            }
        };
        if range.end() - range.start() >= MAX_SPAN {
            return None;
        }
        let (start, end) = (*range.start(), *range.end());
        let mut touched = self.strokes_at(&[place.checked_sub(1), Some(place + run)]);
        if landed > place {
            self.sequence[range].rotate_left(run);
        } else {
            self.sequence[range].rotate_right(run);
        }
        if flipped {
            self.sequence[landed..landed + run].reverse();
            for o in &mut self.sequence[landed..landed + run] {
                o.reversed = !o.reversed;
            }
        }
        self.work += end - start + 1;
        for k in start..=end {
            self.position[self.sequence[k].stroke] = k;
        }
        touched.extend(self.strokes_at(&[
            landed.checked_sub(1),
            Some(landed),
            Some(landed + run - 1),
            Some(landed + run),
        ]));
        Some(touched)
    }
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
