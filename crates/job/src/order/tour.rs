//! Local search over a sequence of strokes: 2-opt moves (a run of strokes reversed, each
//! stroke's direction with it) and Or-opt moves (a run of up to [`MAX_RUN`] strokes moved
//! elsewhere, either way round) among each stroke end's near ends, spanning [`MAX_SPAN`]
//! strokes at most, each stroke looked at [`MAX_ROUNDS`] times at most on average. What a move
//! shortens is the sum of the [`Legs`]' costs: the pen-up travel for the order stage, the
//! estimated pen-up time for the reorder stage (`crate::reorder`).

use std::collections::VecDeque;

use super::oriented::Oriented;

/// Strokes a move shifts or reverses at most.
pub const MAX_SPAN: usize = 1000;

/// Strokes an Or-opt move takes at most.
pub const MAX_RUN: usize = 3;

/// Times each stroke is looked at for a move, on average, at most.
pub const MAX_ROUNDS: usize = 50;

/// The pen-up moves between strokes, each with a cost a [`Tour`] shortens the sum of. A stroke
/// end is a point: 2i is stroke i's start, 2i + 1 its end.
pub trait Legs {
    /// The cost of the move from stroke end `from`, where a stroke is lifted, to stroke end
    /// `to`, where the next is set down; `None` for `from` is the sequence's start, for `to`
    /// its end.
    fn cost(&self, from: Option<usize>, to: Option<usize>) -> f64;

    /// Whether stroke `stroke` may be drawn reversed.
    fn reversible(&self, stroke: usize) -> bool;
}

/// A sequence of strokes being improved by moves among near ends.
pub struct Tour<'a, L: Legs> {
    legs: &'a L,
    /// The strokes in the order they are drawn, each in its direction.
    pub sequence: Vec<Oriented>,
    /// Each stroke's place in `sequence`.
    position: Vec<usize>,
    /// Each stroke end's near ends of other strokes, least costly first, with the cost of the
    /// move between them.
    neighbours: Vec<Vec<(f64, usize)>>,
    /// Costs computed, strokes looked at and strokes shifted so far.
    pub work: usize,
}

/// Gains smaller than this (in the legs' cost) are not taken.
const MIN_GAIN: f64 = 1e-12;

impl<'a, L: Legs> Tour<'a, L> {
    /// `sequence`, a permutation of every stroke of `legs`, to be improved by moves among each
    /// stroke end's `neighbours` (point 2i is stroke i's start, 2i + 1 its end; each list the
    /// ends of other strokes, least costly first, with their costs).
    pub fn new(legs: &'a L, sequence: Vec<Oriented>, neighbours: Vec<Vec<(f64, usize)>>) -> Self {
        let mut position = vec![0; sequence.len()];
        for (place, oriented) in sequence.iter().enumerate() {
            position[oriented.stroke] = place;
        }
        Self {
            legs,
            sequence,
            position,
            neighbours,
            work: 0,
        }
    }

    /// The sum of the costs of the sequence's legs, the sequence's start and end included.
    pub fn cost(&self) -> f64 {
        let n = self.sequence.len();
        (0..=n)
            .map(|place| {
                self.legs
                    .cost(self.exit(place.checked_sub(1)), self.entry(place))
            })
            .fold(0.0, |total, leg| total + leg)
    }

    /// Where the stroke at `place` is set down (`None` past the sequence's end).
    fn entry(&self, place: usize) -> Option<usize> {
        let oriented = self.sequence.get(place)?;
        Some(2 * oriented.stroke + usize::from(oriented.reversed))
    }

    /// Where the stroke at `place` is lifted (`None` before the sequence's start).
    fn exit(&self, place: Option<usize>) -> Option<usize> {
        let oriented = self.sequence.get(place?)?;
        Some(2 * oriented.stroke + usize::from(!oriented.reversed))
    }

    /// The cost of the move from `from` to `to` (`None`: the sequence's start or end).
    fn link(&mut self, from: Option<usize>, to: Option<usize>) -> f64 {
        self.work += 1;
        self.legs.cost(from, to)
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
            .all(|o| self.legs.reversible(o.stroke))
    }

    /// Moves until none among near ends lowers the cost, or the rounds are spent.
    pub fn improve(&mut self) {
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

    /// The first move found at the stroke at `place` that lowers the cost, made; the
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
    /// its entry and another's entry, less costly than the link it has; the strokes whose links
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
                let (cost, other) = self.neighbours[point][slot];
                if cost >= current {
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
                if self.reverse_gain(i, j) > MIN_GAIN && j - i < MAX_SPAN && self.reversible(i..=j)
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

    /// How much reversing the run `i..=j` lowers the cost.
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
        if removed <= MIN_GAIN {
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
                if removed - added > MIN_GAIN && (!flipped || self.reversible(place..=last)) {
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
