//! The plan-strokes stage: each stroke planned by the search to the limit; where the arm cannot
//! finish it in one motion, the rest is planned again from where it stopped (the tool set down
//! a little behind, after a reconfiguration in free space), as often as that gains length; what
//! is left at its end may be planned from the other end back ([`finish_from_the_end`]).

use emg_control::{ARRIVAL_M, Path, Task, Termination, Trajectory};
use emg_kinematics::Robot;
use emg_planner::{PlanRequest, Planner};

use crate::claims::{Coverage, OnStroke, Stretch};
use crate::free_space::FreeSpace;
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
}

/// Plans `path` with `planner` as `request` asks (the search): from `start_s` along it, then
/// from where each part stopped (`settings.overlap_m` back), while a part gains at least
/// `settings.min_gain_m`, up to `settings.max_parts` parts that stop short (a part that stopped
/// only at the rollout's step cap, the arm still able to go on, is not counted). Where no
/// motion starts or gains, the stretch is skipped by `settings.min_gain_m`, doubled for each
/// search in a row that gained nothing after the first [`EVEN_SKIPS`] (such searches are not
/// counted), so the searches a stroke gets grow with what is left of it and a stretch out of
/// reach costs a number of searches that grows with the logarithm of its length. Where `free`
/// is given, a part whose tool cannot lift off its start into it ([`FreeSpace::lifted`]) gains
/// nothing: the connect stage could not set the tool down there. [`Stopped`] where `watch` asks
/// to stop (asked before each search and between a search's rollouts).
pub fn plan_stroke(
    planner: &Planner,
    request: &PlanRequest,
    path: &Path,
    start_s: f64,
    settings: &JobSettings,
    free: Option<&FreeSpace>,
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
    // The parts counted against `settings.max_parts`.
    let mut counted = 0;
    // Searches in a row that gained nothing.
    let mut fruitless = 0;
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
        let part = part.and_then(|part| match free {
            Some(free) if starts(&part) && !lifts_off(free, &part, settings.lift()) => {
                Err(FreeSpace::cannot_lift(settings.lift(), "start"))
            }
            _ => Ok(part),
        });
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
            .filter(|part| starts(part))
            .map_or(0.0, |part| part.reached_s() - done);
        let before = done;
        match part {
            Some(part) if gained >= settings.min_gain_m || completes(&part, length) => {
                done = part.reached_s();
                if part.trajectory.termination != Termination::StepCap {
                    counted += 1;
                }
                fruitless = 0;
                plan.parts.push(part);
            }
            _ => {
                done = (done + fruitless_skip_m(settings.min_gain_m, fruitless)).min(length);
                fruitless += 1;
            }
        }
        watch.searched(done - before);
    }
    Ok(plan)
}

/// `plan` finished from the far side of each gap its forward parts leave (a stretch they do not
/// cover, longer than `settings.min_gain_m`, the one up to the stroke's end included): the
/// stretch from the gap's start (`settings.overlap_m` back) to its end is planned from its end
/// back ([`plan_stroke`] on the reversed stretch), and its parts are added as backward parts
/// (those that start past the gap's start by more than `settings.min_gain_m`): the two sides of
/// each gap meet where both reach. Their searches are counted; a gap whose stretch cannot be
/// reversed is left as it is.
pub fn finish_from_the_end(
    planner: &Planner,
    request: &PlanRequest,
    mut plan: StrokePlan,
    settings: &JobSettings,
    free: Option<&FreeSpace>,
    watch: &dyn Watch,
) -> Result<StrokePlan, Stopped> {
    let length = plan.path.length_m();
    let forward: Vec<Stretch> = plan
        .parts
        .iter()
        .filter(|part| !part.backward)
        .map(StrokePart::planned)
        .collect();
    let gaps = Coverage::of(length, &forward).undrawn;
    for gap in gaps
        .iter()
        .filter(|gap| gap.length_m() > settings.min_gain_m)
    {
        let from = (gap.from_s - settings.overlap_m).max(0.0);
        let Some(back) = plan.path.stretch(from, gap.to_s).and_then(|s| s.reversed()) else {
            continue;
        };
        let back_plan = plan_stroke(planner, request, &back, 0.0, settings, free, watch)?;
        plan.searches += back_plan.searches;
        let unsearched_here = plan
            .unsearched_from_s
            .is_some_and(|s| (gap.from_s..=gap.to_s).contains(&s));
        if unsearched_here && back_plan.unsearched_from_s.is_none() {
            plan.unsearched_from_s = None;
        }
        // A part `from_s` along the reversed stretch starts `gap.to_s − from_s` along the stroke.
        plan.stops
            .extend(back_plan.stops.into_iter().map(|stop| Stop {
                at_s: gap.to_s - stop.at_s,
                ..stop
            }));
        // A part that starts no further than `settings.min_gain_m` into the gap draws only what
        // the forward parts draw (the searches from the gap's end skipped there over a stretch
        // out of reach): it is not kept.
        plan.parts.extend(
            back_plan
                .parts
                .into_iter()
                .map(|part| StrokePart {
                    from_s: gap.to_s - part.from_s,
                    backward: true,
                    ..part
                })
                .filter(|part| part.from_s > gap.from_s + settings.min_gain_m),
        );
    }
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

/// Searches in a row that gain nothing before the skip starts to double: a gap up to this many
/// times `settings.min_gain_m` long is crossed at that step (with 3, the motions that start
/// within a gap of a few centimetres near the edge of the reach were skipped over: place-eval's
/// pencil drew 5 mm less).
const EVEN_SKIPS: usize = 6;

/// How far a search that gained nothing skips along the stroke (m), after `before` searches in
/// a row that gained nothing: `min_gain_m` for the first [`EVEN_SKIPS`], then doubled each
/// time, so that a stretch out of reach `L` long costs about `log2(L / min_gain_m)` searches.
fn fruitless_skip_m(min_gain_m: f64, before: usize) -> f64 {
    let doublings = before.saturating_sub(EVEN_SKIPS - 1).min(60);
    min_gain_m * 2f64.powi(doublings as i32)
}

/// Whether the motion of `part` starts (its start keeps every constraint).
fn starts(part: &StrokePart) -> bool {
    !matches!(
        part.trajectory.termination,
        Termination::InvalidStart { .. }
    )
}

/// Whether the tool of `part` can lift off the part's start into `free` (`lift_m` or a share).
fn lifts_off(free: &FreeSpace, part: &StrokePart, lift_m: f64) -> bool {
    part.trajectory
        .steps
        .first()
        .is_some_and(|step| free.lifted(&step.q, &-part.task.n, lift_m).is_some())
}

/// Whether a part ends at the stroke's end.
fn completes(part: &StrokePart, length: f64) -> bool {
    part.trajectory.termination == Termination::Completed
        || part.reached_s() >= length - 2.0 * ARRIVAL_M
}
