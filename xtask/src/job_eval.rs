//! `cargo xtask job-eval`: jobs planned as `emg job` plans them, on line-art icons (the
//! lucide-static 1.62.0 icons vendored with the SVG reader's tests, or any directory of SVGs)
//! placed in front of the arm at several positions and sizes, and on generated seams on tilted
//! surfaces, each starting and ending at the arm's home; every program re-checked segment by
//! segment by the independent checker, its claims among the rest, and measured for how far its
//! joints stray from the home and how far its moves turn them; beside the
//! baseline a user scripts today (each stroke planned alone by the search, one motion, the strokes
//! joined by straight joint moves with no lift and no collision check):
//! `docs/results/jobs.{json,md}`.

use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use emg_control::{PathSpec, SegmentSpec};
use emg_io::{Placement, read_svg_file};
use emg_job::{
    FreeSpace, Job, JobCheckError, JobFile, JobPlanner, JobSettings, Order, SegmentKind, Unwatched,
    job_part, order_strokes, part_coverage, plan_stroke, valley_seams, verify_job,
};
use emg_kinematics::{JointVector, Vec3};
use emg_planner::{MotionTiming, PlanRequest, Planner, ShippedRobot};
use emg_timing::time_free_move;
use serde::{Deserialize, Serialize};

use crate::task_set_options::ROBOT_WITH_JOINT_LIMITS;
use crate::{progress, workspace};

mod industrial_programs;
mod krl_programs;
mod large;
mod rapid_programs;
mod ur_programs;

/// The icons, robot file and output directory of an evaluation of jobs on icons.
#[derive(clap::Args)]
pub struct IconJobOptions {
    /// Directory of SVG icons (every `*.svg` in it, in name order).
    #[arg(long, default_value_os_t = workspace::root().join("crates/io/tests/data/icons"))]
    pub icons: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    pub robot: PathBuf,
    /// Output directory of the result files.
    #[arg(long, default_value_os_t = workspace::results_dir())]
    pub out_dir: PathBuf,
}

/// Options of `job-eval`.
#[derive(clap::Args)]
#[command(
    mut_arg("robot", |arg| arg.help(ROBOT_WITH_JOINT_LIMITS)),
    mut_arg("out_dir", |arg| arg.help("Output directory of jobs.{json,md}")),
)]
pub struct Args {
    /// Icons, robot file and output directory.
    #[command(flatten)]
    common: IconJobOptions,
    /// Sizes of the large jobs (strokes of generated drawings, comma-separated), each planned
    /// on all threads and on one; none with `--large` alone.
    #[arg(long, value_delimiter = ',', num_args = 0.., default_value = "500,2000,10000")]
    large: Vec<usize>,
}

/// Where an icon is placed: the centre of its bounding box (m) and its width (m), pen down.
const PLACES: [([f64; 3], f64); 4] = [
    ([0.45, 0.0, 0.25], 0.15),
    ([0.45, 0.0, 0.25], 0.3),
    ([0.4, 0.25, 0.2], 0.2),
    ([0.5, -0.25, 0.3], 0.2),
];

/// The large drawing whose program is also written for the industrial controllers and read
/// back (strokes).
const READ_BACK_STROKES: usize = 500;

/// One job's outcome.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct JobRow {
    /// The icon's file name and its place, or the seams' surface.
    pub job: String,
    /// Strokes, and those drawn whole in one part, whole in several, not whole.
    pub strokes: usize,
    /// See `strokes`.
    pub complete: usize,
    /// See `strokes`.
    pub resumed: usize,
    /// See `strokes`.
    pub short: usize,
    /// Pen-down length drawn and in all (m).
    pub drawn_m: f64,
    /// See `drawn_m`.
    pub total_m: f64,
    /// Program duration pen down and pen up (s).
    pub pen_down_s: f64,
    /// See `pen_down_s`.
    pub pen_up_s: f64,
    /// The least duration pen down and pen up the arm's limits allow for the same parts
    /// (`JobSummary::least_pen_down_s`, `least_pen_up_s`) (s).
    #[serde(default)]
    pub least_pen_down_s: f64,
    /// See `least_pen_down_s`.
    #[serde(default)]
    pub least_pen_up_s: f64,
    /// Planning time of the whole job (s) on this machine.
    pub planning_s: f64,
    /// Free moves straight, and found by the sampling planner.
    pub straight_moves: usize,
    /// See `straight_moves`.
    pub sampled_moves: usize,
    /// Whether the independent checker refused the program, and why.
    pub checker_failure: Option<String>,
    /// Whether the checker refused it for claiming more than its samples draw.
    pub claims_exceed: bool,
    /// The largest distance of a joint from its home value over the program (rad).
    pub from_home_rad: f64,
    /// Moves: every segment but the strokes.
    pub moves: usize,
    /// Moves turning a joint more than half a turn, and of
    /// those the ones where that joint could have reached the same angle turning less, the
    /// other way round, within its limits.
    pub moves_over_half_turn: usize,
    /// See `moves_over_half_turn`.
    pub moves_the_long_way: usize,
    /// The baseline: pen-down length its one motion per stroke draws (m), its duration (s), its
    /// straight moves and those of them that collide.
    pub baseline_drawn_m: f64,
    /// See `baseline_drawn_m`.
    pub baseline_duration_s: f64,
    /// See `baseline_drawn_m`.
    pub baseline_moves: usize,
    /// See `baseline_drawn_m`.
    pub baseline_colliding_moves: usize,
}

/// The name of the job of [`grid_of_circles`]`(10, 10, …)`.
const GRID: &str = "100 circles 2 cm across in a 10 × 10 grid";

/// The name of the job of [`hatch`].
const HATCH: &str = "100 parallel seams 0.2 m long, 3 mm apart";

/// A job of 100 strokes: seams 0.2 m long along the base's y, 3 mm apart along its x from
/// (0.3, −0.1, 0.25), pen down.
fn hatch() -> Vec<PathSpec> {
    (0..100)
        .map(|k| {
            let x = 0.3 + 0.003 * k as f64;
            PathSpec {
                version: emg_control::PATH_FORMAT_VERSION,
                start: [x, -0.1, 0.25],
                normal: [0.0, 0.0, -1.0],
                blend_radius_m: 0.0,
                segments: vec![SegmentSpec::Line { to: [x, 0.1, 0.25] }],
            }
        })
        .collect()
}

/// A job of `rows × columns` strokes: circles of 1 cm radius, 3 cm apart in a grid pen down
/// round `centre` (m), rows along the base's x.
pub fn grid_of_circles(rows: usize, columns: usize, centre: [f64; 3]) -> Vec<PathSpec> {
    let centre = Vec3::from(centre);
    (0..rows * columns)
        .map(|k| {
            let middle = centre
                + Vec3::new(
                    0.03 * ((k / columns) as f64 - 0.5 * (rows - 1) as f64),
                    0.03 * ((k % columns) as f64 - 0.5 * (columns - 1) as f64),
                    0.0,
                );
            PathSpec {
                version: emg_control::PATH_FORMAT_VERSION,
                start: (middle + Vec3::new(0.01, 0.0, 0.0)).into(),
                normal: [0.0, 0.0, -1.0],
                blend_radius_m: 0.0,
                segments: vec![SegmentSpec::Arc {
                    centre: Some(middle.into()),
                    through: None,
                    to: None,
                    sweep_deg: Some(360.0),
                }],
            }
        })
        .collect()
}

/// The whole record written to `jobs.json`.
#[derive(Serialize, Deserialize)]
pub struct Record {
    /// Robot name.
    pub robot: String,
    /// The command that wrote it.
    pub command: String,
    /// The icons' directory, relative to the workspace.
    pub icons: String,
    /// Machine and threads.
    pub machine: String,
    /// Threads the jobs of `rows` were planned on.
    pub threads: usize,
    /// Planning time of each 100-stroke job ([`GRID`], [`HATCH`]) on one thread (s).
    pub one_thread_s: Vec<(String, f64)>,
    /// Every job.
    pub rows: Vec<JobRow>,
    /// The large jobs, each on all threads and on one.
    #[serde(default)]
    pub large: Vec<large::LargeRow>,
    /// On the UR5e, each program of `rows` exported both ways and read back.
    #[serde(default)]
    pub ur_programs: Vec<ur_programs::UrRow>,
    /// On the IRB 120, each program of `rows` written as a RAPID module and read back.
    #[serde(default)]
    pub rapid_programs: Vec<rapid_programs::RapidRow>,
    /// On the KR 16, each program of `rows` written as a KRL program and read back.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub krl_programs: Vec<krl_programs::KrlRow>,
}

/// The readers of the controllers' own programs a job-eval arm has: the UR5e's native
/// programs, the IRB 120's RAPID modules, the KR 16's KRL programs.
struct Readers<'a> {
    ur: Option<ur_programs::UrArm<'a>>,
    rapid: Option<rapid_programs::RapidArm<'a>>,
    krl: Option<krl_programs::KrlArm<'a>>,
}

/// A job's program as each controller of its arm runs it, read back.
#[derive(Default)]
struct ProgramRows {
    ur: Option<ur_programs::UrRow>,
    rapid: Option<rapid_programs::RapidRow>,
    krl: Option<krl_programs::KrlRow>,
}

/// Plans, checks and compares every job; writes the record and its table.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let (job_planner, checker) = setup(&args.common.robot)?;
    let planner = job_planner.planner();
    let shipped = ShippedRobot::by_path(&args.common.robot, &workspace::data_dir())
        .context("job-eval plans the shipped arms, whose homes it starts from")?;
    let home = shipped.home;
    // The arm whose controller's frames a native UR program is written in: the UR5e.
    let ur_arm = emg_io::DriverProfile::for_shipped(shipped.name)
        .filter(|profile| profile.has_ur_controller_frames())
        .map(|profile| ur_programs::UrArm {
            robot: planner.robot(),
            robot_file: &args.common.robot,
            profile,
            checker: &checker,
        });
    // The arm whose controller's frames a RAPID module is written in: the IRB 120.
    let rapid_arm = (shipped.name == "irb120").then(|| rapid_programs::RapidArm {
        robot: planner.robot(),
        robot_file: &args.common.robot,
        checker: &checker,
    });
    // The arm whose controller's frames a KRL program is written in: the KR 16.
    let krl_arm = if shipped.name == "kr16" {
        let flange = emg_kinematics::Robot::from_urdf_file(
            &args.common.robot,
            planner.robot().base_link(),
            "tool0",
        )?;
        Some(krl_programs::KrlArm {
            robot: planner.robot(),
            robot_file: &args.common.robot,
            tool_in_flange: emg_job::krl_program::tool_in_flange(planner.robot(), &flange)?,
            checker: &checker,
        })
    } else {
        None
    };
    let readers = Readers {
        ur: ur_arm,
        rapid: rapid_arm,
        krl: krl_arm,
    };
    let jobs = jobs(&args.common.icons, planner, home)?;
    let bar = progress::bar(jobs.len() as u64, "jobs");
    let mut rows = Vec::new();
    let (mut ur_rows, mut rapid_rows, mut krl_rows) = (Vec::new(), Vec::new(), Vec::new());
    for (name, job) in &jobs {
        let (row, programs) = evaluate(&job_planner, &checker, (name, job), &readers)?;
        rows.push(row);
        ur_rows.extend(programs.ur);
        rapid_rows.extend(programs.rapid);
        krl_rows.extend(programs.krl);
        bar.inc(1);
    }
    bar.finish();
    let one_thread_s = one_thread_times(&jobs, &job_planner)?;
    let mut large_rows = Vec::new();
    let sizes = progress::bar(2 * args.large.len() as u64, "large jobs");
    for &strokes in &args.large {
        for threads in [None, Some(1)] {
            let (row, program) = large::evaluate(&job_planner, &checker, home, strokes, threads)?;
            // The smallest large drawing's program, as the industrial controllers run it.
            if threads.is_none() && strokes == READ_BACK_STROKES {
                let name = format!("{strokes} scattered strokes");
                rapid_rows.extend(
                    readers
                        .rapid
                        .as_ref()
                        .map(|arm| rapid_programs::read_back(arm, &name, &program)),
                );
                krl_rows.extend(
                    readers
                        .krl
                        .as_ref()
                        .map(|arm| krl_programs::read_back(arm, &name, &program)),
                );
            }
            large_rows.push(row);
            sizes.inc(1);
        }
    }
    sizes.finish();
    let record = Record {
        robot: planner.robot().name().to_string(),
        command: workspace::command_for("job-eval", &args.common.robot),
        icons: workspace::relative(&args.common.icons),
        machine: workspace::machine(),
        threads: rayon::current_num_threads(),
        one_thread_s,
        rows,
        large: large_rows,
        ur_programs: ur_rows,
        rapid_programs: rapid_rows,
        krl_programs: krl_rows,
    };
    workspace::write_results(&args.common.out_dir, "jobs", &record, &markdown(&record))?;
    ensure_checked(&record)
}

/// The jobs of the evaluation, each by its name: every icon of `icons` at every place, the
/// seams on tilted surfaces, the valley seams as given and in the order of least travel, and
/// the jobs of hundreds of strokes; each starting and ending at the arm's `home`. The places are
/// the FR3's, moved with the arm's default drawing place (`emg_job::default_placement`: the
/// same on every shipped arm but the KR 16, whose reach is larger).
fn jobs(icons: &Path, planner: &Planner, home: &[f64]) -> anyhow::Result<Vec<(String, Job)>> {
    let offset = Vec3::from(emg_job::default_placement(planner.robot()).origin_m)
        - Vec3::from(Placement::default().origin_m);
    let moved = |strokes: Vec<PathSpec>| -> Vec<PathSpec> {
        if offset == Vec3::zeros() {
            return strokes;
        }
        let motion = nalgebra::Isometry3::translation(offset.x, offset.y, offset.z);
        strokes.iter().map(|stroke| stroke.moved(&motion)).collect()
    };
    let with_home = |strokes: Vec<PathSpec>| {
        Job::from_strokes(moved(strokes), planner.robot())
            .and_then(|job| job.with_home(home, planner.robot()))
    };
    let mut jobs: Vec<(String, Job)> = Vec::new();
    let icons = icon_files(icons)?;
    let tolerance = emg_job::DrawingTolerance::new(emg_job::JOB_TOLERANCE_M, 0.0)?;
    for icon in &icons {
        for (origin, width) in PLACES {
            // Moved, to a nanometre, so that the place prints as it reads.
            let origin: [f64; 3] =
                std::array::from_fn(|i| ((origin[i] + offset[i]) * 1e9).round() / 1e9);
            let placement = Placement {
                origin_m: origin,
                width_m: Some(width),
                ..Placement::default()
            };
            let drawing = read_svg_file(icon, &placement, &tolerance.svg_options())?;
            let name = format!(
                "{} at ({}, {}, {}), {} m wide",
                icon.file_name().unwrap_or_default().to_string_lossy(),
                origin[0],
                origin[1],
                origin[2],
                width
            );
            let job = tolerance.job(drawing, planner.robot())?;
            jobs.push((name, job.with_home(home, planner.robot())?));
        }
    }
    for tilt_deg in [0.0, 20.0, 40.0] {
        jobs.push((
            format!("5 seams on a surface tilted {tilt_deg}°"),
            with_home(seams(tilt_deg))?,
        ));
    }
    let valley = with_home(valley_seams())?;
    jobs.push((
        format!("{VALLEY}, in the order of least travel"),
        in_travel_order(&valley),
    ));
    jobs.push((VALLEY.to_string(), valley));
    let hundreds = [
        (GRID, grid_of_circles(10, 10, [0.45, 0.0, 0.25])),
        (HATCH, hatch()),
    ];
    for (name, strokes) in &hundreds {
        jobs.push((name.to_string(), with_home(strokes.clone())?));
    }
    Ok(jobs)
}

/// The time (s) of planning each job of hundreds of strokes (`GRID`, `HATCH`) on one thread.
fn one_thread_times(
    jobs: &[(String, Job)],
    job_planner: &JobPlanner,
) -> anyhow::Result<Vec<(String, f64)>> {
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let mut one_thread_s = Vec::new();
    for (name, job) in jobs
        .iter()
        .filter(|(name, _)| [GRID, HATCH].contains(&name.as_str()))
    {
        let started = Instant::now();
        one_thread.install(|| job_planner.plan(job, &Unwatched))?;
        one_thread_s.push((name.clone(), started.elapsed().as_secs_f64()));
    }
    Ok(one_thread_s)
}

/// An error where a program fails the checker, or a UR program or RAPID module does not read
/// back.
fn ensure_checked(record: &Record) -> anyhow::Result<()> {
    let failures = record
        .rows
        .iter()
        .filter(|r| r.checker_failure.is_some())
        .count();
    let failures = failures
        + record
            .large
            .iter()
            .filter(|r| r.checker_failure.is_some())
            .count();
    anyhow::ensure!(failures == 0, "{failures} programs fail the checker");
    let unread: Vec<&str> = record
        .ur_programs
        .iter()
        .filter_map(|r| r.failure.as_deref())
        .chain(
            record
                .rapid_programs
                .iter()
                .filter_map(|r| r.read.failure.as_deref()),
        )
        .chain(
            record
                .krl_programs
                .iter()
                .filter_map(|r| r.read.failure.as_deref()),
        )
        .collect();
    anyhow::ensure!(
        unread.is_empty(),
        "{} controller programs do not read back:\n{}",
        unread.len(),
        unread.join("\n")
    );
    Ok(())
}

/// Every `*.svg` of `dir`, in name order (at least one).
pub fn icon_files(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut icons: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.extension().is_some_and(|ext| ext == "svg"))
        .collect();
    icons.sort();
    anyhow::ensure!(!icons.is_empty(), "no SVG in {}", dir.display());
    Ok(icons)
}

/// What `emg job` plans with (the cell's plate, the corrected step, 0.5 mm; its timing and
/// request) and the checker, for the selected robot's `robot_file`, which programs name.
pub fn setup(robot_file: &Path) -> anyhow::Result<(JobPlanner, emg_verify::ReferenceModel)> {
    setup_with_tasks(robot_file, &workspace::data("tasks/eval-v1.tasks"))
}

/// [`setup`] for `robot_file`, its models checked on the task file `tasks` (its own arm's).
pub fn setup_with_tasks(
    robot_file: &Path,
    tasks: &Path,
) -> anyhow::Result<(JobPlanner, emg_verify::ReferenceModel)> {
    let workspace::PlannerSetup {
        planner, checker, ..
    } = workspace::planner_setup(robot_file, tasks, 0, "job-eval")?;
    let planner = planner.with_config(emg_job::job_config(emg_job::JOB_TOLERANCE_M))?;
    let recorded_as = robot_file.display().to_string();
    Ok((JobPlanner::new(planner, robot_file, recorded_as)?, checker))
}

/// Five parallel seams 0.2 m long, 3 cm apart, on a surface through (0.45, 0, 0.25) whose
/// normal is turned `tilt_deg` from straight down about the base's x axis.
fn seams(tilt_deg: f64) -> Vec<PathSpec> {
    let tilt = tilt_deg.to_radians();
    let normal = Vec3::new(0.0, libm::sin(tilt), -libm::cos(tilt));
    let across = Vec3::x();
    let along = normal.cross(&across).normalize();
    let centre = Vec3::new(0.45, 0.0, 0.25);
    (0..5)
        .map(|k| {
            let offset = across * (0.03 * (k as f64 - 2.0));
            let start = centre + offset - along * 0.1;
            PathSpec {
                version: emg_control::PATH_FORMAT_VERSION,
                start: start.into(),
                normal: normal.into(),
                blend_radius_m: 0.0,
                segments: vec![SegmentSpec::Line {
                    to: (start + along * 0.2).into(),
                }],
            }
        })
        .collect()
}

/// The name of the job of [`valley_seams`].
const VALLEY: &str = "12 seams across a valley, 6 on each face";

/// `job` with its strokes listed in the order and directions of least pen-up travel (the order
/// stage's, without merging) and drawn as listed: the order the reorder stage starts from.
fn in_travel_order(job: &Job) -> Job {
    let ordering = order_strokes(&job.strokes, Order::Shortest);
    let mut listed = job.clone();
    listed.strokes = ordering
        .sequence
        .iter()
        .map(|oriented| oriented.path(&job.strokes))
        .collect();
    listed.settings.order = Order::Given;
    listed
}

/// `job` (named `name`) planned, checked and compared with the baseline; on the UR5e its
/// program exported both ways and read back, on the IRB 120 written as a RAPID module and read
/// back (`readers`).
fn evaluate(
    job_planner: &JobPlanner,
    checker: &emg_verify::ReferenceModel,
    (name, job): (&str, &Job),
    readers: &Readers<'_>,
) -> anyhow::Result<(JobRow, ProgramRows)> {
    let planner = job_planner.planner();
    let started = Instant::now();
    let planned = job_planner.plan(job, &Unwatched);
    let planning_s = started.elapsed().as_secs_f64();
    let baseline = baseline(planner, job_planner.timing(), job);
    let total_m: f64 = job.strokes.iter().map(|s| s.length_m()).sum();
    let programs = match &planned {
        Ok(program) => ProgramRows {
            ur: readers
                .ur
                .as_ref()
                .map(|arm| ur_programs::read_back(arm, name, program)),
            rapid: readers
                .rapid
                .as_ref()
                .map(|arm| rapid_programs::read_back(arm, name, program)),
            krl: readers
                .krl
                .as_ref()
                .map(|arm| krl_programs::read_back(arm, name, program)),
        },
        Err(_) => ProgramRows::default(),
    };
    let row = match planned {
        Ok(program) => {
            let s = &program.summary;
            let checked = verify_job(&program, checker, planner.robot().joint_names());
            let turns = move_turns(&program, planner.robot().limits());
            JobRow {
                job: name.to_string(),
                strokes: job.strokes.len(),
                complete: s.complete,
                resumed: s.resumed,
                short: s.short,
                drawn_m: s.drawn_m,
                total_m,
                pen_down_s: s.pen_down_s,
                pen_up_s: s.pen_up_s,
                least_pen_down_s: s.least_pen_down_s,
                least_pen_up_s: s.least_pen_up_s,
                planning_s,
                straight_moves: s.straight_moves,
                sampled_moves: s.sampled_moves,
                checker_failure: checked.as_ref().err().map(|e| e.to_string()),
                claims_exceed: matches!(
                    checked,
                    Err(JobCheckError::Claim { .. } | JobCheckError::Summary(_))
                ),
                from_home_rad: from_home_rad(&program),
                moves: turns.moves,
                moves_over_half_turn: turns.over_half,
                moves_the_long_way: turns.long_way,
                baseline_drawn_m: baseline.drawn_m,
                baseline_duration_s: baseline.duration_s,
                baseline_moves: baseline.moves,
                baseline_colliding_moves: baseline.colliding,
            }
        }
        Err(_) => JobRow {
            job: name.to_string(),
            strokes: job.strokes.len(),
            complete: 0,
            resumed: 0,
            short: job.strokes.len(),
            drawn_m: 0.0,
            total_m,
            pen_down_s: 0.0,
            pen_up_s: 0.0,
            least_pen_down_s: 0.0,
            least_pen_up_s: 0.0,
            planning_s,
            straight_moves: 0,
            sampled_moves: 0,
            checker_failure: None,
            claims_exceed: false,
            from_home_rad: 0.0,
            moves: 0,
            moves_over_half_turn: 0,
            moves_the_long_way: 0,
            baseline_drawn_m: baseline.drawn_m,
            baseline_duration_s: baseline.duration_s,
            baseline_moves: baseline.moves,
            baseline_colliding_moves: baseline.colliding,
        },
    };
    Ok((row, programs))
}

/// The largest distance of a joint from its home value over `program`'s points (rad).
fn from_home_rad(program: &JobFile) -> f64 {
    let Some(home) = &program.home else {
        return 0.0;
    };
    program
        .points()
        .iter()
        .flat_map(|p| p.positions.iter().zip(home).map(|(q, h)| (q - h).abs()))
        .fold(0.0, f64::max)
}

/// How many of a program's moves turn a joint more than half a turn, and the long way round.
struct MoveTurns {
    moves: usize,
    over_half: usize,
    long_way: usize,
}

/// The moves of `program` (every segment but its strokes) that turn a joint more than π over
/// their samples, and those of them where the joint's net turn `Δ` exceeds π and its end less a
/// whole turn the way it went (`end − sign(Δ)·2π`) lies within `limits`: a shorter turn to the
/// same angle existed.
fn move_turns(program: &JobFile, limits: &emg_kinematics::JointLimits) -> MoveTurns {
    let mut turns = MoveTurns {
        moves: 0,
        over_half: 0,
        long_way: 0,
    };
    for segment in &program.segments {
        if matches!(segment.kind, SegmentKind::Stroke { .. }) {
            continue;
        }
        let samples = program.segment_samples(segment);
        let (Some(start), Some(end)) = (samples.first(), samples.last()) else {
            continue;
        };
        turns.moves += 1;
        let over: Vec<usize> = program
            .joint_travel_rad(segment)
            .iter()
            .enumerate()
            .filter(|(_, turned)| **turned > PI)
            .map(|(joint, _)| joint)
            .collect();
        turns.over_half += usize::from(!over.is_empty());
        turns.long_way += usize::from(over.iter().any(|&i| {
            let net = end.q[i] - start.q[i];
            let other_way = end.q[i] - net.signum() * TAU;
            net.abs() > PI && other_way >= limits.lower[i] && other_way <= limits.upper[i]
        }));
    }
    turns
}

/// What the baseline script gets.
struct Baseline {
    drawn_m: f64,
    duration_s: f64,
    moves: usize,
    colliding: usize,
}

/// Each stroke, in the shortest order, planned alone by the search (one motion, no resumption),
/// the strokes joined by straight joint moves from one motion's end to the next one's start with
/// no lift; a move collides where the job's free space (the same part, self-collision and
/// tool-tip test as `emg job`'s moves) refuses its edge.
fn baseline(planner: &Planner, timing: &MotionTiming, job: &Job) -> Baseline {
    let settings = JobSettings {
        max_parts: 1,
        ..job.settings.clone()
    };
    let ordering = order_strokes(&job.strokes, Order::Shortest);
    // The controller `emg job` plans with: the hybrid where a policy is trained for the arm,
    // else the classical.
    let request = PlanRequest {
        controller: planner.models().best_controller(),
        ..PlanRequest::default()
    };
    let constraints = &planner.config().rollout.constraints;
    let mut motions = Vec::new();
    for oriented in &ordering.sequence {
        let path = oriented.path(&job.strokes);
        let plan = plan_stroke(planner, &request, &path, 0.0, &settings, None, &Unwatched)
            .expect("an unwatched stroke is never stopped");
        motions.extend(
            plan.parts
                .into_iter()
                .map(|part| (part.task, part.trajectory)),
        );
    }
    let free = FreeSpace::new(planner.robot(), job_part(planner.robot(), job), constraints);
    let mut drawn_m = 0.0;
    let mut duration_s = 0.0;
    let (mut moves, mut colliding) = (0, 0);
    let mut last: Option<JointVector> = None;
    for (task, trajectory) in &motions {
        let Ok(timed) = timing.time(planner.robot(), task, constraints, trajectory) else {
            continue;
        };
        drawn_m += part_coverage(
            planner.robot(),
            task,
            emg_job::OnStroke {
                from_s: 0.0,
                backward: false,
            },
            timed.samples.iter().map(|sample| &sample.q),
        )
        .length_m();
        duration_s += timed.report.duration_s;
        let start = timed.samples[0].q;
        if let Some(end) = last {
            moves += 1;
            colliding += usize::from(!free.edge_free(&end, &start));
            let samples = time_free_move(&[end, start], timing.request()).samples;
            duration_s += samples.last().map_or(0.0, |s| s.time_s());
        }
        last = Some(timed.samples[timed.samples.len() - 1].q);
    }
    Baseline {
        drawn_m,
        duration_s,
        moves,
        colliding,
    }
}

fn markdown(record: &Record) -> String {
    let mut md = comparison(record);
    md.push('\n');
    md.push_str(&job_table(&record.rows));
    if !record.large.is_empty() {
        md.push_str(&large::markdown(&record.large));
    }
    if !record.krl_programs.is_empty() {
        md.push_str(&krl_programs::markdown(&record.krl_programs));
    }
    if !record.rapid_programs.is_empty() {
        md.push_str(&rapid_programs::markdown(&record.rapid_programs));
    }
    if !record.ur_programs.is_empty() {
        md.push_str(&ur_programs::markdown(&record.ur_programs));
    }
    md
}

/// The page's head: what was planned and how, and `emg job` against the baseline summed over
/// the jobs, with the planning time of the jobs timed on one thread.
fn comparison(record: &Record) -> String {
    let rows = &record.rows;
    let sum = |value: fn(&JobRow) -> f64| rows.iter().map(value).sum::<f64>();
    let count = |value: fn(&JobRow) -> usize| rows.iter().map(value).sum::<usize>();
    let strokes = count(|r| r.strokes);
    // Σ of a duration and of its pen-up and pen-down parts (s).
    let split = |up: fn(&JobRow) -> f64, down: fn(&JobRow) -> f64| {
        format!(
            "{:.1} (pen up {:.1}, pen down {:.1})",
            rows.iter().map(|r| up(r) + down(r)).sum::<f64>(),
            sum(up),
            sum(down)
        )
    };
    let mut md = format!(
        "# Jobs ({})\n\n\
         Written by `{}` on {}. Every SVG of `{}` placed pen down at {} places in front of the \
         arm, five seams on surfaces tilted 0°, 20° and 40°, {GRID} and {HATCH}, planned as `emg job` plans \
         them (the search per stroke, resumed where one motion cannot finish it, safe moves \
         between strokes, from the arm's home and back, 0.5 mm, 30°); every program re-checked \
         segment by segment by the independent checker, its claims (length drawn, strokes \
         whole, stretches unreached) measured again from its samples. Lengths drawn are what \
         the samples cover, the baseline's too. The baseline is what a user scripts today: each stroke planned \
         alone by the search in one motion, the strokes joined by straight joint moves with \
         no lift and no collision check (counted colliding where `emg job`'s free-space test \
         refuses the move).\n\n\
         | | `emg job` | baseline |\n|---|---|---|\n\
         | pen-down length drawn (Σ of {:.3} m) | {:.3} ({:.1} %) | {:.3} ({:.1} %) |\n\
         | strokes complete / resumed / short (of {strokes}) | {} / {} / {} | — |\n\
         | moves colliding | 0 of {} (checked) | {} of {} |\n\
         | program duration, Σ (s) | {} | {:.1} |\n\
         | least duration at the arm's limits, Σ (s) | {} | — |\n\
         | pen-up time / pen-down time | {:.2} | — |\n\
         | planning time per stroke, mean (ms, {} threads) | {:.1} | — |\n\
         | programs the checker refuses | {} of {} | — |\n\
         | programs claiming more than their samples draw | {} of {} | — |\n\
         | largest distance of a joint from its home (rad) | {:.3} | — |\n\
         | moves turning a joint more than π / of them the long way round | {} / {} of {} | — |\n",
        record.robot,
        record.command,
        record.machine,
        record.icons,
        PLACES.len(),
        sum(|r| r.total_m),
        sum(|r| r.drawn_m),
        100.0 * sum(|r| r.drawn_m) / sum(|r| r.total_m),
        sum(|r| r.baseline_drawn_m),
        100.0 * sum(|r| r.baseline_drawn_m) / sum(|r| r.total_m),
        count(|r| r.complete),
        count(|r| r.resumed),
        count(|r| r.short),
        count(|r| r.straight_moves + r.sampled_moves),
        count(|r| r.baseline_colliding_moves),
        count(|r| r.baseline_moves),
        split(|r| r.pen_up_s, |r| r.pen_down_s),
        sum(|r| r.baseline_duration_s),
        split(|r| r.least_pen_up_s, |r| r.least_pen_down_s),
        sum(|r| r.pen_up_s) / sum(|r| r.pen_down_s).max(f64::MIN_POSITIVE),
        record.threads,
        1e3 * sum(|r| r.planning_s) / strokes.max(1) as f64,
        rows.iter().filter(|r| r.checker_failure.is_some()).count(),
        rows.len(),
        rows.iter().filter(|r| r.claims_exceed).count(),
        rows.len(),
        rows.iter().map(|r| r.from_home_rad).fold(0.0, f64::max),
        count(|r| r.moves_over_half_turn),
        count(|r| r.moves_the_long_way),
        count(|r| r.moves),
    );
    for (name, one_thread_s) in &record.one_thread_s {
        if let Some(row) = rows.iter().find(|r| &r.job == name) {
            md.push_str(&format!(
                "| {name}: planning (s) on {} threads / on one | {:.2} / {:.2} ({:.1} ms per stroke on one) | — |\n",
                record.threads,
                row.planning_s,
                one_thread_s,
                1e3 * one_thread_s / row.strokes.max(1) as f64,
            ));
        }
    }
    md
}

/// One row per job: its strokes, lengths, durations, moves and planning time beside the
/// baseline's.
fn job_table(rows: &[JobRow]) -> String {
    let mut md = String::from(
        "| job | strokes | complete / resumed / short | drawn (m) | of (m) | pen down (s) | pen up (s) | \
         moves straight / sampled | planning (s) | baseline drawn (m) | baseline colliding moves |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        md.push_str(&format!(
            "| {} | {} | {} / {} / {} | {:.3} | {:.3} | {:.2} | {:.2} | {} / {} | {:.2} | {:.3} | {} of {} |\n",
            r.job,
            r.strokes,
            r.complete,
            r.resumed,
            r.short,
            r.drawn_m,
            r.total_m,
            r.pen_down_s,
            r.pen_up_s,
            r.straight_moves,
            r.sampled_moves,
            r.planning_s,
            r.baseline_drawn_m,
            r.baseline_colliding_moves,
            r.baseline_moves
        ));
    }
    md
}
