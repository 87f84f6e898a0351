//! The choose-branches stage: on which of the arm's branches (the wrist flipped or not, the
//! elbow up or down, the base turned about) each stroke is drawn, chosen for the job as a whole.
//!
//! Each stroke's plan is found alone, and two neighbouring strokes may be planned on different
//! branches: one that the next stroke cannot be drawn whole on, say. The arm then changes
//! branch between them, a slow pen-up move that may turn a joint half a turn or more. Where
//! consecutive plans lie on different branches (a joint more than [`BRANCH_CHANGE_RAD`] apart),
//! the strokes before the change are planned again carried over from the branch after it, and
//! those after it from the branch before it, stroke by stroke as long as each is drawn as far
//! as its own plan (to [`crate::SAME_LENGTH_M`]), up to [`MAX_CARRIED_STROKES`] each way. A
//! shortest path over these candidates (dynamic programming, exact) then picks one plan per
//! stroke: the least estimated pen-up time of the whole job, from the home and back to it, at
//! the arm's limits. Every candidate draws as far as the stroke's own plan, so the choice never
//! draws less.

use emg_kinematics::JointVector;
use rayon::prelude::*;

use crate::SAME_LENGTH_M;
use crate::stroke::StrokePlan;

/// Consecutive strokes whose plans lie further apart than this on some joint (rad, from the
/// end of one to the start of the next) count as planned on different branches: about a sixth
/// of a turn, more than neighbouring strokes of a drawing ask of one joint.
pub const BRANCH_CHANGE_RAD: f64 = 1.0;

/// How many strokes on each side of a branch change are planned again on the other side's
/// branch at most.
pub const MAX_CARRIED_STROKES: usize = 16;

/// A stroke's plan and the place in the job's cascade of planners of the planner that made it.
pub type RankedPlan = (StrokePlan, usize);

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

/// A candidate plan for one stroke, with where it starts and ends.
struct Candidate {
    plan: RankedPlan,
    ends: [JointVector; 2],
}

/// `planned` (one plan per stroke, in the order drawn) with each stroke's branch chosen for the
/// job as a whole (the module's description), the arm starting and ending at `home` where it
/// has one; with how many strokes were planned again. Deterministic: the candidates are found
/// in parallel but gathered in order, and ties keep the stroke's own plan.
pub fn choose_branches(
    planned: Vec<RankedPlan>,
    home: Option<&JointVector>,
    job: &impl Branches,
) -> (Vec<RankedPlan>, usize) {
    let ends: Vec<Option<[JointVector; 2]>> =
        planned.par_iter().map(|(plan, _)| job.ends(plan)).collect();
    // The strokes that have a part, in the order drawn: the others play no part in the choice.
    let drawn: Vec<usize> = (0..planned.len()).filter(|&i| ends[i].is_some()).collect();
    let end = |i: usize| ends[i].expect("a drawn stroke has ends");
    let changes: Vec<usize> = (1..drawn.len())
        .filter(|&k| apart(&end(drawn[k - 1])[1], &end(drawn[k])[0]) > BRANCH_CHANGE_RAD)
        .collect();
    if changes.is_empty() {
        return (planned, 0);
    }
    // Per change, the strokes before it carried over from the branch after it, then those after
    // it from the branch before it.
    let carried: Vec<Vec<(usize, Candidate)>> = changes
        .par_iter()
        .map(|&k| {
            let before = drawn[..k].iter().rev().take(MAX_CARRIED_STROKES);
            let after = drawn[k..].iter().take(MAX_CARRIED_STROKES);
            let mut found = carry(&planned, &ends, before, drawn[k], Side::Before, job);
            found.extend(carry(
                &planned,
                &ends,
                after,
                drawn[k - 1],
                Side::After,
                job,
            ));
            found
        })
        .collect();
    let mut candidates: Vec<Vec<Candidate>> = planned
        .iter()
        .zip(&ends)
        .map(|(plan, ends)| {
            ends.iter()
                .map(|ends| Candidate {
                    plan: plan.clone(),
                    ends: *ends,
                })
                .collect()
        })
        .collect();
    let mut replanned = 0;
    for (stroke, candidate) in carried.into_iter().flatten() {
        candidates[stroke].push(candidate);
        replanned += 1;
    }
    let choice = least_pen_up(&drawn, &candidates, home, job);
    let mut chosen: Vec<RankedPlan> = planned;
    for (&stroke, pick) in drawn.iter().zip(choice) {
        if pick > 0 {
            let Candidate { plan, .. } = candidates[stroke].swap_remove(pick);
            chosen[stroke] = plan;
        }
    }
    (chosen, replanned)
}

/// The largest difference of one joint between two configurations (rad).
fn apart(a: &JointVector, b: &JointVector) -> f64 {
    (a - b).amax()
}

/// Which side of a branch change strokes are carried to.
#[derive(Clone, Copy)]
enum Side {
    /// The strokes drawn before it, from the one just before back: each planned from where
    /// the stroke after it starts.
    Before,
    /// The strokes drawn after it, from the one just after on: each planned from where the
    /// stroke before it ends.
    After,
}

impl Side {
    /// Where a plan with `ends` leaves the arm for the next stroke carried to this side.
    fn seed(self, ends: &[JointVector; 2]) -> JointVector {
        match self {
            Self::Before => ends[0],
            Self::After => ends[1],
        }
    }
}

/// The strokes `strokes` on `side` of a branch change (in the order they are carried to, away
/// from it) planned again one after another by the planner of stroke `across` (the stroke on
/// the change's other side), each from where the one before leaves the arm, the first from
/// where `across`'s plan does: as long as each draws as far as the stroke's own plan and lies
/// on another branch than it.
fn carry<'a>(
    planned: &[RankedPlan],
    ends: &[Option<[JointVector; 2]>],
    strokes: impl Iterator<Item = &'a usize>,
    across: usize,
    side: Side,
    job: &impl Branches,
) -> Vec<(usize, Candidate)> {
    let rank = planned[across].1;
    let mut from = side.seed(&ends[across].expect("a drawn stroke has ends"));
    let mut found = Vec::new();
    for &stroke in strokes {
        let (own, _) = &planned[stroke];
        let own_ends = ends[stroke].expect("a drawn stroke has ends");
        let Some(plan) = job
            .carried(own, rank, &from)
            .filter(|plan| plan.planned_m() >= own.planned_m() - SAME_LENGTH_M)
        else {
            break;
        };
        let Some(plan_ends) = job.ends(&plan) else {
            break;
        };
        let same_branch = apart(&plan_ends[0], &own_ends[0]) <= BRANCH_CHANGE_RAD
            && apart(&plan_ends[1], &own_ends[1]) <= BRANCH_CHANGE_RAD;
        if same_branch {
            break;
        }
        from = side.seed(&plan_ends);
        found.push((
            stroke,
            Candidate {
                plan: (plan, rank),
                ends: plan_ends,
            },
        ));
    }
    found
}

/// The candidate of each drawn stroke (`drawn`, in order) on the path of least total
/// estimated pen-up time from `home` through one candidate per stroke and back to `home`
/// (none where there is no home): the index into its candidates. Ties keep the lower index.
fn least_pen_up(
    drawn: &[usize],
    candidates: &[Vec<Candidate>],
    home: Option<&JointVector>,
    job: &impl Branches,
) -> Vec<usize> {
    // The least time to reach each candidate of the current stroke, and the candidate of the
    // stroke before on that way.
    let mut time: Vec<f64> = Vec::new();
    let mut back: Vec<Vec<usize>> = Vec::with_capacity(drawn.len());
    for (k, &stroke) in drawn.iter().enumerate() {
        let here = &candidates[stroke];
        let (next_time, from): (Vec<f64>, Vec<usize>) = match k {
            0 => here
                .iter()
                .map(|c| (home.map_or(0.0, |home| job.move_s(home, &c.ends[0])), 0))
                .unzip(),
            _ => {
                let before = &candidates[drawn[k - 1]];
                here.iter()
                    .map(|c| {
                        before
                            .iter()
                            .enumerate()
                            .map(|(b, previous)| {
                                (time[b] + job.move_s(&previous.ends[1], &c.ends[0]), b)
                            })
                            .fold((f64::INFINITY, 0), |best, next| {
                                if next.0 < best.0 { next } else { best }
                            })
                    })
                    .unzip()
            }
        };
        time = next_time;
        back.push(from);
    }
    let last = &candidates[*drawn.last().expect("a branch change has drawn strokes")];
    let (mut pick, _) = last
        .iter()
        .enumerate()
        .map(|(c, candidate)| {
            let home_s = home.map_or(0.0, |home| job.move_s(&candidate.ends[1], home));
            (c, time[c] + home_s)
        })
        .fold((0, f64::INFINITY), |best, next| {
            if next.1 < best.1 { next } else { best }
        });
    let mut choice = vec![0; drawn.len()];
    for k in (0..drawn.len()).rev() {
        choice[k] = pick;
        pick = back[k][pick];
    }
    choice
}
