//! The plan-strokes stage: each stroke planned by the search to the limit; where the arm cannot
//! finish it in one motion, the rest is planned again from where it stopped (the tool set down
//! a little behind, after a reconfiguration in free space), as often as that gains length; what
//! is left at its end may be planned from the other end back ([`finish_from_the_end`]).

use emg_control::{ARRIVAL_M, Path, Task, Termination, Trajectory};
use emg_kinematics::Robot;
use emg_planner::{PlanRequest, Planner};

use crate::claims::{Coverage, OnStroke, Stretch};
use crate::shortfall::{Shortfall, Stop};
use crate::spec::JobSettings;
use crate::watch::{Stopped, Watch};

/// One motion along a stretch of a stroke.
#[derive(Clone, Debug)]
pub struct StrokePart {
    /// Arc length of the stroke where the part's stretch starts (m).
    pub from_s: f64,
    /// Whether the part runs from `from_s` back toward the stroke's start (drawn from the
    /// stroke's other end, [`finish_from_the_end`]).
    pub backward: bool,
    /// The task of the stretch, as planned.
    pub task: Task,
    /// The planned motion along it.
    pub trajectory: Trajectory,
}

impl StrokePart {
    /// Where the part's task lies on the stroke.
    pub fn on_stroke(&self) -> OnStroke {
        OnStroke {
            from_s: self.from_s,
            backward: self.backward,
        }
    }

    /// Arc length of the stroke the part reaches (m).
    pub fn reached_s(&self) -> f64 {
        self.on_stroke().stroke_s(self.trajectory.path_length_m)
    }

    /// The stretch of the stroke the part covers as planned.
    pub fn planned(&self) -> Stretch {
        self.on_stroke().stretch(0.0, self.trajectory.path_length_m)
    }
}

/// A stroke planned in one or more parts.
#[derive(Clone, Debug)]
pub struct StrokePlan {
    /// The stroke as drawn (reversed where the order says so).
    pub path: Path,
    /// The parts, in order along the stroke.
    pub parts: Vec<StrokePart>,
    /// Searches run (parts planned, those that gained nothing included).
    pub searches: usize,
    /// Where along the stroke the searches stopped because `settings.max_parts` of them were
    /// spent before its end: past it the stroke was not searched. `None` where they reached
    /// the end.
    pub unsearched_from_s: Option<f64>,
    /// Where each search that ended short of the stroke's end ended, and why, in the order
    /// searched.
    pub stops: Vec<Stop>,
}

impl StrokePlan {
    /// The length of the stroke its parts cover as planned, from where each starts to where it
    /// reaches, overlaps counted once (m).
    pub fn planned_m(&self) -> f64 {
        let stretches: Vec<Stretch> = self.parts.iter().map(StrokePart::planned).collect();
        Coverage::of(self.path.length_m(), &stretches).drawn_m
    }

    /// How far along the stroke its forward parts reach (m; 0 with none).
    fn forward_reach_s(&self) -> f64 {
        self.parts
            .iter()
            .filter(|part| !part.backward)
            .map(StrokePart::reached_s)
            .fold(0.0, f64::max)
    }
}

/// Plans `path` with `planner` as `request` asks (the search): from `start_s` along it, then
/// from where each part stopped (`settings.overlap_m` back), while a part gains at least
/// `settings.min_gain_m`; a stretch where no motion starts or gains is skipped by
/// `settings.min_gain_m`, up to `settings.max_parts` searches (a part that stopped only at the
/// rollout's step cap, the arm still able to go on, is not counted); [`Stopped`] where `watch`
/// asks to stop (asked before each search and between a search's rollouts).
pub fn plan_stroke(
    planner: &Planner,
    request: &PlanRequest,
    path: &Path,
    start_s: f64,
    settings: &JobSettings,
    watch: &dyn Watch,
) -> Result<StrokePlan, Stopped> {
    let length = path.length_m();
    let mut plan = StrokePlan {
        path: path.clone(),
        parts: Vec::new(),
        searches: 0,
        unsearched_from_s: None,
        stops: Vec::new(),
    };
    // How far the stroke is drawn or given up.
    let mut done = start_s;
    // The searches counted against `settings.max_parts`.
    let mut counted = 0;
    // How far along the stroke a search looks: twice what one rollout can draw at most (its
    // step cap at the commanded speed), so a long stroke is not scanned beyond any use.
    let rollout = &planner.config().rollout;
    let searched_m = 2.0 * rollout.max_steps as f64 * rollout.dt_s * rollout.speed_m_per_s;
    let unfinished = |done: f64| done < length - 2.0 * ARRIVAL_M;
    while unfinished(done) {
        if counted == settings.max_parts {
            plan.unsearched_from_s = Some(done);
            break;
        }
        if watch.stop_requested() {
            return Err(Stopped);
        }
        plan.searches += 1;
        let from_s = if plan.parts.is_empty() {
            done
        } else {
            (done - settings.overlap_m).max(0.0)
        };
        let part = match path.stretch(from_s, length.min(from_s + searched_m)) {
            None => Err("the stretch is too short to follow".to_string()),
            Some(stretch) => Task::on_path(planner.robot(), stretch, None)
                .map_err(|error| error.to_string())
                .and_then(|task| {
                    let planned = planner
                        .plan_until(&task, request, &|| watch.stop_requested())
                        .map_err(|error| error.to_string())?;
                    Ok(StrokePart {
                        from_s,
                        backward: false,
                        task,
                        trajectory: planned.trajectory,
                    })
                }),
        };
        // A search ended by the stop request is not the search's plan: nothing of it is kept.
        if watch.stop_requested() {
            return Err(Stopped);
        }
        let part = match part {
            Ok(part) => {
                let stop = Stop::of_motion(part.reached_s(), &part.trajectory.termination);
                plan.stops.extend(stop);
                Some(part)
            }
            Err(why) => {
                plan.stops.push(Stop {
                    at_s: done,
                    why: Shortfall::NoStart { why },
                });
                None
            }
        };
        let gained = part
            .as_ref()
            .filter(|part| {
                !matches!(
                    part.trajectory.termination,
                    Termination::InvalidStart { .. }
                )
            })
            .map_or(0.0, |part| part.reached_s() - done);
        let before = done;
        match part {
            Some(part) if gained >= settings.min_gain_m || completes(&part, length) => {
                done = part.reached_s();
                if part.trajectory.termination != Termination::StepCap {
                    counted += 1;
                }
                plan.parts.push(part);
            }
            _ => {
                counted += 1;
                done = (done + settings.min_gain_m).min(length);
            }
        }
        watch.searched(done - before);
    }
    Ok(plan)
}

/// `plan` finished from its stroke's other end: where its forward parts stop short of the end by
/// more than `settings.min_gain_m`, the stretch from there (`settings.overlap_m` back) to the
/// end is planned from the end back ([`plan_stroke`] on the reversed stretch), and its parts
/// are added as backward parts: the two sides meet where both reach. Its searches are counted;
/// the plan is left as it is where that stretch cannot be reversed.
pub fn finish_from_the_end(
    planner: &Planner,
    request: &PlanRequest,
    mut plan: StrokePlan,
    settings: &JobSettings,
    watch: &dyn Watch,
) -> Result<StrokePlan, Stopped> {
    let length = plan.path.length_m();
    let reached = plan.forward_reach_s();
    if reached >= length - settings.min_gain_m {
        return Ok(plan);
    }
    let from = (reached - settings.overlap_m).max(0.0);
    let Some(back) = plan.path.stretch(from, length).and_then(|s| s.reversed()) else {
        return Ok(plan);
    };
    let back_plan = plan_stroke(planner, request, &back, 0.0, settings, watch)?;
    plan.searches += back_plan.searches;
    if back_plan.unsearched_from_s.is_none() {
        plan.unsearched_from_s = None;
    }
    // A part `from_s` along the reversed stretch starts `length − from_s` along the stroke.
    plan.stops
        .extend(back_plan.stops.into_iter().map(|stop| Stop {
            at_s: length - stop.at_s,
            ..stop
        }));
    plan.parts
        .extend(back_plan.parts.into_iter().map(|part| StrokePart {
            from_s: length - part.from_s,
            backward: true,
            ..part
        }));
    Ok(plan)
}

/// Where a closed stroke none of whose parts can start is started instead: its point nearest
/// the centre of the arm's reach sphere (sampled every 5 mm), the likeliest to be reached.
pub fn reachable_start_s(path: &Path, robot: &Robot) -> f64 {
    let (centre, _) = robot.reach_sphere();
    let length = path.length_m();
    let away = |s: f64| (path.point_at(s) - centre).norm();
    let samples = (length / 0.005).ceil().max(1.0) as usize;
    (0..samples)
        .map(|k| length * k as f64 / samples as f64)
        .min_by(|a, b| away(*a).total_cmp(&away(*b)))
        .unwrap_or(0.0)
}

/// Whether a part ends at the stroke's end.
fn completes(part: &StrokePart, length: f64) -> bool {
    part.trajectory.termination == Termination::Completed
        || part.reached_s() >= length - 2.0 * ARRIVAL_M
}
