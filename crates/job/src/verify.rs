//! The independent check of a job's program (`emg check` on an `emg-job/3` file): every segment
//! replayed by the checker (`emg_verify`, which shares no kinematics with the planners), each
//! from rest to rest within the joint velocity, acceleration and jerk limits; a stroke part's
//! samples on its stretch of the stroke within the tolerance and the cone, clear of the arm's
//! own links, its work plate, the part the file's `surfaces` make and the scene; a move's
//! samples clear of the arm's own links, the part and the scene. Then the program's claims
//! against what its samples draw, measured with the checker's kinematics ([`crate::claims`]):
//! each stroke part's task is its stroke's stretch, no stroke claims more length drawn than its
//! samples cover, every stretch they leave undrawn is listed, and the summary's totals and
//! counts are the strokes'.

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering as AtomicOrdering};

use emg_control::{ConstraintConfig, MIN_SEGMENT_M, Path, Task, task_bounds};
use emg_io::JointTrajectoryPoint;
use emg_verify::{
    JointDynamics, JointSamples, Joints, Line, ReferenceModel, ReplayError, check_replay,
};
use rayon::prelude::*;

use crate::claims::{COVERAGE_SLACK_M, Coverage, OnStroke, Stretch};
use crate::free_space::{LIFT_CONE_RUN, PEN_UP_CLEARANCE_SHARE, with_part};
use crate::program::{JobFile, Segment, SegmentKind, StrokeReport};

/// How much (m) a length a program claims may differ from what the checker measures of its
/// samples: the rounding between the planners' kinematics and the checker's.
pub const CLAIM_TOLERANCE_M: f64 = 1e-6;

/// What the check verified.
#[derive(Clone, Debug, PartialEq)]
pub struct JobCheck {
    /// Segments verified: stroke parts and moves.
    pub stroke_parts: usize,
    /// See `stroke_parts`.
    pub moves: usize,
    /// Samples verified.
    pub points: usize,
    /// Strokes, and those whose samples cover them whole.
    pub strokes: usize,
    /// See `strokes`.
    pub whole_strokes: usize,
    /// Pen-down length the samples cover, and the strokes' total (m).
    pub drawn_m: f64,
    /// See `drawn_m`.
    pub total_m: f64,
}

/// Where a job's program fails the check.
#[derive(Debug, thiserror::Error)]
pub enum JobCheckError {
    /// The file names other joints than the robot's.
    #[error("the job's joints {found:?} are not the robot's {expected:?}")]
    Joints {
        /// The file's.
        found: Vec<String>,
        /// The robot's.
        expected: Vec<String>,
    },
    /// A stroke segment carries no task.
    #[error("segment {0} is a stroke without its task")]
    NoTask(usize),
    /// A stroke's claims are not what its samples draw.
    #[error("stroke {stroke}: {problem}")]
    Claim {
        /// The stroke's index in the job.
        stroke: usize,
        /// What the claim says and what the samples draw.
        problem: String,
    },
    /// The summary's totals or counts are not the strokes'.
    #[error("summary: {0}")]
    Summary(String),
    /// A pen-up move brings the tool's tip near the part away from its lift and set-down.
    #[error(
        "segment {segment} ({kind}), sample at {time_s:.3} s: the tool's tip is {:.3} mm above \
         the part and {:.3} mm across it from where the tool lifts off or sets down; a pen-up \
         move keeps it {:.3} mm above the part (half the lift) but on its lift and set-down \
         (within {LIFT_CONE_RUN} times its height across)",
        height_m * 1e3,
        off_m * 1e3,
        clearance_m * 1e3
    )]
    PenUp {
        /// The segment's index.
        segment: usize,
        /// What it does.
        kind: String,
        /// When.
        time_s: f64,
        /// The tip's height above the part there (m; negative inside it).
        height_m: f64,
        /// Its distance across the part from the nearer of the lift-off and set-down points (m).
        off_m: f64,
        /// The clearance a pen-up move keeps (m).
        clearance_m: f64,
    },
    /// A segment breaks a constraint.
    #[error("segment {segment} ({kind}, {start_s:.3} s to {end_s:.3} s): {error}")]
    Segment {
        /// Its index.
        segment: usize,
        /// What it does.
        kind: String,
        /// Its span (s).
        start_s: f64,
        /// See `start_s`.
        end_s: f64,
        /// What the checker found.
        error: ReplayError,
    },
}

/// Checks every segment of `file` with the checker `model` of its robot (joint names
/// `joint_names`).
pub fn verify_job(
    file: &JobFile,
    model: &ReferenceModel,
    joint_names: &[String],
) -> Result<JobCheck, JobCheckError> {
    if file.joint_names != joint_names {
        return Err(JobCheckError::Joints {
            found: file.joint_names.clone(),
            expected: joint_names.to_vec(),
        });
    }
    let dynamics = file.limits.dynamics();
    let on_part = with_part(&file.constraints, &file.surfaces);
    // Between strokes the tool leaves the line and turns freely: only the arm's clearances hold.
    let free = ConstraintConfig {
        line_tolerance_m: f64::INFINITY,
        theta_max_deg: 180.0,
        ..on_part.clone()
    };
    let all_points = file.points();
    let times: Vec<f64> = all_points
        .iter()
        .map(|p| p.time_from_start.seconds())
        .collect();
    let mut check = JobCheck {
        stroke_parts: 0,
        moves: 0,
        points: all_points.len(),
        strokes: file.strokes.len(),
        whole_strokes: 0,
        drawn_m: 0.0,
        total_m: 0.0,
    };
    // Each stroke's place in `strokes` (the first report of it).
    let mut places = HashMap::with_capacity(file.strokes.len());
    for (place, report) in file.strokes.iter().enumerate() {
        places.entry(report.stroke).or_insert(place);
    }
    // Segments are checked in parallel, each on its own; the outcome is the first failing
    // segment's in segment order (every segment before it is checked, whatever the threads),
    // else every segment's, gathered in segment order: the same on any number of threads.
    // A segment after one known to fail is not checked, since its outcome cannot matter.
    let first_failure = AtomicUsize::new(usize::MAX);
    let outcomes: Vec<Option<SegmentOutcome>> = file
        .segments
        .par_iter()
        .enumerate()
        .map(|(index, segment)| {
            if index > first_failure.load(AtomicOrdering::Relaxed) {
                return None;
            }
            let context = SegmentContext {
                file,
                model,
                dynamics: &dynamics,
                on_part: &on_part,
                free: &free,
                places: &places,
            };
            let outcome = context.verify_segment(index, segment, &all_points, &times);
            if outcome.is_err() {
                first_failure.fetch_min(index, AtomicOrdering::Relaxed);
            }
            Some(outcome)
        })
        .collect();
    // The stretch each stroke's parts' samples cover, by the stroke's place in `strokes`.
    let mut covered: Vec<Vec<Stretch>> = vec![Vec::new(); file.strokes.len()];
    for outcome in outcomes {
        // A segment is left unchecked only after a failing one, which returns first.
        match outcome.expect("every segment before the first failing one is checked")? {
            Some((place, stretch)) => {
                covered[place].push(stretch);
                check.stroke_parts += 1;
            }
            None => check.moves += 1,
        }
    }
    for (report, covered) in file.strokes.iter().zip(&covered) {
        let coverage = verify_claims(report, covered)?;
        check.whole_strokes += usize::from(coverage.whole());
        check.drawn_m += coverage.drawn_m;
        check.total_m += report.length_m;
    }
    verify_summary(file)?;
    verify_home(file, &all_points)?;
    Ok(check)
}

/// A segment's check: a stroke part's stroke (its place in the file's `strokes`) and the
/// stretch its samples cover, or `None` for a move.
type SegmentOutcome = Result<Option<(usize, Stretch)>, JobCheckError>;

/// What every segment's check shares.
struct SegmentContext<'a> {
    file: &'a JobFile,
    model: &'a ReferenceModel,
    dynamics: &'a JointDynamics,
    /// The constraints of a stroke part, the part in the scene.
    on_part: &'a ConstraintConfig,
    /// The constraints of a move: only the arm's clearances.
    free: &'a ConstraintConfig,
    /// Each stroke's place in the file's `strokes`.
    places: &'a HashMap<usize, usize>,
}

impl SegmentContext<'_> {
    /// Checks segment `index` (`segment`) on its samples among `all_points` (their times
    /// `times`): a stroke part's, then its task against its stroke, giving its stroke's place
    /// and the stretch its samples cover; a move's, giving `None`.
    fn verify_segment(
        &self,
        index: usize,
        segment: &Segment,
        all_points: &[JointTrajectoryPoint],
        times: &[f64],
    ) -> SegmentOutcome {
        let first = times.partition_point(|t| *t < segment.start_s - 1e-9);
        let last = times.partition_point(|t| *t <= segment.end_s + 1e-9);
        let points = &all_points[first..last];
        let samples = JointSamples {
            time_s: times[first..last].to_vec(),
            q: points.iter().map(|p| joints(&p.positions)).collect(),
            qd: Some(points.iter().map(|p| joints(&p.velocities)).collect()),
            qdd: Some(points.iter().map(|p| joints(&p.accelerations)).collect()),
        };
        let fail = |error| JobCheckError::Segment {
            segment: index,
            kind: segment_kind(&segment.kind),
            start_s: segment.start_s,
            end_s: segment.end_s,
            error,
        };
        match segment.kind {
            SegmentKind::Stroke {
                stroke,
                from_s,
                backward,
                ..
            } => {
                let on = OnStroke { from_s, backward };
                let task = segment.task.as_ref().ok_or(JobCheckError::NoTask(index))?;
                let line: Line = task.into();
                let report = check_replay(
                    self.model,
                    &line,
                    &task_bounds(task, self.on_part),
                    &samples,
                    None,
                    Some(self.dynamics),
                )
                .map_err(fail)?;
                let place = *self
                    .places
                    .get(&stroke)
                    .ok_or_else(|| JobCheckError::Claim {
                        stroke,
                        problem: format!("segment {index} draws it, but no stroke report has it"),
                    })?;
                on_its_stroke(&self.file.strokes[place], task, on, index)?;
                // What `Line::covered` gives of the samples' TCPs.
                let (least, greatest) = report.progress_range_m;
                Ok(Some((place, on.stretch(least, greatest))))
            }
            _ => {
                // The whole part is in `free`'s scene: one surface's task frames the replay.
                if let Some(task) = self.file.surfaces.first() {
                    check_replay(
                        self.model,
                        &task.into(),
                        &task_bounds(task, self.free),
                        &samples,
                        None,
                        Some(self.dynamics),
                    )
                    .map_err(fail)?;
                }
                self.verify_pen_up(index, segment, &samples, all_points, times)?;
                Ok(None)
            }
        }
    }
}

impl SegmentContext<'_> {
    /// Checks that the pen-up move segment `index` (`segment`, its samples `samples` among
    /// `points`, whose times are `times`) keeps the tool's tip [`PEN_UP_CLEARANCE_SHARE`] of the
    /// lift above every plate of the part it passes over, but on the lift and the set-down:
    /// across the plate by at most [`LIFT_CONE_RUN`] times its height above where the run of
    /// moves it belongs to leaves the part or meets it again, from that point. A move that sags would drag the
    /// tool across the part.
    fn verify_pen_up(
        &self,
        index: usize,
        segment: &Segment,
        samples: &JointSamples,
        points: &[JointTrajectoryPoint],
        times: &[f64],
    ) -> Result<(), JobCheckError> {
        let clearance_m = PEN_UP_CLEARANCE_SHARE * self.file.settings.lift();
        let is_move = |k: usize| !matches!(self.file.segments[k].kind, SegmentKind::Stroke { .. });
        let first = (0..index)
            .rev()
            .take_while(|&k| is_move(k))
            .last()
            .unwrap_or(index);
        let last = (index + 1..self.file.segments.len())
            .take_while(|&k| is_move(k))
            .last()
            .unwrap_or(index);
        let tip_at = |time_s: f64| {
            let k = times
                .partition_point(|t| *t < time_s - 1e-9)
                .min(points.len() - 1);
            self.model.tcp_pose(&joints(&points[k].positions)).0
        };
        let ends = [
            tip_at(self.file.segments[first].start_s),
            tip_at(self.file.segments[last].end_s),
        ];
        for (q, &time_s) in samples.q.iter().zip(&samples.time_s) {
            let tip = self.model.tcp_pose(q).0;
            for task in &self.file.surfaces {
                let (p0, d, n) = (task.p0, task.d, task.n);
                let emg_kinematics::WorkSurface::Plate(plate) =
                    task.work_surface(&self.on_part.work_surface)
                else {
                    continue;
                };
                let offset = tip - p0;
                let (along, across, height_m) =
                    (offset.dot(&d), offset.dot(&n.cross(&d)), -offset.dot(&n));
                let over = (-plate.behind_m..=plate.ahead_m).contains(&along)
                    && across.abs() <= plate.half_width_m;
                if !over || height_m >= clearance_m - CLAIM_TOLERANCE_M {
                    continue;
                }
                // Across the plate from each end, and the room the lift cone leaves there.
                let (off_m, room_m) = ends
                    .iter()
                    .map(|end| {
                        let beside = tip - end;
                        let risen = -beside.dot(&n);
                        ((beside + n * risen).norm(), LIFT_CONE_RUN * risen.max(0.0))
                    })
                    .fold((f64::INFINITY, 0.0), |nearer, end| {
                        if end.0 - end.1 < nearer.0 - nearer.1 {
                            end
                        } else {
                            nearer
                        }
                    });
                if off_m > room_m + CLAIM_TOLERANCE_M {
                    return Err(JobCheckError::PenUp {
                        segment: index,
                        kind: segment_kind(&segment.kind),
                        time_s,
                        height_m,
                        off_m,
                        clearance_m,
                    });
                }
            }
        }
        Ok(())
    }
}

/// What a segment of kind `kind` does, as the check names it.
fn segment_kind(kind: &SegmentKind) -> String {
    match kind {
        SegmentKind::Stroke { stroke, part, .. } => format!("stroke {stroke} part {part}"),
        SegmentKind::Retreat => "retreat".to_string(),
        SegmentKind::Travel => "travel".to_string(),
        SegmentKind::Approach => "approach".to_string(),
    }
}

/// Checks that `task`, the task of stroke part segment `segment`, is its stroke's stretch from
/// `on.from_s` (back toward its start where `on.backward`): their points agree along the whole
/// task (to the pieces shorter than [`MIN_SEGMENT_M`] that a stretch leaves out).
fn on_its_stroke(
    report: &StrokeReport,
    task: &Task,
    on: OnStroke,
    segment: usize,
) -> Result<(), JobCheckError> {
    let from_s = on.from_s;
    let claim = |problem: String| JobCheckError::Claim {
        stroke: report.stroke,
        problem,
    };
    let path = Path::new(report.path.clone())
        .map_err(|e| claim(format!("its path is not a valid path: {e}")))?;
    let length = task.length_m().unwrap_or(0.0);
    const CHECKS: usize = 64;
    for k in 0..=CHECKS {
        let s = length * k as f64 / CHECKS as f64;
        let off = (task.point_at(s) - path.point_at(on.stroke_s(s))).norm();
        if off > 2.0 * MIN_SEGMENT_M {
            return Err(claim(format!(
                "segment {segment}'s task is not the stroke's stretch from {from_s:.4} m: {s:.4} m                  along it lies {off:.3e} m off the stroke"
            )));
        }
    }
    Ok(())
}

/// Checks a stroke's claims against the stretches its parts' samples cover (`covered`, as the
/// checker measures them); returns the coverage measured.
fn verify_claims(report: &StrokeReport, covered: &[Stretch]) -> Result<Coverage, JobCheckError> {
    let claim = |problem: String| JobCheckError::Claim {
        stroke: report.stroke,
        problem,
    };
    let length = Path::new(report.path.clone())
        .map_err(|e| claim(format!("its path is not a valid path: {e}")))?
        .length_m();
    if (length - report.length_m).abs() > CLAIM_TOLERANCE_M {
        return Err(claim(format!(
            "claims a length of {} m; its path is {length} m long",
            report.length_m
        )));
    }
    if report.parts != covered.len() {
        return Err(claim(format!(
            "claims {} parts; the program draws {}",
            report.parts,
            covered.len()
        )));
    }
    let measured = Coverage::of(length, covered);
    if report.drawn_m > measured.drawn_m + CLAIM_TOLERANCE_M {
        return Err(claim(format!(
            "claims {:.6} m drawn; its samples draw {:.6} m of its {length:.6} m",
            report.drawn_m, measured.drawn_m
        )));
    }
    for gap in &measured.undrawn {
        let listed: f64 = report
            .unreached
            .iter()
            .map(|u| (u.to_s.min(gap.to_s) - u.from_s.max(gap.from_s)).max(0.0))
            .sum();
        if listed < gap.length_m() - COVERAGE_SLACK_M {
            return Err(claim(format!(
                "{:.4} m to {:.4} m along it is not drawn, and not listed as unreached",
                gap.from_s, gap.to_s
            )));
        }
    }
    if report.unreached_at.len() != report.unreached.len() {
        return Err(claim(format!(
            "lists {} unreached stretches but {} places where they start",
            report.unreached.len(),
            report.unreached_at.len()
        )));
    }
    if report.unreached_causes.len() != report.unreached.len() {
        return Err(claim(format!(
            "lists {} unreached stretches but {} causes",
            report.unreached.len(),
            report.unreached_causes.len()
        )));
    }
    Ok(measured)
}

/// Checks that the program (its samples `points`) starts at its home, and ends there where it
/// says it does.
fn verify_home(
    file: &JobFile,
    points: &[emg_io::JointTrajectoryPoint],
) -> Result<(), JobCheckError> {
    let at = |point: Option<&emg_io::JointTrajectoryPoint>, home: &[f64]| {
        point.is_some_and(|p| {
            p.positions.len() == home.len()
                && p.positions
                    .iter()
                    .zip(home)
                    .all(|(q, h)| (q - h).abs() <= 1e-9)
        })
    };
    match &file.home {
        Some(home) if !at(points.first(), home) => Err(JobCheckError::Summary(format!(
            "the program does not start at its home {home:?}"
        ))),
        Some(home) if file.summary.ends_at_home && !at(points.last(), home) => Err(
            JobCheckError::Summary(format!("the program does not end at its home {home:?}")),
        ),
        None if file.summary.ends_at_home => Err(JobCheckError::Summary(
            "says the program ends at its home, but it has none".to_string(),
        )),
        _ => Ok(()),
    }
}

/// Checks that the summary's totals and counts are the strokes' claims.
fn verify_summary(file: &JobFile) -> Result<(), JobCheckError> {
    let summary = &file.summary;
    let drawn: f64 = file.strokes.iter().map(|r| r.drawn_m).sum();
    let total: f64 = file.strokes.iter().map(|r| r.length_m).sum();
    let whole = |parts: fn(usize) -> bool| {
        file.strokes
            .iter()
            .filter(|r| r.unreached.is_empty() && r.parts > 0 && parts(r.parts))
            .count()
    };
    let complete = whole(|parts| parts == 1);
    let resumed = whole(|parts| parts > 1);
    let short = file.strokes.len() - complete - resumed;
    let tolerance = CLAIM_TOLERANCE_M * (1 + file.strokes.len()) as f64;
    if (summary.drawn_m - drawn).abs() > tolerance || (summary.total_m - total).abs() > tolerance {
        return Err(JobCheckError::Summary(format!(
            "pen down {} m of {} m; the strokes claim {drawn} m of {total} m",
            summary.drawn_m, summary.total_m
        )));
    }
    if (summary.complete, summary.resumed, summary.short) != (complete, resumed, short) {
        return Err(JobCheckError::Summary(format!(
            "{} complete, {} resumed, {} short; the strokes are {complete} complete, {resumed}              resumed, {short} short",
            summary.complete, summary.resumed, summary.short
        )));
    }
    Ok(())
}

/// A checker's joint vector from a file's values.
fn joints(values: &[f64]) -> Joints {
    let mut q = Joints::zeros();
    for (i, v) in values.iter().enumerate() {
        q[i] = *v;
    }
    q
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use emg_io::{Placement, SvgOptions, read_svg_file};
    use emg_kinematics::Robot;
    use emg_planner::{DataDir, Models, PlanRequest, Planner, ShippedRobot};

    use super::*;
    use crate::{JOB_TOLERANCE_M, Job, Unwatched, job_config, job_timing, plan_job};

    /// A line-art icon (lucide's `pencil`, vendored with the SVG reader's tests) planned on the
    /// FR3 as `emg job` plans it, the FR3's checker and joint names.
    fn pencil_on_the_fr3() -> (JobFile, ReferenceModel, Vec<String>) {
        let workspace = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
        let data = DataDir::new(workspace.join("data"));
        let shipped = ShippedRobot::by_name("fr3").expect("a shipped robot");
        let file = shipped.path(&data);
        let robot = Robot::from_chain_file(&file).expect("robot loads");
        let checker = ReferenceModel::from_urdf_file(&file, robot.base_link(), robot.tip_link())
            .expect("checker loads");
        let names = robot.joint_names().to_vec();
        let models = Models::shipped(&robot, &shipped.data_dir(&data)).expect("shipped models");
        let config = job_config(JOB_TOLERANCE_M);
        let timing = job_timing(&robot, &file, &config).expect("timing");
        let planner = Planner::new(robot, models, config).expect("planner");
        let icon = workspace.join("crates/io/tests/data/icons/pencil.svg");
        let strokes = read_svg_file(&icon, &Placement::default(), &SvgOptions::default())
            .expect("icon")
            .strokes;
        let job = Job::from_strokes(strokes, planner.robot()).expect("a valid job");
        let program = plan_job(
            &planner,
            &PlanRequest::default(),
            &job,
            &timing,
            &file.display().to_string(),
            &Unwatched,
        )
        .expect("the job plans");
        (program, checker, names)
    }

    /// `verify_job` on a pool of `threads` threads, its error as text.
    fn on_threads(
        threads: usize,
        program: &JobFile,
        checker: &ReferenceModel,
        names: &[String],
    ) -> Result<JobCheck, String> {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
            .install(|| verify_job(program, checker, names))
            .map_err(|e| e.to_string())
    }

    #[test]
    fn a_program_checks_alike_on_any_number_of_threads() {
        let (program, checker, names) = pencil_on_the_fr3();
        let one = on_threads(1, &program, &checker, &names);
        assert!(one.is_ok(), "{one:?}");
        for threads in [2, 3, 8] {
            assert_eq!(on_threads(threads, &program, &checker, &names), one);
        }
        // Every stroke part breaks a line tolerance of 1 nm, and so does every segment after
        // the first: the first stroke part's failure is reported, whatever the threads.
        let mut tight = program.clone();
        tight.constraints.line_tolerance_m = 1e-9;
        let first_part = program
            .segments
            .iter()
            .position(|s| matches!(s.kind, SegmentKind::Stroke { .. }))
            .expect("a stroke part");
        let failure = on_threads(1, &tight, &checker, &names).expect_err("too tight");
        assert!(
            failure.starts_with(&format!("segment {first_part} (stroke ")),
            "{failure}"
        );
        for threads in [2, 3, 8] {
            assert_eq!(
                on_threads(threads, &tight, &checker, &names),
                Err(failure.clone())
            );
        }
    }
}
