//! A job planned as the list of its stages, each a function from one stage's result to the
//! next's: order → plan strokes → connect → reorder → choose branches → write.

use std::time::Instant;

use emg_control::Path;
use emg_kinematics::{JointVector, Vec3};
use emg_planner::{MotionTiming, PlanRequest, Planner};

use crate::branch::choose_branches;
use crate::connect::{Connected, Connector, JobBranches, connect_strokes};
use crate::free_space::{FreeSpace, job_part};
use crate::order::{Ordering, merge_and_order};
use crate::plan_error::JobPlanError;
use crate::plan_strokes::{PlannedStroke, cascade, plan_strokes};
use crate::program::JobFile;
use crate::reorder::{in_order, reorder_by_move_time};
use crate::spec::{Job, Order};
use crate::tolerance;
use crate::watch::{Stopped, Watch};
use crate::write::{Recorded, job_file};

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
    let following = tolerance::following(planner, job.settings.corner_tolerance_m)?;
    let planner = following.as_ref().unwrap_or(planner);
    let robot = planner.robot();
    let (ordering, drawn) = ordered(planner, job, watch);
    // The part under the strokes, which the arm keeps off while drawing as between strokes.
    let constraints = &planner.config().rollout.constraints;
    let free = FreeSpace::new(robot, job_part(robot, job), constraints);
    let mut on_part = planner.config().clone();
    on_part.rollout.constraints = free.constraints().clone();
    let on_part = planner
        .with_config(on_part)
        .expect("the planner's configuration with obstacles added is valid");
    let cascade = cascade(on_part, job.home.as_ref());
    let settings = &job.settings;
    let planned = plan_strokes(
        &cascade,
        request,
        &ordering.sequence,
        &drawn,
        settings,
        &free,
        watch,
    )?;
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
    let first = connect(&branches, planned, watch, "connecting")?;
    let home_held = job.home.map(|home| branches.held(&home));
    let reordered = reordered(&first, settings.order, &branches, home_held.as_ref(), watch)?;
    let chosen = quickest_on_chosen_branches(first, reordered, &branches, home_held, watch)?;
    let recorded = Recorded {
        job,
        planner,
        timing,
        free: &free,
        robot_file,
        started,
    };
    job_file(chosen, ordering, &recorded)
}

/// The order stage: `job`'s strokes merged where they meet end to end and put in the order
/// its settings ask for, with the drawn strokes' paths.
fn ordered(planner: &Planner, job: &Job, watch: &dyn Watch) -> (Ordering, Vec<Path>) {
    let strokes = job.strokes.len();
    watch.progress("ordering", 0, strokes);
    let tolerance_m = planner.config().rollout.constraints.line_tolerance_m;
    let ordering = merge_and_order(&job.strokes, job.settings.order, tolerance_m);
    let drawn = ordering.drawn_paths(&job.strokes);
    watch.progress("ordering", strokes, strokes);
    (ordering, drawn)
}

/// The connect stage ([`connect_strokes`]) on strokes placed where their plans start.
fn connect(
    branches: &JobBranches<'_>,
    strokes: Vec<PlannedStroke>,
    watch: &dyn Watch,
    stage: &str,
) -> Result<Connected, Stopped> {
    let unmoved = vec![None; strokes.len()];
    connect_strokes(branches, strokes, &unmoved, watch, stage)
}

/// The reorder stage: unless the order is the job's own, the strokes of `first` reordered by
/// estimated pen-up time between their placed ends (the arm starting and ending at `home`) and
/// connected again; `None` where the order is kept.
fn reordered(
    first: &Connected,
    order: Order,
    branches: &JobBranches<'_>,
    home: Option<&JointVector>,
    watch: &dyn Watch,
) -> Result<Option<Connected>, Stopped> {
    if order == Order::Given {
        return Ok(None);
    }
    watch.progress("reordering", 0, first.strokes.len());
    let points: Vec<[Vec3; 2]> = first
        .strokes
        .iter()
        .map(|stroke| {
            let path = &stroke.plan.path;
            [path.point_at(0.0), path.point_at(path.length_m())]
        })
        .collect();
    let placed_ends = &first.connection.placed_ends;
    let Some((order, _)) = reorder_by_move_time(placed_ends, &points, home, branches) else {
        return Ok(None);
    };
    let strokes = in_order(&first.strokes, &order);
    connect(branches, strokes, watch, "reordering").map(Some)
}

/// The choose-branches stage on each order, `first` and the `reordered` one, and of the two
/// the one that draws as much in less time.
fn quickest_on_chosen_branches(
    first: Connected,
    reordered: Option<Connected>,
    branches: &JobBranches<'_>,
    home: Option<JointVector>,
    watch: &dyn Watch,
) -> Result<Connected, Stopped> {
    let best = on_chosen_branches(first, branches, home.as_ref(), watch)?;
    let Some(reordered) = reordered else {
        return Ok(best);
    };
    let reordered = on_chosen_branches(reordered, branches, home.as_ref(), watch)?;
    Ok(if reordered.is_better_than(&best) {
        reordered
    } else {
        best
    })
}

/// The choose-branches stage ([`choose_branches`]) on `drawing`: its strokes' branches chosen
/// for the job as a whole (the arm starting and ending at `home`), connected again, and kept
/// where that draws as much in less time.
fn on_chosen_branches(
    drawing: Connected,
    branches: &JobBranches<'_>,
    home: Option<&JointVector>,
    watch: &dyn Watch,
) -> Result<Connected, Stopped> {
    let placed_ends = &drawing.connection.placed_ends;
    let Some(chosen) = choose_branches(&drawing.strokes, placed_ends, home, branches) else {
        return Ok(drawing);
    };
    let moved_to: Vec<Option<JointVector>> = chosen.iter().map(|choice| choice.moved_to).collect();
    let strokes = drawing
        .strokes
        .iter()
        .zip(chosen)
        .map(|(stroke, choice)| PlannedStroke {
            oriented: stroke.oriented,
            plan: choice.plan,
            rank: choice.rank,
        })
        .collect();
    let connected = connect_strokes(branches, strokes, &moved_to, watch, "branches")?;
    Ok(if connected.is_better_than(&drawing) {
        connected
    } else {
        drawing
    })
}
