//! The choose-branches stage: on which of the arm's branches (the wrist flipped or not, the
//! elbow up or down, the base turned about) each stroke is drawn, chosen for the job as a whole.
//!
//! Each stroke's plan is found alone, and the connect stage carries the arm's branch from one
//! stroke to the next wherever the next can be drawn as far from it (a stand-in part planned
//! from where the arm is). Where it cannot, the branch changes: a slow pen-up move that may turn
//! a joint half a turn or more, onto a branch the strokes before could have shared, or off one
//! that the strokes after could have kept. At each such change in a connected program (the
//! parts on either side more than [`BRANCH_CHANGE_RAD`] apart on some joint), the branches known
//! about it (the arm's on either side of the change, and those of the strokes' own plans within
//! [`MAX_CARRIED_STROKES`] of it) are each carried to the strokes before and after them there:
//! each stroke planned again from where the one next to it leaves the arm, stroke by stroke as
//! long as it draws as far as its own plan (to [`crate::SAME_LENGTH_M`]) on a branch not yet
//! known for it. A shortest path over these candidates and the strokes as placed (dynamic
//! programming, exact) then picks one per stroke: the least estimated pen-up time of the whole
//! job, from the home and back to it, at the arm's limits. Every candidate draws as far as the
//! stroke's own plan, so the choice never draws less.

use emg_kinematics::JointVector;
use rayon::prelude::*;

use crate::measures::SAME_LENGTH_M;
use crate::plan_strokes::PlannedStroke;
use crate::stroke::StrokePlan;

/// Consecutive strokes placed further apart than this on some joint (rad, from the end of one
/// to the start of the next) lie on different branches: about a sixth of a turn, more than
/// neighbouring strokes of a drawing ask of one joint.
pub const BRANCH_CHANGE_RAD: f64 = 1.0;

/// How many strokes on either side of a branch change its branches are carried to at most.
pub const MAX_CARRIED_STROKES: usize = 8;

/// A stroke's plan and the place in the job's cascade of planners of the planner that made it.
type RankedPlan = (StrokePlan, usize);

/// What the stage asks of the job about its strokes' plans.
pub trait Branches: Sync {
    /// Where `plan` starts and ends, each configuration as the job will hold it (its joints
    /// among their whole turns nearest the home, the tool's free roll left out); `None` where
    /// it has no part.
    fn ends(&self, plan: &StrokePlan) -> Option<[JointVector; 2]>;

    /// `plan`'s stroke planned again by the cascade's planner `rank`, from the start that the
    /// arm reaches from `from` keeping its branch (its searches those of `plan`, which were run);
    /// `None` where it cannot be.
    fn carried(&self, plan: &StrokePlan, rank: usize, from: &JointVector) -> Option<StrokePlan>;

    /// The estimated time (s) the pen-up move from `from` to `to` takes.
    fn move_s(&self, from: &JointVector, to: &JointVector) -> f64;
}

/// A stroke's plan as the stage chose it.
#[derive(Clone, Debug)]
pub struct BranchChoice {
    /// The plan.
    pub plan: StrokePlan,
    /// The place in the job's cascade of planners of the planner that made it.
    pub rank: usize,
    /// Where it starts as the job holds it ([`Branches::ends`]), where it is on another branch
    /// than the stroke was placed on; `None` where the stroke keeps its place.
    pub moved_to: Option<JointVector>,
}

/// A candidate plan for one stroke, with where it starts and ends.
struct Candidate {
    plan: RankedPlan,
    ends: [JointVector; 2],
}

/// The plans to connect again for the planned `strokes` (in the order drawn; each planned by
/// the job's cascade's planner of its rank), connected once with their parts placed as
/// `placed` says (where each stroke's first part
/// starts and its last ends, as [`Branches::ends`] holds them; `None` where none was placed):
/// each stroke's branch chosen for the job as a whole (the module's description), the arm
/// starting and ending at `home` where it has one. `None` where no stroke changes branch.
/// Deterministic: the candidates are found in parallel but gathered in order, and ties keep the
/// strokes as placed.
pub fn choose_branches(
    strokes: &[PlannedStroke],
    placed: &[Option<[JointVector; 2]>],
    home: Option<&JointVector>,
    job: &impl Branches,
) -> Option<Vec<BranchChoice>> {
    // The strokes that have a part, in the order drawn: the others play no part in the choice.
    let drawn: Vec<usize> = (0..strokes.len())
        .filter(|&i| placed[i].is_some())
        .collect();
    let ends = |i: usize| placed[i].expect("a drawn stroke has ends");
    let changes: Vec<usize> = (1..drawn.len())
        .filter(|&k| apart(&ends(drawn[k - 1])[1], &ends(drawn[k])[0]) > BRANCH_CHANGE_RAD)
        .collect();
    if changes.is_empty() {
        return None;
    }
    // Per change, the branches known about it carried to the strokes about it.
    let carried: Vec<Vec<(usize, Candidate)>> = changes
        .par_iter()
        .map(|&k| carried_about(strokes, placed, &drawn, k, job))
        .collect();
    let mut others: Vec<Vec<Candidate>> = (0..strokes.len()).map(|_| Vec::new()).collect();
    for (stroke, candidate) in carried.into_iter().flatten() {
        others[stroke].push(candidate);
    }
    // Where each drawn stroke's candidates start and end: as placed first.
    let candidate_ends: Vec<Vec<[JointVector; 2]>> = drawn
        .iter()
        .map(|&stroke| {
            std::iter::once(ends(stroke))
                .chain(others[stroke].iter().map(|other| other.ends))
                .collect()
        })
        .collect();
    let picks = least_pen_up(&candidate_ends, home, |from, to| job.move_s(from, to));
    if picks.iter().all(|&pick| pick == 0) {
        return None;
    }
    let mut chosen: Vec<BranchChoice> = strokes
        .iter()
        .map(|stroke| BranchChoice {
            plan: stroke.plan.clone(),
            rank: stroke.rank,
            moved_to: None,
        })
        .collect();
    for (&stroke, pick) in drawn.iter().zip(picks) {
        if pick > 0 {
            let Candidate {
                plan: (plan, rank),
                ends: [start, _],
            } = others[stroke].swap_remove(pick - 1);
            chosen[stroke] = BranchChoice {
                plan,
                rank,
                moved_to: Some(start),
            };
        }
    }
    Some(chosen)
}

/// The largest difference of one joint between two configurations (rad).
fn apart(a: &JointVector, b: &JointVector) -> f64 {
    (a - b).amax()
}

/// Whether `ends` lies on another branch than each of `known` (more than
/// [`BRANCH_CHANGE_RAD`] from it at its start or its end).
fn new_branch(known: &[[JointVector; 2]], ends: &[JointVector; 2]) -> bool {
    known.iter().all(|other| {
        apart(&other[0], &ends[0]) > BRANCH_CHANGE_RAD
            || apart(&other[1], &ends[1]) > BRANCH_CHANGE_RAD
    })
}

/// The candidates for the strokes within [`MAX_CARRIED_STROKES`] of the branch change before
/// `drawn[k]` (`drawn`: the strokes placed, in the order drawn): the strokes' own plans where
/// they lie on another branch than placed, then each branch known there carried to the strokes
/// before and after it (the module's description). With the stroke each is for.
fn carried_about(
    strokes: &[PlannedStroke],
    placed: &[Option<[JointVector; 2]>],
    drawn: &[usize],
    k: usize,
    job: &impl Branches,
) -> Vec<(usize, Candidate)> {
    let window = k.saturating_sub(MAX_CARRIED_STROKES)..(k + MAX_CARRIED_STROKES).min(drawn.len());
    let placed_ends = |position: usize| placed[drawn[position]].expect("a drawn stroke has ends");
    // The branches known for each stroke of the window, as placed first.
    let mut known: Vec<Vec<[JointVector; 2]>> =
        window.clone().map(|p| vec![placed_ends(p)]).collect();
    let mut found: Vec<(usize, Candidate)> = Vec::new();
    // Each branch to carry: where it lies in the window, its ends there, the rank of its
    // planner, and whether it is carried back (to earlier strokes) and on (to later ones).
    let rank = |position: usize| strokes[drawn[position]].rank;
    let mut seeds = vec![
        (k, placed_ends(k), rank(k), true, false),
        (k - 1, placed_ends(k - 1), rank(k - 1), false, true),
    ];
    for position in window.clone() {
        let PlannedStroke {
            plan: own,
            rank: own_rank,
            ..
        } = &strokes[drawn[position]];
        let own_rank = *own_rank;
        let Some(ends) = job.ends(own) else {
            continue;
        };
        let slot = &mut known[position - window.start];
        if new_branch(slot, &ends) {
            slot.push(ends);
            let plan = (own.clone(), own_rank);
            found.push((drawn[position], Candidate { plan, ends }));
            seeds.push((position, ends, own_rank, true, true));
        }
    }
    // The stroke at `position` planned again from `from` on the branch of `rank`'s planner;
    // where it draws as far on a branch not known for it, kept: its ends.
    let mut extend = |position: usize, from: &JointVector, rank: usize| {
        let stroke = drawn[position];
        let own = &strokes[stroke].plan;
        let plan = job
            .carried(own, rank, from)
            .filter(|plan| plan.planned_m() >= own.planned_m() - SAME_LENGTH_M)?;
        let ends = job.ends(&plan)?;
        let slot = &mut known[position - window.start];
        if !new_branch(slot, &ends) {
            return None;
        }
        slot.push(ends);
        found.push((
            stroke,
            Candidate {
                plan: (plan, rank),
                ends,
            },
        ));
        Some(ends)
    };
    for (position, ends, rank, back, on) in seeds {
        if back {
            let mut from = ends[0];
            for earlier in (window.start..position).rev() {
                match extend(earlier, &from, rank) {
                    Some([start, _]) => from = start,
                    None => break,
                }
            }
        }
        if on {
            let mut from = ends[1];
            for later in position + 1..window.end {
                match extend(later, &from, rank) {
                    Some([_, end]) => from = end,
                    None => break,
                }
            }
        }
    }
    found
}

/// The candidate of each stroke (`candidates`: where each of a stroke's candidates starts and
/// ends, strokes in the order drawn, at least one each) on the way of least total estimated
/// pen-up time (`move_s` per move) from `home` through one candidate per stroke and back to
/// `home` (none where there is no home): the index into its candidates. Ties keep the lower
/// index.
fn least_pen_up(
    candidates: &[Vec<[JointVector; 2]>],
    home: Option<&JointVector>,
    move_s: impl Fn(&JointVector, &JointVector) -> f64,
) -> Vec<usize> {
    let Some(first) = candidates.first() else {
        return Vec::new();
    };
    // The least time to reach each candidate of the current stroke, and per stroke the
    // candidate of the stroke before on that way.
    let mut time: Vec<f64> = first
        .iter()
        .map(|[start, _]| home.map_or(0.0, |home| move_s(home, start)))
        .collect();
    let mut back: Vec<Vec<usize>> = vec![vec![0; first.len()]];
    for pair in candidates.windows(2) {
        let (before, here) = (&pair[0], &pair[1]);
        let (next_time, from): (Vec<f64>, Vec<usize>) = here
            .iter()
            .map(|[start, _]| {
                before
                    .iter()
                    .enumerate()
                    .map(|(b, [_, end])| (time[b] + move_s(end, start), b))
                    .fold((f64::INFINITY, 0), |best, next| {
                        if next.0 < best.0 { next } else { best }
                    })
            })
            .unzip();
        time = next_time;
        back.push(from);
    }
    let last = candidates.last().expect("there is a first stroke");
    let (mut pick, _) = last
        .iter()
        .enumerate()
        .map(|(c, [_, end])| (c, time[c] + home.map_or(0.0, |home| move_s(end, home))))
        .fold((0, f64::INFINITY), |best, next| {
            if next.1 < best.1 { next } else { best }
        });
    let mut choice = vec![0; candidates.len()];
    for k in (0..candidates.len()).rev() {
        choice[k] = pick;
        pick = back[k][pick];
    }
    choice
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The total time of one pick per stroke, home to home.
    fn total_s(
        candidates: &[Vec<[JointVector; 2]>],
        picks: &[usize],
        home: &JointVector,
        move_s: &impl Fn(&JointVector, &JointVector) -> f64,
    ) -> f64 {
        let ends: Vec<[JointVector; 2]> = picks
            .iter()
            .zip(candidates)
            .map(|(&pick, candidates)| candidates[pick])
            .collect();
        let inner: f64 = ends
            .windows(2)
            .map(|pair| move_s(&pair[0][1], &pair[1][0]))
            .sum();
        move_s(home, &ends[0][0]) + inner + move_s(&ends[ends.len() - 1][1], home)
    }

    #[test]
    fn the_least_pen_up_choice_is_the_best_of_every_choice() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        // The largest joint difference, as a move at one speed on every joint takes.
        let move_s = |from: &JointVector, to: &JointVector| apart(from, to);
        let home = JointVector::zeros();
        for _ in 0..50 {
            let strokes = rng.random_range(1..6);
            let candidates: Vec<Vec<[JointVector; 2]>> = (0..strokes)
                .map(|_| {
                    (0..rng.random_range(1..4))
                        .map(|_| {
                            let start = JointVector::from_fn(|_, _| rng.random_range(-3.0..3.0));
                            let end = start.map(|q| q + rng.random_range(-0.3..0.3));
                            [start, end]
                        })
                        .collect()
                })
                .collect();
            let picks = least_pen_up(&candidates, Some(&home), move_s);
            // Every choice, enumerated.
            let mut best = f64::INFINITY;
            let mut choice = vec![0; strokes];
            loop {
                best = best.min(total_s(&candidates, &choice, &home, &move_s));
                let Some(k) = (0..strokes).find(|&k| choice[k] + 1 < candidates[k].len()) else {
                    break;
                };
                choice[k] += 1;
                choice[..k].iter_mut().for_each(|c| *c = 0);
            }
            let found = total_s(&candidates, &picks, &home, &move_s);
            assert!((found - best).abs() < 1e-12, "{found} against {best}");
        }
    }
}
