//! Jobs: a drawing or a set of seams planned as one program a robot runs. A job is planned in
//! stages with one job each, above the planner:
//!
//! 1. **read** ([`spec`]): a job file or a drawing's strokes, validated into a [`Job`];
//! 2. **order** ([`order`]): strokes that meet end to end merged ([`order::merge`]), the
//!    drawing order and directions that shorten the pen-up travel;
//! 3. **plan strokes** ([`stroke`]): each stroke to the limit by the search, resumed after a
//!    reconfiguration where one motion cannot finish it;
//! 4. **connect** ([`free_space`]): retreat along −n, a collision-free joint-space move,
//!    approach along n;
//! 5. **reorder** ([`reorder`]): where the order stage chose the order, runs of strokes moved
//!    to lower the estimated pen-up time between their planned configurations, not the travel,
//!    and the strokes connected again in that order;
//! 6. **choose branches** ([`branch`]): where the arm changes branch between strokes, the
//!    branches known there carried to the strokes around, one plan per stroke by the least
//!    pen-up time of the whole job, and the strokes connected again where that is quicker; in
//!    both orders, the quicker program kept;
//! 7. **time** and **write** ([`program`]): one rest-to-rest joint trajectory (a pen-up move
//!    blended through its corners where that stays free), every segment with its time span, as
//!    an `emg-job/3` file;
//!
//! and [`verify_job`] re-checks a written program with the independent checker.
//!
//! [`plan_job`] runs them in order; [`place_job`] runs it at the best places for the part.

pub mod branch;
pub mod claims;
pub mod demo_jobs;
pub mod free_space;
pub mod motion;
pub mod order;
pub mod page;
pub mod place;
pub mod program;
pub mod reorder;
pub mod shortfall;
pub mod spec;
pub mod stroke;
pub mod tolerance;
pub mod tool_output;
pub mod ur_program;
pub mod verify;
pub mod watch;

use std::collections::VecDeque;
use std::time::Instant;

use emg_control::Path;
use emg_kinematics::{JointVector, Robot, Vec3};
use emg_planner::{
    DEFAULT_RATE_HZ, MotionTiming, PlanRequest, Planner, PlannerConfig, TimingSetupError,
};
use emg_timing::{DynamicLimits, least_move_s, time_blended_move};
use rayon::prelude::*;

pub use branch::{BRANCH_CHANGE_RAD, BranchChoice, Branches, MAX_CARRIED_STROKES, choose_branches};
pub use claims::{COVERAGE_SLACK_M, Coverage, OnStroke, Stretch, part_coverage};
pub use demo_jobs::valley_seams;
pub use free_space::{
    FreeSpace, LIFT_CONE_RUN, MAX_POINT_TRAVEL_M, PART, PEN_UP_CLEARANCE_SHARE, job_part,
    part_surfaces, with_part,
};
pub use motion::Motion;
pub use order::merge::{Chain, merge_strokes};
pub use order::{Ordering, Oriented, merge_and_order, order_strokes, order_strokes_counted};
pub use page::{placement_map, viewer_page};
pub use place::{
    Certified, Moving, Place, PlaceError, PlaceFrame, PlaceSettings, Placement, Region, RegionEdge,
    SAME_SCORE, Score, Scored, place_job, place_score,
};
pub use program::{
    JOB_FILE_FORMAT, JobFile, JobFileError, JobSummary, MAX_PROGRAM_S, Program, Segment,
    SegmentKind, StrokeReport,
};
pub use reorder::{MIN_SAVED_S, in_order, reorder_by_move_time};
pub use shortfall::{LeftOut, Shortfall, Stop};
pub use spec::{JOB_FORMAT_VERSION, Job, JobError, JobSettings, JobSpec, Order, Tool, Transform};
pub use stroke::{StrokePart, StrokePlan, finish_from_the_end, plan_stroke, reachable_start_s};
pub use tolerance::DrawingTolerance;
pub use tool_output::{OutputBank, ToolOutput};
pub use verify::{JobCheck, JobCheckError, verify_job};
use watch::PlanningProgress;
pub use watch::{Stopped, StopsWith, Unwatched, Watch};

/// Pen-down lengths closer than this (m) count as the same: of two starts of a stroke that draw
/// as far, the nearer one to the arm is taken; places that draw as much rank by duration.
pub const SAME_LENGTH_M: f64 = 1e-3;

/// A job's line tolerance unless it is given another (m): what a pen, a bead or a seam needs.
pub const JOB_TOLERANCE_M: f64 = 5e-4;

/// The planner configuration a job plans with: `emg plan`'s ([`PlannerConfig::cell`]: the work
/// plate, the corrected step) at `tolerance_m`.
pub fn job_config(tolerance_m: f64) -> PlannerConfig {
    let mut config = PlannerConfig::cell();
    config.rollout.constraints.line_tolerance_m = tolerance_m;
    config
}

/// The timing of a job's program for `robot` read from `robot_file`, as `emg job` times it:
/// the limits file beside the robot file (else assumed ones), unscaled, the tool at the
/// configuration's speed, sampled at [`DEFAULT_RATE_HZ`].
pub fn job_timing(
    robot: &emg_kinematics::Robot,
    robot_file: &std::path::Path,
    config: &PlannerConfig,
) -> Result<MotionTiming, TimingSetupError> {
    MotionTiming::for_robot_file(
        robot,
        robot_file,
        None,
        emg_timing::Scaling::default(),
        config.rollout.speed_m_per_s,
        DEFAULT_RATE_HZ,
        &config.rollout.constraints,
    )
}

/// Why a planned job cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum JobPlanError {
    /// No part of any stroke could be drawn with a safe move to it.
    #[error(
        "no stroke of the job can be drawn: {0} (move the drawing where the arm reaches it, or \
         change its size or normal)"
    )]
    NothingDrawn(String),
    /// The program is too long for the trajectory format.
    #[error("the program lasts longer than a joint trajectory file holds")]
    TooLong,
    /// The watcher asked the job to stop.
    #[error(transparent)]
    Stopped(#[from] Stopped),
    /// The job's corner tolerance leaves nothing of the planner's line tolerance.
    #[error(transparent)]
    Job(#[from] JobError),
}

/// Plans `job` with `planner` as `request` asks (the search; its constraints and scene) and
/// times it with `timing`;
/// `robot_file` is recorded in the file; `watch` is told each stage's progress ("ordering",
/// "planning", "connecting", "reordering", and "branches" where the strokes are connected
/// again on the branches chosen for the job, in strokes) and asked between strokes whether to stop
/// ([`JobPlanError::Stopped`]). Strokes are planned in parallel; the result does not depend on
/// the number of threads.
pub fn plan_job(
    planner: &Planner,
    request: &PlanRequest,
    job: &Job,
    timing: &MotionTiming,
    robot_file: &str,
    watch: &dyn Watch,
) -> Result<JobFile, JobPlanError> {
    let started = Instant::now();
    let settings = &job.settings;
    let following = tolerance::following(planner, settings.corner_tolerance_m)?;
    let planner = following.as_ref().unwrap_or(planner);
    let robot = planner.robot();
    let dof = robot.dof();
    let strokes = job.strokes.len();
    watch.progress("ordering", 0, strokes);
    let mut ordering = merge_and_order(
        &job.strokes,
        settings.order,
        planner.config().rollout.constraints.line_tolerance_m,
    );
    let drawn = ordering.drawn_paths(&job.strokes);
    watch.progress("ordering", strokes, strokes);
    // The part under the strokes, which the arm keeps off while drawing as between strokes.
    let free = FreeSpace::new(
        robot,
        job_part(robot, job),
        &planner.config().rollout.constraints,
    );
    let constraints = &planner.config().rollout.constraints;
    let mut on_part = planner.config().clone();
    on_part.rollout.constraints = free.constraints().clone();
    let on_part = planner
        .with_config(on_part)
        .expect("the planner's configuration with obstacles added is valid");
    // The planners a stroke is tried with in turn: where the arm has a home and joints that
    // turn further than a turn, those joints within each band about the home, narrowest first;
    // then their whole range.
    let bands: Vec<Planner> = job
        .home
        .iter()
        .flat_map(|home| {
            NEAR_HOME_BANDS_RAD
                .iter()
                .filter_map(|&band| on_part.within(home, band))
        })
        .collect();
    let cascade: Vec<&Planner> = bands.iter().chain([&on_part]).collect();
    let progress = PlanningProgress::new(watch, drawn.iter().map(Path::length_m));
    // Each stroke as the first planner of the cascade that draws it whole plans it, else as the
    // narrowest that draws the most (to `SAME_LENGTH_M`), with that planner's place in it.
    let planned: Vec<(Oriented, StrokePlan, usize)> = ordering
        .sequence
        .par_iter()
        .map(|&oriented| {
            let length = oriented.path(&drawn).length_m();
            let stroke_progress = progress.stroke(length);
            let watch = &stroke_progress;
            let mut best: Option<(Oriented, StrokePlan, usize)> = None;
            for (rank, planner) in cascade.iter().enumerate() {
                let (oriented, plan) =
                    planned_stroke(planner, request, oriented, &drawn, settings, watch)?;
                let drawn_m = plan.planned_m();
                if best
                    .as_ref()
                    .is_none_or(|(_, best, _)| drawn_m > best.planned_m() + SAME_LENGTH_M)
                {
                    best = Some((oriented, plan, rank));
                }
                if drawn_m >= length - SAME_LENGTH_M {
                    break;
                }
            }
            stroke_progress.finish();
            Ok(best.expect("the cascade holds the whole range"))
        })
        .collect::<Result<_, Stopped>>()?;
    let connector = Connector {
        free: &free,
        timing,
        settings,
    };
    let branches = JobBranches {
        connector: &connector,
        cascade: &cascade,
        request,
        home: job.home.as_ref(),
    };
    let mut plans = Vec::with_capacity(planned.len());
    let mut ranks = Vec::with_capacity(planned.len());
    ordering.sequence = planned
        .into_iter()
        .map(|(oriented, plan, rank)| {
            plans.push(plan);
            ranks.push(rank);
            oriented
        })
        .collect();
    let first = ConnectedOrder {
        connected: connect_strokes(
            &branches,
            &ordering.sequence,
            &plans,
            &ranks,
            &vec![None; plans.len()],
            watch,
            "connecting",
        )?,
        sequence: std::mem::take(&mut ordering.sequence),
        plans,
        ranks,
    };
    let home_held = job.home.map(|home| branches.held(&home));
    // Unless the order is the job's own, the strokes reordered by estimated pen-up time and
    // connected again.
    let reorder = match settings.order {
        Order::Given => None,
        Order::Shortest => {
            watch.progress("reordering", 0, first.plans.len());
            let points: Vec<[Vec3; 2]> = first
                .plans
                .iter()
                .map(|plan| {
                    [
                        plan.path.point_at(0.0),
                        plan.path.point_at(plan.path.length_m()),
                    ]
                })
                .collect();
            reorder_by_move_time(
                &first.connected.placed_ends,
                &points,
                home_held.as_ref(),
                &branches,
            )
        }
    };
    let reordered = match reorder {
        None => None,
        Some((order, _)) => {
            let (sequence, plans, ranks) = (
                in_order(&first.sequence, &order),
                in_order(&first.plans, &order),
                in_order(&first.ranks, &order),
            );
            let connected = connect_strokes(
                &branches,
                &sequence,
                &plans,
                &ranks,
                &vec![None; plans.len()],
                watch,
                "reordering",
            )?;
            Some(ConnectedOrder {
                sequence,
                plans,
                ranks,
                connected,
            })
        }
    };
    // Each order on the branches chosen for it, and of the two the one that draws as much in
    // less time.
    let mut best = on_chosen_branches(first, &branches, home_held.as_ref(), watch)?;
    if let Some(reordered) = reordered {
        let reordered = on_chosen_branches(reordered, &branches, home_held.as_ref(), watch)?;
        if reordered.connected.is_better_than(&best.connected) {
            best = reordered;
        }
    }
    let ConnectedOrder {
        sequence,
        plans,
        connected,
        ..
    } = best;
    ordering.sequence = sequence;
    // Measured again between the strokes as they are drawn: their directions and starts taken.
    ordering.travel_m = plans
        .windows(2)
        .map(|pair| {
            let end = pair[0].path.point_at(pair[0].path.length_m());
            (pair[1].path.point_at(0.0) - end).norm()
        })
        .fold(0.0, |total, leg| total + leg);
    let Connected {
        program,
        reports,
        moves: (straight_moves, sampled_moves),
        searches,
        least,
        ends_at_home,
        ..
    } = connected;
    if program.segments().is_empty() {
        let why = reports
            .iter()
            .flat_map(|r| r.parts_left_out.first())
            .next()
            .cloned()
            .unwrap_or_else(|| "no stroke has a reachable start".to_string());
        return Err(JobPlanError::NothingDrawn(why));
    }
    let mut summary = summarise(
        &reports,
        &program,
        &ordering,
        (straight_moves, sampled_moves),
        searches,
        started,
    );
    summary.ends_at_home = ends_at_home;
    (summary.least_pen_down_s, summary.least_pen_up_s) = least;
    if program.duration_s() > MAX_PROGRAM_S {
        return Err(JobPlanError::TooLong);
    }
    Ok(JobFile {
        format: JOB_FILE_FORMAT.to_string(),
        robot: robot_file.to_string(),
        joint_names: robot.joint_names().to_vec(),
        constraints: constraints.clone(),
        limits: timing.record(),
        settings: settings.clone().resolved(),
        home: job.home.map(|home| home.as_slice()[..dof].to_vec()),
        ordering,
        strokes: reports,
        summary,
        surfaces: free.surfaces().to_vec(),
        rate_hz: timing.request().rate_hz,
        segments: program.segments().to_vec(),
    })
}

/// A job's strokes joined into one program by the connect stage.
struct Connected {
    program: Program,
    /// One per stroke, in the order drawn.
    reports: Vec<StrokeReport>,
    /// Pen-up moves whose edges are straight, and those the sampling planner found a stretch of.
    moves: (usize, usize),
    /// Searches run: the strokes' plans' and the rest plans'.
    searches: usize,
    /// The least duration the arm's limits allow for the same parts: pen down, pen up (s).
    least: (f64, f64),
    /// Whether the program ends at the home.
    ends_at_home: bool,
    /// Where each stroke's first placed part starts and its last ends, as the job holds them
    /// ([`JobBranches::held`]); `None` where none was placed.
    placed_ends: Vec<Option<[JointVector; 2]>>,
}

impl Connected {
    /// Whether this program draws as much as `other` (to [`SAME_LENGTH_M`]) in less time.
    fn is_better_than(&self, other: &Connected) -> bool {
        let drawn = |c: &Connected| c.reports.iter().map(|r| r.drawn_m).sum::<f64>();
        drawn(self) >= drawn(other) - SAME_LENGTH_M
            && self.program.duration_s() < other.program.duration_s()
    }
}

/// A job's strokes in the order drawn, their plans, and the program connecting them.
struct ConnectedOrder {
    sequence: Vec<Oriented>,
    plans: Vec<StrokePlan>,
    /// Each plan's planner's place in the job's cascade.
    ranks: Vec<usize>,
    connected: Connected,
}

/// The choose-branches stage ([`branch`]) on `drawing`: its strokes' branches chosen for the
/// job as a whole (the arm starting and ending at `home`), connected again, and kept where
/// that draws as much in less time.
fn on_chosen_branches(
    drawing: ConnectedOrder,
    branches: &JobBranches<'_>,
    home: Option<&JointVector>,
    watch: &dyn Watch,
) -> Result<ConnectedOrder, JobPlanError> {
    let Some(chosen) = choose_branches(
        &drawing.plans,
        &drawing.ranks,
        &drawing.connected.placed_ends,
        home,
        branches,
    ) else {
        return Ok(drawing);
    };
    let moved_to: Vec<Option<JointVector>> = chosen.iter().map(|choice| choice.moved_to).collect();
    let (plans, ranks): (Vec<StrokePlan>, Vec<usize>) = chosen
        .into_iter()
        .map(|choice| (choice.plan, choice.rank))
        .unzip();
    let connected = connect_strokes(
        branches,
        &drawing.sequence,
        &plans,
        &ranks,
        &moved_to,
        watch,
        "branches",
    )?;
    Ok(if connected.is_better_than(&drawing.connected) {
        ConnectedOrder {
            plans,
            ranks,
            connected,
            ..drawing
        }
    } else {
        drawing
    })
}

/// The connect stage: the strokes `sequence` planned as `plans` (each by the cascade's planner
/// of its rank in `ranks`) placed one after another into one program, from the home and back
/// to it; where a stroke's plan was carried over to another branch (`moved_to`: where it
/// starts), the stroke before it ends the way nearest it. `watch` is told the strokes connected
/// as `stage`.
fn connect_strokes(
    branches: &JobBranches<'_>,
    sequence: &[Oriented],
    plans: &[StrokePlan],
    ranks: &[usize],
    moved_to: &[Option<JointVector>],
    watch: &dyn Watch,
    stage: &str,
) -> Result<Connected, JobPlanError> {
    let connector = branches.connector;
    let (free, settings, cascade, request) = (
        connector.free,
        connector.settings,
        branches.cascade,
        branches.request,
    );
    let home = branches.home.copied();
    let robot = free.robot();
    let dof = robot.dof();
    let limits = &connector.timing.request().limits;
    let mut least = LeastDuration::new(connector.timing.request(), home);
    let mut placed_ends = Vec::with_capacity(sequence.len());
    let mut program = Program::default();
    let mut reports = Vec::new();
    let (mut straight_moves, mut sampled_moves) = (0, 0);
    // The last part's lift, joined to the move after it.
    let mut retreat: Option<[JointVector; 2]> = None;
    let mut searches: usize = plans.iter().map(|plan| plan.searches).sum();
    for (connected, ((oriented, plan), &rank)) in sequence.iter().zip(plans).zip(ranks).enumerate()
    {
        // The stroke's planner's place in the cascade.
        let mut rank = rank;
        if watch.stop_requested() {
            return Err(Stopped.into());
        }
        watch.progress(stage, connected, sequence.len());
        let mut parts_left_out = Vec::new();
        // The stretches of the stroke the placed parts' samples cover.
        let mut covered = Vec::new();
        let mut queue: VecDeque<StrokePart> = plan.parts.iter().cloned().collect();
        let mut rest_plans = 0;
        let mut unsearched_from_s = plan.unsearched_from_s;
        // Where the stroke's searches stopped short, and the parts left out.
        let mut stops = plan.stops.clone();
        let mut left_out = Vec::new();
        let mut next_index = 0;
        // Where the stroke's first placed part starts and its last ends.
        let mut stroke_ends: Option<[JointVector; 2]> = None;
        while let Some(planned) = queue.pop_front() {
            let index = next_index;
            next_index += 1;
            let from = retreat.map(|[_, above]| above).or(program.last()).or(home);
            // The way the tool rose off the last part, which it may rise further along.
            let risen = retreat.and_then(|[end, above]| {
                (robot.forward(&above).tcp() - robot.forward(&end).tcp()).try_normalize(1e-12)
            });
            // Each joint among its whole turns nearest the home (else where the arm is), the
            // tool's free roll centred on it.
            let planned = toward(planned, home.as_ref(), from.as_ref(), free);
            let seed = settings.seed.wrapping_add(program.segments().len() as u64);
            // The part planned again from the configuration the arm is in and from the home,
            // each moved above the part's start and set down there: tried first where it draws
            // as far from a start nearer the arm, and where the searched start cannot be reached.
            let again: Vec<StrokePart> = [from, home]
                .iter()
                .flatten()
                .filter_map(|start| {
                    connector.replanned_nearby(cascade[rank], request, &planned, start)
                })
                .map(|part| toward(part, home.as_ref(), from.as_ref(), free))
                .collect();
            // Where the arm goes after the stroke's last part, where the next stroke was
            // carried over to another branch.
            let next = queue
                .is_empty()
                .then(|| moved_to.get(connected + 1).copied().flatten())
                .flatten();
            let next = next
                .as_ref()
                .map(|next| (next, |q: &JointVector| branches.held(q)));
            let candidates = ranked(planned.clone(), again, from.as_ref(), next, limits);
            // The first candidate placed, else why the first one could not be.
            let mut placed = None;
            let mut first_why = None;
            for part in &candidates {
                match connector.place(part, from.map(|from| (from, risen)), seed) {
                    Ok(done) => {
                        placed = Some(done);
                        break;
                    }
                    Err(why) => {
                        first_why.get_or_insert(why);
                    }
                }
            }
            let placed = placed.ok_or_else(|| first_why.expect("the searched part is a candidate"));
            // Where a part planned within a band about the home cannot be reached, the stroke is
            // planned again from there by the next planner of the cascade; where a stand-in that
            // draws less than the planned part was placed, the rest of the stroke is planned
            // again from where it ends. The parts from the stroke's other end still follow.
            // A timed motion cut before the end it was planned to (a timed sample left the
            // tolerance, `emg_planner::MotionTiming::time`) is resumed from where its samples
            // stop, as a stand-in that draws less is.
            let (resume_s, placed) = match placed {
                Ok((part, placed)) => {
                    let drawn = part_coverage(
                        robot,
                        &part.task,
                        part.on_stroke(),
                        placed.timed.samples.iter().map(|sample| &sample.q),
                    );
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
                    let again = rank + 1 < cascade.len()
                        && !planned.backward
                        && rest_plans < settings.max_parts;
                    if again {
                        rank += 1;
                    } else {
                        parts_left_out.push(format!("part {index}: {why}"));
                        left_out.push(LeftOut {
                            planned: planned.planned(),
                            why: why.to_string(),
                        });
                    }
                    (again.then_some(planned.from_s), None)
                }
            };
            if let Some(resume_s) = resume_s.filter(|_| !planned.backward)
                && rest_plans < settings.max_parts
            {
                rest_plans += 1;
                let rest = plan_stroke(
                    cascade[rank],
                    request,
                    &plan.path,
                    resume_s,
                    settings,
                    watch,
                )?;
                searches += rest.searches;
                unsearched_from_s = rest.unsearched_from_s;
                stops.extend(rest.stops);
                let backward: Vec<StrokePart> = queue.drain(..).filter(|p| p.backward).collect();
                queue = rest.parts.into_iter().chain(backward).collect();
            }
            let Some((part, placed, stretch)) = placed else {
                continue;
            };
            let Placed {
                timed,
                above_start,
                above_end,
                travel,
                sampled,
            } = placed;
            let (start, end) = (timed.samples[0].q, timed.samples[timed.samples.len() - 1].q);
            match (travel.is_empty(), sampled) {
                (true, _) => {}
                (false, false) => straight_moves += 1,
                (false, true) => sampled_moves += 1,
            }
            // Without a home the program begins above the first stroke.
            connector.join(
                &mut program,
                retreat.take(),
                &travel,
                Some([above_start, start]),
                dof,
            );
            program.append(
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
            least.add_stroke(above_start, start, end, stretch.length_m());
            stroke_ends = Some([stroke_ends.map_or(start, |[first, _]| first), end]);
            covered.push(stretch);
            retreat = Some([end, above_end]);
        }
        placed_ends.push(stroke_ends.map(|ends| ends.map(|q| branches.held(&q))));
        let length_m = plan.path.length_m();
        let coverage = Coverage::of(length_m, &covered);
        let (unreached, unreached_causes) =
            shortfall::undrawn_causes(&coverage.undrawn, &stops, &left_out, unsearched_from_s)
                .into_iter()
                .unzip::<_, _, Vec<_>, Vec<_>>();
        reports.push(StrokeReport {
            stroke: oriented.stroke,
            reversed: oriented.reversed,
            path: plan.path.spec().clone(),
            length_m,
            drawn_m: coverage.drawn_m,
            parts: covered.len(),
            unreached_at: unreached
                .iter()
                .map(|u: &Stretch| plan.path.point_at(u.from_s).into())
                .collect(),
            unreached,
            unreached_causes,
            parts_left_out,
            unsearched_from_s,
        });
    }
    let last = retreat.map(|[_, above]| above).or(program.last());
    let home_travel = home.zip(last).and_then(|(home, last)| {
        connector.home_move(&last, &home, settings.seed.wrapping_add(u64::MAX / 2))
    });
    let ends_at_home = home_travel.is_some();
    connector.join(
        &mut program,
        retreat.take(),
        home_travel.as_deref().unwrap_or_default(),
        None,
        dof,
    );
    least.end_at(program.last());
    Ok(Connected {
        program,
        reports,
        moves: (straight_moves, sampled_moves),
        searches,
        least: (least.pen_down_s, least.pen_up_s),
        ends_at_home,
        placed_ends,
    })
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
    watch: &dyn Watch,
) -> Result<(Oriented, StrokePlan), Stopped> {
    let plan = plan_stroke(
        planner,
        request,
        &oriented.path(drawn),
        0.0,
        settings,
        watch,
    )?;
    match settings.order {
        Order::Shortest => {
            let (oriented, plan) = the_way_drawing_more((oriented, plan), drawn, |path| {
                plan_stroke(planner, request, path, 0.0, settings, watch)
            })?;
            let plan = finish_from_the_end(planner, request, plan, settings, watch)?;
            let plan = started_where_it_draws(plan, planner.robot(), |path| {
                let plan = plan_stroke(planner, request, path, 0.0, settings, watch)?;
                finish_from_the_end(planner, request, plan, settings, watch)
            })?;
            Ok((oriented, plan))
        }
        Order::Given => Ok((oriented, plan)),
    }
}

/// How far (rad) from the home's roll the tool's roll joint is held: a quarter turn.
pub const ROLL_FROM_HOME_RAD: f64 = std::f64::consts::FRAC_PI_2;

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
struct JobBranches<'a> {
    connector: &'a Connector<'a>,
    /// The planners a stroke is tried with, by rank.
    cascade: &'a [&'a Planner],
    request: &'a PlanRequest,
    home: Option<&'a JointVector>,
}

impl JobBranches<'_> {
    /// `q` as the job holds it: each joint among its whole turns nearest the home (where there
    /// is one), the tool's free roll, which the job holds still, left out (0).
    fn held(&self, q: &JointVector) -> JointVector {
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
                .replanned_nearby(self.cascade[rank], self.request, first, from)?;
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

/// How far before a pen-up move's corner its rounding starts: this share of the shorter of the
/// corner's edges (the tool has risen 60 % of its lift before it moves aside, clear of the
/// [`PEN_UP_CLEARANCE_SHARE`] it keeps off the lift and the set-down).
pub const BLEND_SHARE: f64 = 0.4;

/// How far before a hop's top its rounding starts: this share of the shorter of its two edges
/// (the hop leaves and meets the part along them, [`LIFT_CONE_RUN`]).
pub const HOP_BLEND_SHARE: f64 = 0.5;

/// How high a pen-up hop between close parts rises for each metre of lateral distance: half,
/// so that the tool leaves and meets the surface at about 45°.
pub const HOP_RISE: f64 = 0.5;

/// A hop rises at most this many lifts; parts further apart are joined by the lift, the move
/// and the set-down.
pub const MAX_HOP_RISE_LIFTS: f64 = 4.0;

/// Halvings at most of a pen-up move's straight edge that sags toward the part
/// (`Connector::held_up`): up to 8 edges, each held at the lift at its ends.
pub const MAX_HELD_UP_DEPTH: usize = 3;

/// How much further (m) the tool rises where no straight free move joins two parts at its lift:
/// a torch's lift, clear of what lies on the part.
pub const CLEARANCE_LIFT_M: f64 = 0.03;

/// The shares of the job's lift height tried in turn where the tool cannot lift the whole of it
/// into free space (near an obstacle, say).
const LIFT_SHARES: [f64; 3] = [1.0, 0.5, 0.25];

/// A stroke part made ready to join the program: timed, with its free configurations above
/// its start and end and the free move to the first from where the arm was.
struct Placed {
    timed: emg_timing::TimedMotion,
    above_start: JointVector,
    above_end: JointVector,
    /// Empty when the program begins here.
    travel: Vec<JointVector>,
    /// Whether the sampling planner found a stretch of `travel` (else its edges are straight).
    sampled: bool,
}

/// The connect stage for one part at a time.
struct Connector<'a> {
    free: &'a FreeSpace<'a>,
    timing: &'a MotionTiming,
    settings: &'a JobSettings,
}

impl Connector<'_> {
    /// `part` timed and joined to the arm's configuration `from` (none at the program's start;
    /// with the way the tool rose there off the last part, if it did): lifted at both ends,
    /// the free move to above its start; or why it cannot be.
    fn place(
        &self,
        part: &StrokePart,
        from: Option<(JointVector, Option<Vec3>)>,
        seed: u64,
    ) -> Result<(StrokePart, Placed), String> {
        let robot = self.free.robot();
        let timed = self
            .timing
            .time(robot, &part.task, self.free.constraints(), &part.trajectory)
            .map_err(|e| format!("cannot be timed: {e}"))?;
        let start = timed.samples[0].q;
        let end = timed.samples[timed.samples.len() - 1].q;
        // The tool lifts the job's height where that is free, else half or a quarter of it.
        let above = |q: &JointVector, what: &str| {
            LIFT_SHARES
                .iter()
                .find_map(|share| {
                    let lift = -part.task.n * (self.settings.lift() * share);
                    self.free.reach_point(q, &(robot.forward(q).tcp() + lift))
                })
                .ok_or_else(|| {
                    format!(
                        "the tool cannot lift {} m (or a quarter of it) off its {what} into free \
                         space",
                        self.settings.lift()
                    )
                })
        };
        let above_start = above(&start, "start")?;
        let above_end = above(&end, "end")?;
        let (travel, sampled) = match from {
            None => (Vec::new(), false),
            Some((from, risen)) => self
                .travel(&from, risen, &above_start, &-part.task.n, seed)
                .ok_or_else(|| {
                    format!(
                        "no free move to its start found in {} samples",
                        self.settings.rrt_max_samples
                    )
                })?,
        };
        Ok((
            part.clone(),
            Placed {
                timed,
                above_start,
                above_end,
                travel,
                sampled,
            },
        ))
    }

    /// The free move from `from` (risen along `risen` off the last part, if it did) to `to`
    /// (above the next part, which the tool leaves along `up`): the straight joint-space edge
    /// where it is free; else over both, each risen [`CLEARANCE_LIFT_M`] further where that is
    /// free, the straight edge between them or a sampled move ([`FreeSpace::connect`]); else a
    /// sampled move between `from` and `to` themselves. With whether the sampling planner found
    /// a stretch of it.
    fn travel(
        &self,
        from: &JointVector,
        risen: Option<Vec3>,
        to: &JointVector,
        up: &Vec3,
        seed: u64,
    ) -> Option<(Vec<JointVector>, bool)> {
        let clear = |path: &[JointVector]| self.free.move_free(path, self.pen_up_clearance_m());
        if let Some(path) = self.held_up(from, to, up, MAX_HELD_UP_DEPTH)
            && clear(&path)
        {
            return Some((path, false));
        }
        let robot = self.free.robot();
        let rise = |q: &JointVector, up: &Vec3| {
            self.free
                .reach_point(q, &(robot.forward(q).tcp() + up * CLEARANCE_LIFT_M))
        };
        let over = || {
            let (high_from, high_to) = (
                risen.map_or(Some(*from), |up| rise(from, &up))?,
                rise(to, up)?,
            );
            let between =
                self.free
                    .connect(&high_from, &high_to, seed, self.settings.rrt_max_samples)?;
            let sampled = between.len() > 2;
            Some(([vec![*from], between, vec![*to]].concat(), sampled))
        };
        over().filter(|(path, _)| clear(path)).or_else(|| {
            let path = self
                .free
                .connect(from, to, seed, self.settings.rrt_max_samples)?;
            clear(&path).then_some((path, true))
        })
    }

    /// The free move from `last` (above the last part) back to `home` that keeps the pen-up
    /// clearance ([`FreeSpace::move_free`]): the sampled move between them, else from `last`
    /// risen [`CLEARANCE_LIFT_M`] further; `None` where neither is found.
    fn home_move(
        &self,
        last: &JointVector,
        home: &JointVector,
        seed: u64,
    ) -> Option<Vec<JointVector>> {
        let clear = |path: &Vec<JointVector>| self.free.move_free(path, self.pen_up_clearance_m());
        let samples = self.settings.rrt_max_samples;
        self.free
            .connect(last, home, seed, samples)
            .filter(clear)
            .or_else(|| {
                let robot = self.free.robot();
                let tip = robot.forward(last).tcp();
                let up = self
                    .free
                    .surfaces()
                    .iter()
                    .min_by(|a, b| {
                        ((tip - a.p0).dot(&a.n).abs()).total_cmp(&(tip - b.p0).dot(&b.n).abs())
                    })
                    .map(|surface| -surface.n)?;
                let high = self
                    .free
                    .reach_point(last, &(tip + up * CLEARANCE_LIFT_M))?;
                let path = self.free.connect(&high, home, seed, samples)?;
                Some([vec![*last], path].concat()).filter(clear)
            })
    }

    /// The joint-space polyline from `from` to `to` (both lifted above the part, which the tool
    /// leaves along `up`) whose edges are free and keep the pen-up clearance
    /// ([`FreeSpace::move_free`]): the straight edge where it does; else, where the edge sags,
    /// through the configuration near the middle of the edge whose tip lies midway between the
    /// two tips and the clearance higher ([`FreeSpace::reach_point`]), so that a blend rounding
    /// it keeps clear too, each half held up the same way, `depth` halvings at most.
    fn held_up(
        &self,
        from: &JointVector,
        to: &JointVector,
        up: &Vec3,
        depth: usize,
    ) -> Option<Vec<JointVector>> {
        if self
            .free
            .move_free(&[*from, *to], self.pen_up_clearance_m())
        {
            return Some(vec![*from, *to]);
        }
        if depth == 0 {
            return None;
        }
        let robot = self.free.robot();
        let tips = (robot.forward(from).tcp() + robot.forward(to).tcp()) / 2.0
            + up * self.pen_up_clearance_m();
        let middle = self.free.reach_point(&((from + to) / 2.0), &tips)?;
        let mut path = self.held_up(from, &middle, up, depth - 1)?;
        path.pop();
        path.extend(self.held_up(&middle, to, up, depth - 1)?);
        Some(path)
    }

    /// How high (m) the tool's tip stays above the part along a pen-up move, but on the lift
    /// and the set-down ([`PEN_UP_CLEARANCE_SHARE`] of the lift).
    fn pen_up_clearance_m(&self) -> f64 {
        PEN_UP_CLEARANCE_SHARE * self.settings.lift()
    }

    /// Appends the pen-up move between two parts (or after the last): `retreat` (the lift off
    /// the last part), `travel` (the free move from above it, or from the program's start) and
    /// `approach` (the set-down onto the next part) as one motion through their vertices with
    /// its corners rounded ([`time_blended_move`], each corner's arc starting
    /// [`BLEND_SHARE`] of the shorter edge before it), where that motion is free and keeps the
    /// pen-up clearance ([`FreeSpace::move_free`]) and holds the limits: one `travel` segment, at rest only where
    /// the tool leaves and meets the part. Else each of them rest to rest, at rest at every
    /// vertex.
    fn join(
        &self,
        program: &mut Program,
        retreat: Option<[JointVector; 2]>,
        travel: &[JointVector],
        approach: Option<[JointVector; 2]>,
        dof: usize,
    ) {
        let mut vertices: Vec<JointVector> = Vec::new();
        for q in retreat
            .iter()
            .flatten()
            .chain(travel)
            .chain(approach.iter().flatten())
        {
            if vertices.last().is_none_or(|last| (q - last).norm() > 1e-12) {
                vertices.push(*q);
            }
        }
        let request = self.timing.request();
        let blended = (retreat.is_some() && vertices.len() > 2)
            .then(|| time_blended_move(&vertices, request, BLEND_SHARE))
            .flatten()
            .filter(|timed| {
                let path: Vec<JointVector> = timed.samples.iter().map(|s| s.q).collect();
                self.free.move_free(&path, self.pen_up_clearance_m())
            });
        let hop = match (retreat, travel, approach) {
            (Some(retreat), [_, _], Some(approach)) => self.hop(retreat, approach),
            _ => None,
        };
        let last_time =
            |timed: &emg_timing::TimedMove| timed.samples[timed.samples.len() - 1].time_ns;
        let quickest = match (blended, hop) {
            (Some(blended), Some(hop)) if last_time(&hop) < last_time(&blended) => Some(hop),
            (blended, hop) => blended.or(hop),
        };
        if let Some(timed) = quickest {
            let (definition, samples) = (&timed.definition, &timed.samples);
            program.append(SegmentKind::Travel, definition, samples, None, dof);
            return;
        }
        if let Some(retreat) = retreat {
            program.append_move(SegmentKind::Retreat, &retreat, self.timing, dof);
        }
        if !travel.is_empty() {
            program.append_move(SegmentKind::Travel, travel, self.timing, dof);
        }
        if let Some(approach) = approach {
            program.append_move(SegmentKind::Approach, &approach, self.timing, dof);
        }
    }

    /// The short pen-up move from the end of one part to the start of the next on the same
    /// surface as one hop: up and over through the configuration above the middle between
    /// them and straight down, the corner rounded ([`time_blended_move`]), the tool rising
    /// [`HOP_RISE`] of the lateral distance (at least the lift `retreat` and `approach` take,
    /// at most [`MAX_HOP_RISE_LIFTS`] lifts); `None` where the parts lie on different surfaces,
    /// lie further apart, or the hop is not free or comes nearer the part than the pen-up
    /// clearance off the lift and the set-down ([`FreeSpace::move_free`]).
    fn hop(
        &self,
        [end, above_end]: [JointVector; 2],
        [above_start, start]: [JointVector; 2],
    ) -> Option<emg_timing::TimedMove> {
        let robot = self.free.robot();
        let tcp = |q: &JointVector| robot.forward(q).tcp();
        let (from, to) = (tcp(&end), tcp(&start));
        let (lift_end, lift_start) = (tcp(&above_end) - from, tcp(&above_start) - to);
        let up = lift_end.try_normalize(1e-12)?;
        let across = to - from;
        let tolerance = self.free.constraints().line_tolerance_m;
        if (lift_start.try_normalize(1e-12)? - up).norm() > 1e-6
            || up.dot(&across).abs() > 2.0 * tolerance
        {
            return None;
        }
        let lift = lift_end.norm().min(lift_start.norm());
        // The distance from `origin` across the surface.
        let lateral = |point: &Vec3, origin: &Vec3| {
            let offset = point - origin;
            (offset - up * up.dot(&offset)).norm()
        };
        let distance = lateral(&to, &from);
        let rise = (HOP_RISE * distance).max(lift);
        if rise > MAX_HOP_RISE_LIFTS * lift {
            return None;
        }
        let middle = (above_end + above_start) / 2.0;
        let top = self
            .free
            .reach_point(&middle, &((from + to) / 2.0 + up * rise))?;
        let timed = time_blended_move(&[end, top, start], self.timing.request(), HOP_BLEND_SHARE)?;
        let path: Vec<JointVector> = timed.samples.iter().map(|s| s.q).collect();
        self.free
            .move_free(&path, self.pen_up_clearance_m())
            .then_some(timed)
    }

    /// `part`'s stretch planned again by one rollout from the configuration reached from
    /// `from` (lifted, above the part's start) by moving the tool straight above the start and
    /// down onto it, the arm keeping its branch: at the tool's lift, else risen
    /// [`CLEARANCE_LIFT_M`] higher first (over what a low move would graze); `None` where
    /// neither move is free.
    fn replanned_nearby(
        &self,
        planner: &Planner,
        request: &PlanRequest,
        part: &StrokePart,
        from: &JointVector,
    ) -> Option<StrokePart> {
        let robot = self.free.robot();
        let start_point = part.task.p0;
        let up = -part.task.n;
        let above = self
            .free
            .reach_point(from, &(start_point + up * self.settings.lift()))
            .or_else(|| {
                let high = self
                    .free
                    .reach_point(from, &(robot.forward(from).tcp() + up * CLEARANCE_LIFT_M))?;
                let over = self
                    .free
                    .reach_point(&high, &(start_point + up * CLEARANCE_LIFT_M))?;
                self.free
                    .reach_point(&over, &(start_point + up * self.settings.lift()))
            })?;
        let start = self.free.reach_point(&above, &start_point)?;
        let rollout = PlanRequest {
            planner: emg_planner::PlannerKind::Controller,
            seed: Some(emg_planner::SeedSource::Given(
                robot.joints_of(&start).to_vec(),
            )),
            controller: request.controller,
        };
        let planned = planner.plan(&part.task, &rollout).ok()?;
        (planned.trajectory.steps.len() > 1).then(|| StrokePart {
            from_s: part.from_s,
            backward: part.backward,
            task: part.task.clone(),
            trajectory: planned.trajectory,
        })
    }
}

/// Starts a closed stroke none of whose parts draws anything is tried at: [`reachable_start_s`]
/// and as many more evenly spaced round the loop from it.
pub const CLOSED_STARTS: usize = 8;

/// `plan` of a closed stroke ([`Path::is_closed`]) whose start no part covers, started again
/// elsewhere on it where that draws more by [`SAME_LENGTH_M`] (`replan`, both ends): a closed
/// stroke may start anywhere, and one starting out of reach draws little from either end. The
/// new start is the middle of the longest stretch a part covers; where none covers any, the
/// [`CLOSED_STARTS`] points from [`reachable_start_s`] round the loop in turn, until one draws
/// half the loop, the one that draws most kept. The searches of all are counted.
fn started_where_it_draws(
    plan: StrokePlan,
    robot: &Robot,
    replan: impl Fn(&Path) -> Result<StrokePlan, Stopped>,
) -> Result<StrokePlan, Stopped> {
    let path = &plan.path.clone();
    let length = path.length_m();
    let stretches: Vec<Stretch> = plan.parts.iter().map(StrokePart::planned).collect();
    let whole = Coverage::of(length, &stretches).whole();
    let start_covered = stretches.iter().any(|s| s.from_s <= COVERAGE_SLACK_M);
    if !path.is_closed() || whole || start_covered {
        return Ok(plan);
    }
    let longest = stretches
        .iter()
        .max_by(|a, b| a.length_m().total_cmp(&b.length_m()));
    let starts: Vec<f64> = match longest {
        Some(stretch) => vec![0.5 * (stretch.from_s + stretch.to_s)],
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
        if other.planned_m() >= best.planned_m() + SAME_LENGTH_M {
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

/// The least time a program needs at the arm's limits, summed as its parts are placed
/// (docs/jobs.md, "Cycle time"): each stroke part at least its drawn length at the tool speed,
/// and at least the least time its joints need from its start to its end ([`least_move_s`]);
/// each pen-up move at least the least time from the configuration where the last part ended
/// (or the program starts) to where the next one starts, whatever path it takes. No program
/// that draws the same parts from the same configurations within the limits is shorter.
struct LeastDuration<'a> {
    request: &'a emg_timing::TimingRequest,
    /// Where the arm is when the next pen-up move starts: the last part's end, or the home
    /// before the first (none where the program starts above its first stroke).
    pen_up_from: Option<JointVector>,
    /// The sum over stroke parts (s).
    pen_down_s: f64,
    /// The sum over pen-up moves (s).
    pen_up_s: f64,
}

impl<'a> LeastDuration<'a> {
    fn new(request: &'a emg_timing::TimingRequest, home: Option<JointVector>) -> Self {
        Self {
            request,
            pen_up_from: home,
            pen_down_s: 0.0,
            pen_up_s: 0.0,
        }
    }

    /// Adds the stroke part from `start` to `end` drawing `drawn_m`, and the move to it (from
    /// `above_start` where it is the program's first).
    fn add_stroke(
        &mut self,
        above_start: JointVector,
        start: JointVector,
        end: JointVector,
        drawn_m: f64,
    ) {
        let limits = &self.request.limits;
        let from = self.pen_up_from.unwrap_or(above_start);
        self.pen_up_s += least_move_s(&from, &start, limits);
        self.pen_down_s +=
            (drawn_m / self.request.tool_speed_m_per_s).max(least_move_s(&start, &end, limits));
        self.pen_up_from = Some(end);
    }

    /// Adds the move from the last part's end to `last`, the program's last configuration.
    fn end_at(&mut self, last: Option<JointVector>) {
        if let Some((from, last)) = self.pen_up_from.zip(last) {
            self.pen_up_s += least_move_s(&from, &last, &self.request.limits);
        }
    }
}

/// The job's totals.
fn summarise(
    reports: &[StrokeReport],
    program: &Program,
    ordering: &Ordering,
    (straight_moves, sampled_moves): (usize, usize),
    searches: usize,
    started: Instant,
) -> JobSummary {
    let whole = |r: &&StrokeReport| r.unreached.is_empty() && r.parts > 0;
    let pen_down_s = program
        .segments()
        .iter()
        .filter(|s| matches!(s.kind, SegmentKind::Stroke { .. }))
        .map(|s| s.end_s - s.start_s)
        .sum::<f64>();
    let duration_s = program.segments().last().map_or(0.0, |s| s.end_s);
    JobSummary {
        complete: reports
            .iter()
            .filter(whole)
            .filter(|r| r.parts == 1)
            .count(),
        resumed: reports.iter().filter(whole).filter(|r| r.parts > 1).count(),
        short: reports.iter().filter(|r| !whole(r)).count(),
        drawn_m: reports.iter().map(|r| r.drawn_m).sum(),
        total_m: reports.iter().map(|r| r.length_m).sum(),
        travel_given_m: ordering.travel_given_m,
        travel_m: ordering.travel_m,
        duration_s,
        pen_down_s,
        pen_up_s: duration_s - pen_down_s,
        straight_moves,
        sampled_moves,
        searches,
        planning_s: started.elapsed().as_secs_f64(),
        ends_at_home: true,
        least_pen_down_s: 0.0,
        least_pen_up_s: 0.0,
    }
}
