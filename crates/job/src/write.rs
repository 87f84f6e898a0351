//! The write stage: the program the later stages chose, what it draws of each stroke and the
//! job's totals assembled into one `emg-job/3` file.

use std::time::Instant;

use emg_planner::{MotionTiming, Planner};

use crate::connect::{Connected, Connection};
use crate::free_space::FreeSpace;
use crate::order::Ordering;
use crate::plan_error::JobPlanError;
use crate::program::{
    JOB_FILE_FORMAT, JobFile, JobSummary, MAX_PROGRAM_S, Program, SegmentKind, StrokeReport,
};
use crate::spec::Job;

/// What a job file records beside its program: the job, how it was planned and timed, and
/// when planning started.
pub(crate) struct Recorded<'a> {
    /// The job.
    pub job: &'a Job,
    /// The planner the strokes were followed with (its constraints are the file's).
    pub planner: &'a Planner,
    /// How the program was timed.
    pub timing: &'a MotionTiming,
    /// The space the arm moved in: the part's surfaces.
    pub free: &'a FreeSpace<'a>,
    /// The robot file, as the file names it.
    pub robot_file: &'a str,
    /// When planning started.
    pub started: Instant,
}

/// The job file of the program `chosen` for `ordering`'s strokes, its order set to the one
/// drawn; [`JobPlanError::NothingDrawn`] where it draws nothing, [`JobPlanError::TooLong`]
/// where it lasts longer than a file holds.
pub(crate) fn job_file(
    chosen: Connected,
    mut ordering: Ordering,
    recorded: &Recorded<'_>,
) -> Result<JobFile, JobPlanError> {
    let Connected {
        strokes,
        connection,
    } = chosen;
    // Measured again between the strokes as they are drawn: their directions and starts taken.
    ordering.travel_m = strokes
        .windows(2)
        .map(|pair| {
            let end = pair[0].plan.path.point_at(pair[0].plan.path.length_m());
            (pair[1].plan.path.point_at(0.0) - end).norm()
        })
        .fold(0.0, |total, leg| total + leg);
    ordering.sequence = strokes.into_iter().map(|stroke| stroke.oriented).collect();
    let Connection {
        program,
        reports,
        moves,
        searches,
        least,
        ends_at_home,
        ..
    } = connection;
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
        moves,
        searches,
        recorded.started,
    );
    summary.ends_at_home = ends_at_home;
    (summary.least_pen_down_s, summary.least_pen_up_s) = least;
    if program.duration_s() > MAX_PROGRAM_S {
        return Err(JobPlanError::TooLong);
    }
    let (job, timing) = (recorded.job, recorded.timing);
    let robot = recorded.planner.robot();
    Ok(JobFile {
        format: JOB_FILE_FORMAT.to_string(),
        robot: recorded.robot_file.to_string(),
        joint_names: robot.joint_names().to_vec(),
        constraints: recorded.planner.config().rollout.constraints.clone(),
        limits: timing.record(),
        settings: job.settings.clone().resolved(),
        home: job.home.map(|home| home.as_slice()[..robot.dof()].to_vec()),
        ordering,
        strokes: reports,
        summary,
        surfaces: recorded.free.surfaces().to_vec(),
        rate_hz: timing.request().rate_hz,
        segments: program.segments().to_vec(),
    })
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
