//! The plan-strokes stage: each stroke of the order searched to the limit by the first planner
//! of the job's cascade that draws it whole (else the narrowest that draws the most), the way
//! that draws more, finished from its other end, a closed stroke started where it draws.

use emg_control::Path;
use emg_kinematics::{JointVector, Robot};
use emg_planner::{PlanRequest, Planner};
use rayon::prelude::*;

use crate::claims::{COVERAGE_SLACK_M, Coverage, Stretch};
use crate::free_space::FreeSpace;
use crate::measures::SAME_LENGTH_M;
use crate::order::Oriented;
use crate::spec::{JobSettings, Order};
use crate::stroke::{StrokePart, StrokePlan, finish_from_the_end, plan_stroke, reachable_start_s};
use crate::watch::{PlanningProgress, Stopped, Watch};

/// One stroke as the plan-strokes stage leaves it: drawn the way `oriented` says, planned as
/// `plan` by the cascade's planner `rank`.
#[derive(Clone, Debug)]
pub struct PlannedStroke {
    /// The stroke and the way it is drawn.
    pub oriented: Oriented,
    /// Its parts, as the search left them.
    pub plan: StrokePlan,
    /// The place in the job's cascade ([`cascade`]) of the planner that made `plan`.
    pub rank: usize,
}

/// The planners a job's strokes are tried with in turn, from `on_part` (the job's planner with
/// the part among its obstacles): where the arm has a `home` and joints that turn further than
/// a turn, those joints within each band of [`NEAR_HOME_BANDS_RAD`] about the home, narrowest
/// first; then their whole range (`on_part` itself, last).
pub(crate) fn cascade(on_part: Planner, home: Option<&JointVector>) -> Vec<Planner> {
    let mut planners: Vec<Planner> = home
        .iter()
        .flat_map(|home| {
            NEAR_HOME_BANDS_RAD
                .iter()
                .filter_map(|&band| on_part.within(home, band))
        })
        .collect();
    planners.push(on_part);
    planners
}

/// The plan-strokes stage: each stroke of `sequence` (among the `drawn` paths) planned as the
/// first planner of `cascade` that draws it whole plans it, else as the narrowest that draws
/// the most (to [`SAME_LENGTH_M`]), each part's tool able to lift off its start into `free`;
/// in parallel, the result independent of the number of threads. `watch` is told the planning
/// progress in stroke lengths.
pub(crate) fn plan_strokes(
    cascade: &[Planner],
    request: &PlanRequest,
    sequence: &[Oriented],
    drawn: &[Path],
    settings: &JobSettings,
    free: &FreeSpace,
    watch: &dyn Watch,
) -> Result<Vec<PlannedStroke>, Stopped> {
    let progress = PlanningProgress::new(watch, drawn.iter().map(Path::length_m));
    sequence
        .par_iter()
        .map(|&oriented| {
            let length = oriented.path(drawn).length_m();
            let stroke_progress = progress.stroke(length);
            let watch = &stroke_progress;
            let mut best: Option<PlannedStroke> = None;
            for (rank, planner) in cascade.iter().enumerate() {
                let (oriented, plan) =
                    planned_stroke(planner, request, oriented, drawn, settings, free, watch)?;
                let drawn_m = plan.planned_m();
                if best
                    .as_ref()
                    .is_none_or(|best| drawn_m > best.plan.planned_m() + SAME_LENGTH_M)
                {
                    best = Some(PlannedStroke {
                        oriented,
                        plan,
                        rank,
                    });
                }
                if drawn_m >= length - SAME_LENGTH_M {
                    break;
                }
            }
            stroke_progress.finish();
            Ok(best.expect("the cascade holds the whole range"))
        })
        .collect()
}

/// The bands (rad either side of the home) within which a job plans its strokes, narrowest
/// first, on the joints whose range exceeds a turn (the UR5e's): a quarter turn, then half a turn
/// less 2 mrad (a timed motion overshoots its planned configurations by a little and still lies
/// within ±π of the home); past them, the joints' whole range. The narrower band keeps a joint
/// that could sit on either of two branches (the wrist flipped or not) on the one nearer the
/// home, so neighbouring strokes share it.
pub const NEAR_HOME_BANDS_RAD: [f64; 2] =
    [std::f64::consts::FRAC_PI_2, std::f64::consts::PI - 2e-3];

/// The plan-strokes stage for one stroke, `oriented` among `drawn`: planned by `planner` as
/// `request` asks; in the shortest order also the other way where that draws more, finished
/// from its other end, and a closed stroke started where it can be drawn.
fn planned_stroke(
    planner: &Planner,
    request: &PlanRequest,
    oriented: Oriented,
    drawn: &[Path],
    settings: &JobSettings,
    free: &FreeSpace,
    watch: &dyn Watch,
) -> Result<(Oriented, StrokePlan), Stopped> {
    let plan = plan_stroke(
        planner,
        request,
        &oriented.path(drawn),
        0.0,
        settings,
        Some(free),
        watch,
    )?;
    match settings.order {
        Order::Shortest => {
            let (oriented, plan) = the_way_drawing_more((oriented, plan), drawn, |path| {
                plan_stroke(planner, request, path, 0.0, settings, Some(free), watch)
            })?;
            let plan = finish_from_the_end(planner, request, plan, settings, Some(free), watch)?;
            let plan = started_where_it_draws(plan, planner.robot(), |path| {
                let plan = plan_stroke(planner, request, path, 0.0, settings, Some(free), watch)?;
                finish_from_the_end(planner, request, plan, settings, Some(free), watch)
            })?;
            Ok((oriented, plan))
        }
        Order::Given => Ok((oriented, plan)),
    }
}

/// Starts a closed stroke none of whose parts draws anything is tried at: [`reachable_start_s`]
/// and as many more evenly spaced round the loop from it.
pub const CLOSED_STARTS: usize = 8;

/// `plan` of a closed stroke ([`Path::is_closed`]) whose start no part covers, started again
/// elsewhere on it (`replan`, both ends) where that draws more by [`SAME_LENGTH_M`], or as much
/// in fewer parts: a closed stroke may start anywhere, and one starting out of reach draws
/// little from either end. The new start is where the longest stretch no part covers ends (the
/// stretches either side of the start counted as one), so that one motion from there may draw
/// the rest; where no part covers any, the [`CLOSED_STARTS`] points from [`reachable_start_s`]
/// round the loop in turn, until one draws half the loop, the one that draws most kept. The
/// searches of all are counted.
fn started_where_it_draws(
    plan: StrokePlan,
    robot: &Robot,
    replan: impl Fn(&Path) -> Result<StrokePlan, Stopped>,
) -> Result<StrokePlan, Stopped> {
    let path = &plan.path.clone();
    let length = path.length_m();
    let stretches: Vec<Stretch> = plan.parts.iter().map(StrokePart::planned).collect();
    let undrawn = Coverage::of(length, &stretches).undrawn;
    let start_covered = stretches.iter().any(|s| s.from_s <= COVERAGE_SLACK_M);
    if !path.is_closed() || undrawn.is_empty() || start_covered {
        return Ok(plan);
    }
    let starts: Vec<f64> = match longest_gap_end_s(&undrawn, length) {
        Some(end_s) => vec![end_s],
        None => {
            let first = reachable_start_s(path, robot);
            (0..CLOSED_STARTS)
                .map(|k| (first + length * k as f64 / CLOSED_STARTS as f64) % length)
                .collect()
        }
    };
    let mut best = plan;
    for start_s in starts {
        let Some(rotated) = path.started_at(start_s) else {
            continue;
        };
        let mut other = replan(&rotated)?;
        let as_much = other.planned_m() >= best.planned_m() - SAME_LENGTH_M;
        if other.planned_m() >= best.planned_m() + SAME_LENGTH_M
            || (as_much && other.parts.len() < best.parts.len())
        {
            other.searches += best.searches;
            best = other;
        } else {
            best.searches += other.searches;
        }
        if best.planned_m() >= 0.5 * length {
            break;
        }
    }
    Ok(best)
}

/// Where the longest of the `undrawn` stretches of a closed stroke `length` long ends, the
/// stretch that ends at the stroke's end and the one that starts at its start counted as one
/// (the loop's seam lies within it); `None` where every stretch is undrawn (no part drew any).
fn longest_gap_end_s(undrawn: &[Stretch], length: f64) -> Option<f64> {
    let at_start = undrawn.first().filter(|gap| gap.from_s <= COVERAGE_SLACK_M);
    let at_end = undrawn
        .last()
        .filter(|gap| gap.to_s >= length - COVERAGE_SLACK_M);
    let across_seam = match (at_start, at_end) {
        (Some(first), Some(last)) if undrawn.len() > 1 => {
            Some((first.length_m() + last.length_m(), first.to_s))
        }
        _ => None,
    };
    let whole_loop = undrawn.len() == 1 && undrawn[0].length_m() >= length - COVERAGE_SLACK_M;
    let longest = undrawn
        .iter()
        .map(|gap| (gap.length_m(), gap.to_s % length))
        .chain(across_seam)
        .max_by(|a, b| a.0.total_cmp(&b.0))?;
    (!whole_loop).then_some(longest.1)
}

/// The stroke `planned` drawn the way that draws more: where its plan leaves some of it
/// undrawn and it may be reversed, it is planned the other way too (`plan`), and that way is
/// taken where it draws more by [`SAME_LENGTH_M`] or more; the searches of both are counted.
fn the_way_drawing_more(
    planned: (Oriented, StrokePlan),
    drawn: &[Path],
    plan: impl Fn(&Path) -> Result<StrokePlan, Stopped>,
) -> Result<(Oriented, StrokePlan), Stopped> {
    let (oriented, mut first) = planned;
    let whole = first.path.length_m() - SAME_LENGTH_M;
    let other = Oriented {
        reversed: !oriented.reversed,
        ..oriented
    };
    let Some(path) = (first.planned_m() < whole)
        .then(|| drawn[oriented.stroke].reversed().map(|_| other.path(drawn)))
        .flatten()
    else {
        return Ok((oriented, first));
    };
    let mut second = plan(&path)?;
    if second.planned_m() >= first.planned_m() + SAME_LENGTH_M {
        second.searches += first.searches;
        Ok((other, second))
    } else {
        first.searches += second.searches;
        Ok((oriented, first))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gap(from_s: f64, to_s: f64) -> Stretch {
        Stretch { from_s, to_s }
    }

    #[test]
    fn a_loop_starts_where_its_longest_gap_ends_the_seam_joining_two() {
        // The stretches either side of the seam make one gap 0.25 m long, longer than 0.2 m
        // in the middle.
        let undrawn = [gap(0.0, 0.12), gap(0.3, 0.5), gap(0.87, 1.0)];
        assert_eq!(longest_gap_end_s(&undrawn, 1.0), Some(0.12));
        let undrawn = [gap(0.0, 0.05), gap(0.3, 0.6), gap(0.95, 1.0)];
        assert_eq!(longest_gap_end_s(&undrawn, 1.0), Some(0.6));
        // A gap ending at the seam alone ends at the start.
        assert_eq!(longest_gap_end_s(&[gap(0.7, 1.0)], 1.0), Some(0.0));
        // Nothing covered: no gap ends anywhere.
        assert_eq!(longest_gap_end_s(&[gap(0.0, 1.0)], 1.0), None);
    }
}
