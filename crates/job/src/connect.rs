//! The connect stage: a job's planned strokes placed one after another into one program, from
//! the home and back to it. Each part is timed, lifted at both ends and joined to the last by a
//! free pen-up move ([`connector`]); a part that cannot be placed is planned again by the next
//! planner of the cascade, and a part placed short of its plan is resumed where it stops.

mod connector;
mod least;

use std::collections::VecDeque;

use emg_kinematics::JointVector;
use emg_planner::{PlanRequest, Planner};
use emg_timing::{DynamicLimits, least_move_s};

use crate::branch::Branches;
use crate::claims::{COVERAGE_SLACK_M, Coverage, Stretch, part_coverage};
use crate::free_space::FreeSpace;
use crate::measures::SAME_LENGTH_M;
use crate::order::Oriented;
use crate::plan_strokes::PlannedStroke;
use crate::program::{Program, SegmentKind, StrokeReport};
use crate::shortfall::{self, LeftOut, Shortfall, Stop};
use crate::stroke::{StrokePart, StrokePlan, plan_stroke};
use crate::watch::{Stopped, Watch};

pub(crate) use connector::Connector;
use connector::Placed;
pub use connector::{
    BLEND_SHARE, CLEARANCE_LIFT_M, HOP_BLEND_SHARE, HOP_RISE, MAX_HELD_UP_DEPTH, MAX_HOP_RISE_LIFTS,
};
use least::LeastDuration;

/// How far (rad) from the home's roll the tool's roll joint is held: a quarter turn.
pub const ROLL_FROM_HOME_RAD: f64 = std::f64::consts::FRAC_PI_2;

/// A job's strokes in the order drawn, and the program connecting them: what the connect,
/// reorder and choose-branches stages hand on.
pub(crate) struct Connected {
    /// The strokes, in the order drawn.
    pub strokes: Vec<PlannedStroke>,
    /// The program joining them.
    pub connection: Connection,
}

impl Connected {
    /// Whether this program draws as much as `other` (to [`SAME_LENGTH_M`]) in less time.
    pub fn is_better_than(&self, other: &Connected) -> bool {
        let drawn = |c: &Connected| c.connection.reports.iter().map(|r| r.drawn_m).sum::<f64>();
        drawn(self) >= drawn(other) - SAME_LENGTH_M
            && self.connection.program.duration_s() < other.connection.program.duration_s()
    }
}

/// The program joining a job's strokes, with what it draws of each.
pub(crate) struct Connection {
    /// The program.
    pub program: Program,
    /// One per stroke, in the order drawn.
    pub reports: Vec<StrokeReport>,
    /// Pen-up moves whose edges are straight, and those the sampling planner found a stretch of.
    pub moves: (usize, usize),
    /// Searches run: the strokes' plans' and the rest plans'.
    pub searches: usize,
    /// The least duration the arm's limits allow for the same parts: pen down, pen up (s).
    pub least: (f64, f64),
    /// Whether the program ends at the home.
    pub ends_at_home: bool,
    /// Where each stroke's first placed part starts and its last ends, as the job holds them
    /// ([`JobBranches::held`]); `None` where none was placed.
    pub placed_ends: Vec<Option<[JointVector; 2]>>,
}

/// The connect stage: `strokes` placed one after another into one program, from the home and
/// back to it; where a stroke's plan was carried over to another branch (`moved_to`: where it
/// starts), the stroke before it ends the way nearest it. `watch` is told the strokes connected
/// as `stage`.
pub(crate) fn connect_strokes(
    branches: &JobBranches<'_>,
    strokes: Vec<PlannedStroke>,
    moved_to: &[Option<JointVector>],
    watch: &dyn Watch,
    stage: &str,
) -> Result<Connected, Stopped> {
    let mut joining = Joining::new(branches, &strokes);
    for (connected, stroke) in strokes.iter().enumerate() {
        if watch.stop_requested() {
            return Err(Stopped);
        }
        watch.progress(stage, connected, strokes.len());
        let next_moved_to = moved_to.get(connected + 1).copied().flatten();
        joining.stroke(stroke, next_moved_to, watch)?;
    }
    Ok(Connected {
        strokes,
        connection: joining.home(),
    })
}

/// The program as the connect stage builds it, stroke by stroke.
struct Joining<'a> {
    branches: &'a JobBranches<'a>,
    home: Option<JointVector>,
    program: Program,
    reports: Vec<StrokeReport>,
    placed_ends: Vec<Option<[JointVector; 2]>>,
    least: LeastDuration<'a>,
    /// Pen-up moves whose edges are straight, and those sampled.
    moves: (usize, usize),
    searches: usize,
    /// The last part's lift, joined to the move after it.
    retreat: Option<[JointVector; 2]>,
}

/// One stroke as the connect stage works through its parts.
struct StrokeJoining {
    /// The stroke's planner's place in the cascade.
    rank: usize,
    /// The parts still to place.
    queue: VecDeque<StrokePart>,
    /// The next part's index.
    next_index: usize,
    /// The rest plans run after a part that could not be placed or stopped short.
    rest_plans: usize,
    unsearched_from_s: Option<f64>,
    /// Where the stroke's searches stopped short.
    stops: Vec<Stop>,
    /// The parts left out, and why, in words.
    parts_left_out: Vec<String>,
    left_out: Vec<LeftOut>,
    /// The stretches of the stroke the placed parts' samples cover.
    covered: Vec<Stretch>,
    /// Where the stroke's first placed part starts and its last ends.
    ends: Option<[JointVector; 2]>,
}

impl<'a> Joining<'a> {
    fn new(branches: &'a JobBranches<'a>, strokes: &[PlannedStroke]) -> Self {
        let home = branches.home.copied();
        Self {
            branches,
            home,
            program: Program::default(),
            reports: Vec::new(),
            placed_ends: Vec::with_capacity(strokes.len()),
            least: LeastDuration::new(branches.connector.timing.request(), home),
            moves: (0, 0),
            searches: strokes.iter().map(|stroke| stroke.plan.searches).sum(),
            retreat: None,
        }
    }

    fn connector(&self) -> &'a Connector<'a> {
        self.branches.connector
    }

    /// Places the parts of `stroke` (the next stroke starting where `next_moved_to` says, if
    /// its plan was carried to another branch) and reports what they draw.
    fn stroke(
        &mut self,
        stroke: &PlannedStroke,
        next_moved_to: Option<JointVector>,
        watch: &dyn Watch,
    ) -> Result<(), Stopped> {
        let plan = &stroke.plan;
        let mut joining = StrokeJoining {
            rank: stroke.rank,
            queue: plan.parts.iter().cloned().collect(),
            next_index: 0,
            rest_plans: 0,
            unsearched_from_s: plan.unsearched_from_s,
            stops: plan.stops.clone(),
            parts_left_out: Vec::new(),
            left_out: Vec::new(),
            covered: Vec::new(),
            ends: None,
        };
        while let Some(planned) = joining.queue.pop_front() {
            self.part(&mut joining, stroke, planned, next_moved_to, watch)?;
        }
        self.placed_ends.push(
            joining
                .ends
                .map(|ends| ends.map(|q| self.branches.held(&q))),
        );
        self.reports.push(joining.report(stroke.oriented, plan));
        Ok(())
    }

    /// Places one part of `stroke` where it can be, planned again from where the arm is where
    /// that draws as far nearer it; where it cannot, by the next planner of the cascade; where
    /// it draws less than planned or its timed motion is cut short, the rest of the stroke
    /// planned again from where it stops. The parts from the stroke's other end still follow.
    fn part(
        &mut self,
        joining: &mut StrokeJoining,
        stroke: &PlannedStroke,
        planned: StrokePart,
        next_moved_to: Option<JointVector>,
        watch: &dyn Watch,
    ) -> Result<(), Stopped> {
        let connector = self.connector();
        let (settings, cascade) = (connector.settings, self.branches.cascade);
        let index = joining.next_index;
        joining.next_index += 1;
        let from = self.retreat.map(|[_, above]| above).or(self.program.last());
        let from = from.or(self.home);
        let (planned, candidates) = self.candidates(joining, planned, from, next_moved_to);
        let seed = settings
            .seed
            .wrapping_add(self.program.segments().len() as u64);
        let placed = self.place_first(&candidates, from, seed);
        // A timed motion cut before the end it was planned to (a timed sample left the
        // tolerance, `emg_planner::MotionTiming::time`) is resumed from where its samples stop,
        // as a stand-in that draws less is.
        let (resume_s, placed) = match placed {
            Ok((part, placed)) => {
                let robot = connector.free.robot();
                let samples = placed.timed.samples.iter().map(|sample| &sample.q);
                let drawn = part_coverage(robot, &part.task, part.on_stroke(), samples);
                let short = part.trajectory.path_length_m
                    < planned.trajectory.path_length_m - SAME_LENGTH_M;
                let reached_s = part.reached_s().min(drawn.to_s);
                let cut = reached_s < part.reached_s() - COVERAGE_SLACK_M;
                let resume_s = (reached_s - settings.overlap_m).max(part.from_s);
                (
                    (short || cut).then_some(resume_s),
                    Some((part, placed, drawn)),
                )
            }
            Err(why) => {
                let again = joining.rank + 1 < cascade.len()
                    && !planned.backward
                    && joining.rest_plans < settings.max_parts;
                if again {
                    joining.rank += 1;
                } else {
                    joining.parts_left_out.push(format!("part {index}: {why}"));
                    joining.left_out.push(LeftOut {
                        planned: planned.planned(),
                        why,
                    });
                }
                (again.then_some(planned.from_s), None)
            }
        };
        if let Some(resume_s) = resume_s.filter(|_| !planned.backward)
            && joining.rest_plans < settings.max_parts
        {
            self.plan_rest(joining, &stroke.plan, resume_s, watch)?;
        }
        if let Some((part, placed, stretch)) = placed {
            self.append(joining, stroke.oriented, index, part, placed, stretch);
        }
        Ok(())
    }

    /// The parts that may draw `planned`'s stretch from `from`, where the arm is, in the order
    /// they are tried ([`ranked`]), with `planned` moved toward the home ([`toward`]): itself,
    /// and the part planned again from `from` and from the home, each moved above the part's
    /// start and set down there.
    fn candidates(
        &self,
        joining: &StrokeJoining,
        planned: StrokePart,
        from: Option<JointVector>,
        next_moved_to: Option<JointVector>,
    ) -> (StrokePart, Vec<StrokePart>) {
        let connector = self.connector();
        let free = connector.free;
        let home = self.home;
        let planner = &self.branches.cascade[joining.rank];
        let request = self.branches.request;
        let planned = toward(planned, home.as_ref(), from.as_ref(), free);
        let again: Vec<StrokePart> = [from, home]
            .iter()
            .flatten()
            .filter_map(|start| connector.replanned_nearby(planner, request, &planned, start))
            .map(|part| toward(part, home.as_ref(), from.as_ref(), free))
            .collect();
        // Where the arm goes after the stroke's last part, where the next stroke was carried
        // over to another branch.
        let next = next_moved_to.filter(|_| joining.queue.is_empty());
        let next = next
            .as_ref()
            .map(|next| (next, |q: &JointVector| self.branches.held(q)));
        let limits = &connector.timing.request().limits;
        let candidates = ranked(planned.clone(), again, from.as_ref(), next, limits);
        (planned, candidates)
    }

    /// The first of `candidates` placed from `from` ([`Connector::place`]), else why the first
    /// one could not be.
    fn place_first(
        &self,
        candidates: &[StrokePart],
        from: Option<JointVector>,
        seed: u64,
    ) -> Result<(StrokePart, Placed), Shortfall> {
        let connector = self.connector();
        let robot = connector.free.robot();
        // The way the tool rose off the last part, which it may rise further along.
        let risen = self.retreat.and_then(|[end, above]| {
            (robot.forward(&above).tcp() - robot.forward(&end).tcp()).try_normalize(1e-12)
        });
        let mut first_why = None;
        for part in candidates {
            match connector.place(part, from.map(|from| (from, risen)), seed) {
                Ok(done) => return Ok(done),
                Err(why) => {
                    first_why.get_or_insert(why);
                }
            }
        }
        Err(first_why.expect("the searched part is a candidate"))
    }

    /// The rest of the stroke of `plan` planned again from `resume_s` by the stroke's planner,
    /// in place of the parts still queued from its start (those from its other end kept).
    fn plan_rest(
        &mut self,
        joining: &mut StrokeJoining,
        plan: &StrokePlan,
        resume_s: f64,
        watch: &dyn Watch,
    ) -> Result<(), Stopped> {
        joining.rest_plans += 1;
        let rest = plan_stroke(
            &self.branches.cascade[joining.rank],
            self.branches.request,
            &plan.path,
            resume_s,
            self.connector().settings,
            Some(self.connector().free),
            watch,
        )?;
        self.searches += rest.searches;
        joining.unsearched_from_s = rest.unsearched_from_s;
        joining.stops.extend(rest.stops);
        let backward: Vec<StrokePart> = joining.queue.drain(..).filter(|p| p.backward).collect();
        joining.queue = rest.parts.into_iter().chain(backward).collect();
        Ok(())
    }

    /// Appends the pen-up move to `part` and `part` itself (the `index`th of its stroke, its
    /// samples drawing `stretch`) to the program.
    fn append(
        &mut self,
        joining: &mut StrokeJoining,
        oriented: Oriented,
        index: usize,
        part: StrokePart,
        placed: Placed,
        stretch: Stretch,
    ) {
        let Placed {
            timed,
            above_start,
            above_end,
            travel,
            sampled,
        } = placed;
        let dof = self.connector().free.robot().dof();
        let (start, end) = (timed.samples[0].q, timed.samples[timed.samples.len() - 1].q);
        match (travel.is_empty(), sampled) {
            (true, _) => {}
            (false, false) => self.moves.0 += 1,
            (false, true) => self.moves.1 += 1,
        }
        // Without a home the program begins above the first stroke.
        self.connector().join(
            &mut self.program,
            self.retreat.take(),
            &travel,
            Some([above_start, start]),
            dof,
        );
        self.program.append(
            SegmentKind::Stroke {
                stroke: oriented.stroke,
                part: index,
                from_s: part.from_s,
                backward: part.backward,
            },
            &timed.definition,
            &timed.samples,
            Some(&part.task),
            dof,
        );
        self.least
            .add_stroke(above_start, start, end, stretch.length_m());
        joining.ends = Some([joining.ends.map_or(start, |[first, _]| first), end]);
        joining.covered.push(stretch);
        self.retreat = Some([end, above_end]);
    }

    /// The program ended by the move back to the home, where there is one and a free move
    /// reaches it.
    fn home(mut self) -> Connection {
        let connector = self.connector();
        let settings = connector.settings;
        let last = self.retreat.map(|[_, above]| above).or(self.program.last());
        let home_travel = self.home.zip(last).and_then(|(home, last)| {
            connector.home_move(&last, &home, settings.seed.wrapping_add(u64::MAX / 2))
        });
        let dof = connector.free.robot().dof();
        connector.join(
            &mut self.program,
            self.retreat.take(),
            home_travel.as_deref().unwrap_or_default(),
            None,
            dof,
        );
        self.least.end_at(self.program.last());
        Connection {
            program: self.program,
            reports: self.reports,
            moves: self.moves,
            searches: self.searches,
            least: (self.least.pen_down_s, self.least.pen_up_s),
            ends_at_home: home_travel.is_some(),
            placed_ends: self.placed_ends,
        }
    }
}

impl StrokeJoining {
    /// What the placed parts of the stroke `oriented`, planned as `plan`, draw of it, and why
    /// the rest is not drawn.
    fn report(self, oriented: Oriented, plan: &StrokePlan) -> StrokeReport {
        let length_m = plan.path.length_m();
        let coverage = Coverage::of(length_m, &self.covered);
        let (unreached, unreached_causes) = shortfall::undrawn_causes(
            &coverage.undrawn,
            &self.stops,
            &self.left_out,
            self.unsearched_from_s,
        )
        .into_iter()
        .unzip::<_, _, Vec<_>, Vec<_>>();
        StrokeReport {
            stroke: oriented.stroke,
            reversed: oriented.reversed,
            path: plan.path.spec().clone(),
            length_m,
            drawn_m: coverage.drawn_m,
            parts: self.covered.len(),
            unreached_at: unreached
                .iter()
                .map(|u: &Stretch| plan.path.point_at(u.from_s).into())
                .collect(),
            unreached,
            unreached_causes,
            parts_left_out: self.parts_left_out,
            unsearched_from_s: self.unsearched_from_s,
        }
    }
}

/// `part` moved without changing what it draws, toward `home` (else `from`, where the arm is):
/// each joint turned by whole turns ([`emg_kinematics::JointLimits::turns_toward`]), the same
/// motion of the arm with its joint values nearest the reference within the limits; then the
/// tool's roll joint, where the arm has one ([`emg_kinematics::Robot::tool_roll_joint`]), held
/// still at the roll the arm is at (`from`'s, else the home's), within
/// [`ROLL_FROM_HOME_RAD`] of the home's and the limits: no roll to move while drawing or
/// between strokes. The TCP and the tool axis, all a stroke constrains, do not depend on the
/// roll, so the part draws exactly as before. Where the held roll is not free (`free`'s test
/// along the motion: the tool's bodies turn with it), the part's roll is turned as a whole to
/// start there instead, and where that is not free either, it is kept.
fn toward(
    mut part: StrokePart,
    home: Option<&JointVector>,
    from: Option<&JointVector>,
    free: &FreeSpace,
) -> StrokePart {
    let Some(reference) = home.or(from) else {
        return part;
    };
    let robot = free.robot();
    let motion: Vec<JointVector> = part.trajectory.steps.iter().map(|step| step.q).collect();
    let shift = robot.limits().turns_toward(&motion, reference);
    let mut turned: Vec<JointVector> = motion.iter().map(|q| q + shift).collect();
    if let Some(roll) = robot.tool_roll_joint() {
        let limits = robot.limits();
        let (mut lower, mut upper) = (limits.lower[roll], limits.upper[roll]);
        if let Some(home) = home {
            lower = lower.max(home[roll] - ROLL_FROM_HOME_RAD);
            upper = upper.min(home[roll] + ROLL_FROM_HOME_RAD);
        }
        let wanted = from.unwrap_or(reference)[roll].clamp(lower, upper);
        let held: Vec<JointVector> = turned
            .iter()
            .map(|q| {
                let mut q = *q;
                q[roll] = wanted;
                q
            })
            .collect();
        let (least, greatest) = turned
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                (lo.min(q[roll]), hi.max(q[roll]))
            });
        let turn = (wanted - turned[0][roll])
            .min(upper - greatest)
            .max(lower - least)
            .min(limits.upper[roll] - greatest)
            .max(limits.lower[roll] - least);
        let rolled: Vec<JointVector> = turned
            .iter()
            .map(|q| {
                let mut q = *q;
                q[roll] += turn;
                q
            })
            .collect();
        if free.path_free(&held) {
            turned = held;
        } else if turn.abs() > 0.0 && free.path_free(&rolled) {
            turned = rolled;
        }
    }
    for (step, q) in part.trajectory.steps.iter_mut().zip(turned) {
        step.q = q;
    }
    part
}

/// The parts that may draw a stretch, in the order they are tried: those drawing as far as the
/// searched part `planned` (to [`SAME_LENGTH_M`]), the one with the least pen-up time first
/// ([`least_move_s`] within `limits` from `from`, where the arm is, to the part's start, and
/// where the part is its stroke's last before a stroke the branch choice moved, from its end as
/// `next` holds it to `next`'s configuration, that stroke's start); then the others, the
/// furthest-drawing first.
/// Deterministic: ties keep the order given, `planned` first.
fn ranked(
    planned: StrokePart,
    again: Vec<StrokePart>,
    from: Option<&JointVector>,
    next: Option<(&JointVector, impl Fn(&JointVector) -> JointVector)>,
    limits: &DynamicLimits,
) -> Vec<StrokePart> {
    // Every candidate starts where the searched part does: the longer draws further.
    let reach = planned.trajectory.path_length_m;
    let as_far = |part: &StrokePart| part.trajectory.path_length_m >= reach - SAME_LENGTH_M;
    let time_from = |part: &StrokePart| {
        let steps = &part.trajectory.steps;
        let to_start = from.map_or(0.0, |from| least_move_s(from, &steps[0].q, limits));
        let onward = next.as_ref().map_or(0.0, |(next, held)| {
            least_move_s(&held(&steps[steps.len() - 1].q), next, limits)
        });
        to_start + onward
    };
    let mut candidates: Vec<StrokePart> = std::iter::once(planned).chain(again).collect();
    candidates.sort_by(|a, b| {
        as_far(b).cmp(&as_far(a)).then_with(|| match as_far(a) {
            true => time_from(a).total_cmp(&time_from(b)),
            false => b
                .trajectory
                .path_length_m
                .total_cmp(&a.trajectory.path_length_m),
        })
    });
    candidates
}

/// The job as the choose-branches stage ([`branch`]) sees it.
pub(crate) struct JobBranches<'a> {
    /// Places the parts.
    pub connector: &'a Connector<'a>,
    /// The planners a stroke is tried with, by rank.
    pub cascade: &'a [Planner],
    /// What the search is asked.
    pub request: &'a PlanRequest,
    /// Where the arm starts and ends, if anywhere.
    pub home: Option<&'a JointVector>,
}

impl JobBranches<'_> {
    /// `q` as the job holds it: each joint among its whole turns nearest the home (where there
    /// is one), the tool's free roll, which the job holds still, left out (0).
    pub fn held(&self, q: &JointVector) -> JointVector {
        let robot = self.connector.free.robot();
        let mut held = match self.home {
            Some(home) => q + robot.limits().turns_toward(std::slice::from_ref(q), home),
            None => *q,
        };
        if let Some(roll) = robot.tool_roll_joint() {
            held[roll] = 0.0;
        }
        held
    }
}

impl Branches for JobBranches<'_> {
    fn ends(&self, plan: &StrokePlan) -> Option<[JointVector; 2]> {
        let first = plan.parts.first()?.trajectory.steps.first()?;
        let last = plan.parts.last()?.trajectory.steps.last()?;
        Some([self.held(&first.q), self.held(&last.q)])
    }

    fn carried(&self, plan: &StrokePlan, rank: usize, from: &JointVector) -> Option<StrokePlan> {
        let first = plan
            .parts
            .first()
            .filter(|part| part.from_s == 0.0 && !part.backward)?;
        let part =
            self.connector
                .replanned_nearby(&self.cascade[rank], self.request, first, from)?;
        let stops = Stop::of_motion(part.reached_s(), &part.trajectory.termination);
        Some(StrokePlan {
            path: plan.path.clone(),
            parts: vec![part],
            searches: plan.searches,
            unsearched_from_s: None,
            stops: stops.into_iter().collect(),
        })
    }

    fn move_s(&self, from: &JointVector, to: &JointVector) -> f64 {
        least_move_s(from, to, &self.connector.timing.request().limits)
    }
}
