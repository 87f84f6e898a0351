//! Strokes that meet end to end merged into one (as vpype's `linemerge` does): each drawn
//! stroke joins a chain of the job's strokes, each one after the last moved onto its end
//! ([`Path::joined`]) by the gap between them, the gaps of a chain adding up to the job's line
//! tolerance at most, so every point of the job's strokes lies within it of the stroke drawn.
//! Strokes join only where the drawn stroke turns by [`MAX_JOIN_TURN_DEG`] at most: one that
//! doubles back on itself is drawn as two.

use emg_control::Path;
use serde::{Deserialize, Serialize};

use super::near::Grid;
use super::oriented::Oriented;
use crate::spec::Order;

/// The sharpest turn (degrees) where two merged strokes join.
pub const MAX_JOIN_TURN_DEG: f64 = 90.0;

/// The job's strokes one drawn stroke joins end to end, in order along it, each in its
/// direction.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Chain(pub Vec<Oriented>);

impl Chain {
    /// The drawn stroke: the chain's strokes of `strokes` (the job's) joined, or `None` where
    /// two of them do not join ([`Path::joined`]).
    pub fn path(&self, strokes: &[Path]) -> Option<Path> {
        let (first, rest) = self.0.split_first()?;
        rest.iter().try_fold(first.path(strokes), |joined, next| {
            joined.joined(&next.path(strokes))
        })
    }
}

/// The drawn strokes of `strokes` (the job's) at `tolerance_m`, with the work the search
/// counted ([`Grid::work`]). Each chain grows from its first stroke (in the job's order) at its
/// end, then, where every stroke of it may be reversed, at its start: by the nearest free end of
/// another stroke within the tolerance the chain has left (a start, or an end where that stroke
/// may be reversed) that turns by [`MAX_JOIN_TURN_DEG`] at most. In the given order ([`Order::Given`]) a stroke joins only the one listed
/// before it, end to start. A chain whose strokes do not join is cut where they do not.
pub fn merge_strokes(
    strokes: &[Path],
    order: Order,
    tolerance_m: f64,
) -> (Vec<(Chain, Path)>, usize) {
    let reversible: Vec<bool> = strokes.iter().map(|s| s.reversed().is_some()).collect();
    let (chains, work) = match order {
        Order::Given => (listed_chains(strokes, tolerance_m), strokes.len()),
        Order::Shortest => nearest_chains(strokes, &reversible, tolerance_m),
    };
    let drawn = chains
        .into_iter()
        .flat_map(|chain| joined(chain, strokes))
        .collect();
    (drawn, work)
}

/// Runs of listed strokes each starting where the one before it ends, within the tolerance.
fn listed_chains(strokes: &[Path], tolerance_m: f64) -> Vec<Vec<Oriented>> {
    let mut chains: Vec<Vec<Oriented>> = Vec::new();
    let mut left_m = 0.0;
    for (stroke, path) in strokes.iter().enumerate() {
        let oriented = Oriented {
            stroke,
            reversed: false,
        };
        let gap = stroke
            .checked_sub(1)
            .map(|before| (path.point_at(0.0) - end_of(&strokes[before])).norm());
        match (gap, chains.last_mut()) {
            (Some(gap), Some(chain))
                if gap <= left_m && turns_gently(strokes, chain[chain.len() - 1], oriented) =>
            {
                left_m -= gap;
                chain.push(oriented);
            }
            _ => {
                left_m = tolerance_m;
                chains.push(vec![oriented]);
            }
        }
    }
    chains
}

/// Chains grown by the nearest free stroke ends (see [`merge_strokes`]).
fn nearest_chains(
    strokes: &[Path],
    reversible: &[bool],
    tolerance_m: f64,
) -> (Vec<Vec<Oriented>>, usize) {
    // Point 2i is stroke i's start, 2i + 1 its end.
    let mut grid = Grid::new(
        strokes
            .iter()
            .flat_map(|path| [path.point_at(0.0), end_of(path)])
            .collect(),
    );
    let mut chains = Vec::new();
    for first in 0..strokes.len() {
        if !grid.contains(2 * first) {
            continue;
        }
        grid.remove(2 * first);
        grid.remove(2 * first + 1);
        let mut chain = vec![Oriented {
            stroke: first,
            reversed: false,
        }];
        let mut left_m = tolerance_m;
        // Whether the chain is turned round to grow at its start.
        let mut turned = false;
        for side in 0..2 {
            if side == 1 {
                if !chain.iter().all(|o| reversible[o.stroke]) {
                    break;
                }
                turn_round(&mut chain);
                turned = true;
            }
            loop {
                let last = chain[chain.len() - 1];
                let at = grid.point(2 * last.stroke + usize::from(!last.reversed));
                let accept = |point: usize| {
                    let next = Oriented {
                        stroke: point / 2,
                        reversed: !point.is_multiple_of(2),
                    };
                    (!next.reversed || reversible[next.stroke]) && turns_gently(strokes, last, next)
                };
                let Some(&(gap, point)) = grid.nearest(at, 1, left_m, accept).first() else {
                    break;
                };
                left_m -= gap;
                grid.remove(point);
                grid.remove(point ^ 1);
                chain.push(Oriented {
                    stroke: point / 2,
                    reversed: point % 2 == 1,
                });
            }
        }
        // Back the way the first stroke is given: a stroke that merges with none keeps its
        // direction.
        if turned {
            turn_round(&mut chain);
        }
        chains.push(chain);
    }
    (chains, grid.work())
}

/// `chain` drawn the other way: its strokes in reverse order, each reversed.
fn turn_round(chain: &mut [Oriented]) {
    chain.reverse();
    for o in chain.iter_mut() {
        o.reversed = !o.reversed;
    }
}

/// `chain`'s drawn strokes: one where its strokes join, else cut where they do not.
fn joined(chain: Vec<Oriented>, strokes: &[Path]) -> Vec<(Chain, Path)> {
    let mut drawn: Vec<(Chain, Path)> = Vec::new();
    for oriented in chain {
        let path = oriented.path(strokes);
        let grown = drawn.last_mut().and_then(|(chain, joined)| {
            let longer = joined.joined(&path)?;
            chain.0.push(oriented);
            *joined = longer;
            Some(())
        });
        if grown.is_none() {
            drawn.push((Chain(vec![oriented]), path));
        }
    }
    drawn
}

/// Whether `next` drawn after `last` (both of `strokes`) turns by [`MAX_JOIN_TURN_DEG`] at
/// most where they join.
fn turns_gently(strokes: &[Path], last: Oriented, next: Oriented) -> bool {
    // The direction the drawn stroke takes at its start (or end).
    let tangent = |o: Oriented, at_start: bool| {
        let path = &strokes[o.stroke];
        let s = if at_start != o.reversed {
            0.0
        } else {
            path.length_m()
        };
        let along = path.tangent_at(s);
        if o.reversed { -along } else { along }
    };
    // A turn of the limit to rounding counts as within it.
    tangent(last, false).dot(&tangent(next, true))
        >= libm::cos(MAX_JOIN_TURN_DEG.to_radians()) - 1e-12
}

/// The end point of `path`.
fn end_of(path: &Path) -> emg_kinematics::Vec3 {
    path.point_at(path.length_m())
}
