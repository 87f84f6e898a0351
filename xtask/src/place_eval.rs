//! `cargo xtask place-eval`: `emg place` on jobs whose part stands where the arm draws little of
//! it (every icon of the SVG reader's vendored lucide-static 1.62.0 set, 0.3 m wide, near the
//! edge of the arm's reach) and on a 20-stroke job, beside the usual approach (the place whose
//! stroke points most often have an IK solution in the cone, planned as it is); the 20-stroke
//! job's screening timed, its best places checked against the top 20 planned, and its places
//! found again on one thread; every job also planned at [`RANDOM_PLACES`] places drawn at
//! random in the region, none of which may draw more than the chosen place:
//! `docs/results/placement.{json,md}` and the heat map `docs/figures/placement-map.svg`.

use std::path::{Path, PathBuf};

use emg_io::{Placement as SvgPlacement, read_svg_file};
use emg_job::{
    Job, JobPlanner, Moving, Place, PlaceFrame, PlaceSettings, Placement, Region, SAME_LENGTH_M,
    SAME_SCORE, Score, Unwatched, verify_job,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::job_eval::{IconJobOptions, grid_of_circles, icon_files, setup};
use crate::{progress, workspace};

/// Options of `place-eval`.
#[derive(clap::Args)]
#[command(mut_arg("out_dir", |arg| arg.help("Output directory of placement.{json,md}")))]
pub struct Args {
    /// Icons, robot file and output directory.
    #[command(flatten)]
    common: IconJobOptions,
    /// The heat map of the 20-stroke job.
    #[arg(long, default_value_os_t = workspace::root().join("docs/figures/placement-map.svg"))]
    map: PathBuf,
}

/// The region every job is placed in: shifts along the part's x and y axes (m), turns (°),
/// across the edge of the arm's reach.
const REGION: Region = Region {
    moving: Moving::Part,
    x_m: [-0.2, 0.15],
    y_m: [-0.3, 0.3],
    z_m: [0.0, 0.0],
    rotation_deg: [-90.0, 90.0],
};

/// Places drawn at random in the region per job, each planned.
const RANDOM_PLACES: usize = 16;

/// Seed of the random places.
const RANDOM_SEED: u64 = 20_261_129;

/// Where each icon stands before it is placed: its centre (m) and width (m).
const FAR: ([f64; 3], f64) = ([0.78, 0.0, 0.25], 0.3);

/// One job's places, found by the bound and by the usual point-by-point score.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PlaceRow {
    /// The job.
    pub job: String,
    /// Its strokes and pen-down length (m).
    pub strokes: usize,
    /// See `strokes`.
    pub total_m: f64,
    /// Drawn where it stands (m).
    pub as_given_m: f64,
    /// `emg place`'s chosen place: drawn (m), strokes complete, program (s).
    pub chosen_m: f64,
    /// See `chosen_m`.
    pub chosen_complete: usize,
    /// See `chosen_m`.
    pub chosen_s: f64,
    /// Whether the independent checker passed the chosen place's program.
    pub chosen_checked: bool,
    /// The place the point-by-point score ranks first (ties deepest inside the arm's reach
    /// first, as `emg place` breaks them), planned: drawn (m), strokes complete.
    pub point_ik_m: f64,
    /// See `point_ik_m`.
    pub point_ik_complete: usize,
    /// The screened places at the point-by-point score's top (every one of them best to that
    /// score), and of up to [`TIED_PLANNED`] of them, spread over the grid and planned, those
    /// that leave strokes unfinished.
    pub point_ik_top: TopPlaces,
    /// The same for the screening bound's top places.
    pub bound_top: TopPlaces,
    /// The most any of [`RANDOM_PLACES`] places drawn at random in the region draws, each
    /// planned (m).
    pub random_best_m: f64,
    /// Places screened, and the screening's wall time (s).
    pub screened: usize,
    /// See `screened`.
    pub screening_s: f64,
}

/// Places at a score's top, some of them planned.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct TopPlaces {
    /// Screened places at the top score (within `SAME_SCORE`).
    pub places: usize,
    /// Of them planned.
    pub planned: usize,
    /// Of those planned, those that leave strokes unfinished.
    pub unfinished: usize,
    /// Pen-down length the planned ones draw, Σ, and in all (m).
    pub drawn_m: f64,
    /// See `drawn_m`.
    pub total_m: f64,
}

/// Places at a score's top planned per job at most, spread evenly over the grid's order.
const TIED_PLANNED: usize = 20;

/// The 20-stroke job's checks.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TopTwenty {
    /// The most any of the 20 best refined places draws when planned (m).
    pub best_of_top_m: f64,
    /// What the chosen place draws (m).
    pub chosen_m: f64,
    /// Whether the places found on one thread are the same (every score and the chosen place).
    pub same_on_one_thread: bool,
}

/// The whole record written to `placement.json`.
#[derive(Serialize, Deserialize)]
pub struct Record {
    /// Robot name.
    pub robot: String,
    /// The command that wrote it.
    pub command: String,
    /// Machine and threads.
    pub machine: String,
    /// Threads.
    pub threads: usize,
    /// The region.
    pub region: Region,
    /// The settings.
    pub settings: PlaceSettings,
    /// Every job.
    pub rows: Vec<PlaceRow>,
    /// The 20-stroke job's checks.
    pub top_twenty: TopTwenty,
}

/// Name of the 20-stroke job.
const TWENTY: &str = "20 circles 2 cm across in a 4 × 5 grid round (0.75, 0, 0.25)";

/// Places every job, compares, checks, writes the record, its table and the heat map.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let (job_planner, checker) = setup(&args.common.robot)?;
    let planner = job_planner.planner();
    let icons = icon_files(&args.common.icons)?;
    let mut jobs: Vec<(String, Job)> = Vec::new();
    let tolerance = emg_job::DrawingTolerance::new(emg_job::JOB_TOLERANCE_M, 0.0)?;
    for icon in &icons {
        let placement = SvgPlacement {
            origin_m: FAR.0,
            width_m: Some(FAR.1),
            ..SvgPlacement::default()
        };
        let drawing = read_svg_file(icon, &placement, &tolerance.svg_options())?;
        jobs.push((
            format!(
                "{} at ({}, {}, {}), {} m wide",
                icon.file_name().unwrap_or_default().to_string_lossy(),
                FAR.0[0],
                FAR.0[1],
                FAR.0[2],
                FAR.1
            ),
            tolerance.job(drawing, planner.robot())?,
        ));
    }
    let twenty = Job::from_strokes(grid_of_circles(4, 5, [0.75, 0.0, 0.25]), planner.robot())?;
    jobs.push((TWENTY.to_string(), twenty.clone()));
    let settings = PlaceSettings::default();
    let bar = progress::bar(jobs.len() as u64, "jobs");
    let mut rows = Vec::new();
    let mut twenty_placement = None;
    for (name, job) in &jobs {
        let (row, placement) = evaluate(&job_planner, &checker, name, job, &settings)?;
        rows.push(row);
        if name == TWENTY {
            twenty_placement = Some(placement);
        }
        bar.inc(1);
    }
    bar.finish();
    let placement = twenty_placement.expect("the 20-stroke job was placed");
    let top_twenty = top_twenty(&job_planner, &twenty, &placement, &settings)?;
    write_map(&args.map, &placement)?;
    let record = Record {
        robot: planner.robot().name().to_string(),
        command: workspace::command_for("place-eval", &args.common.robot),
        machine: workspace::machine(),
        threads: rayon::current_num_threads(),
        region: REGION,
        settings,
        rows,
        top_twenty,
    };
    workspace::write_results(
        &args.common.out_dir,
        "placement",
        &record,
        &markdown(&record),
    )?;
    anyhow::ensure!(
        record.rows.iter().all(|r| r.chosen_checked),
        "a chosen place's program fails the checker"
    );
    anyhow::ensure!(
        record.top_twenty.same_on_one_thread,
        "the places differ on one thread"
    );
    anyhow::ensure!(
        record
            .rows
            .iter()
            .all(|r| r.random_best_m <= r.chosen_m + SAME_LENGTH_M),
        "a random place draws more than the chosen one"
    );
    Ok(())
}

/// Every one of the 20 best refined places of the 20-stroke job `twenty` (placed as
/// `placement`) planned, and the placement again on one thread.
fn top_twenty(
    job_planner: &JobPlanner,
    twenty: &Job,
    placement: &Placement,
    settings: &PlaceSettings,
) -> anyhow::Result<TopTwenty> {
    let frame = PlaceFrame::of(twenty, REGION.moving);
    let best_of_top_m = placement
        .refined
        .iter()
        .take(20)
        .map(|scored| {
            let moved = twenty.moved(&frame.job_motion(&scored.place))?;
            Ok(job_planner
                .plan(&moved, &Unwatched)
                .map_or(0.0, |program| program.summary.drawn_m))
        })
        .collect::<anyhow::Result<Vec<f64>>>()?
        .into_iter()
        .fold(0.0, f64::max);
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let again = one_thread
        .install(|| job_planner.place(twenty, &REGION, settings, Score::Bound, &Unwatched))?;
    let same_on_one_thread = again.screened == placement.screened
        && again.refined == placement.refined
        && again.best().scored == placement.best().scored;
    Ok(TopTwenty {
        best_of_top_m,
        chosen_m: placement.best().drawn_m,
        same_on_one_thread,
    })
}

/// `job` as it stands, placed by `emg place` and by the point-by-point score.
fn evaluate(
    job_planner: &JobPlanner,
    checker: &emg_verify::ReferenceModel,
    name: &str,
    job: &Job,
    settings: &PlaceSettings,
) -> anyhow::Result<(PlaceRow, Placement)> {
    let planner = job_planner.planner();
    let plan = |job: &Job| job_planner.plan(job, &Unwatched).ok();
    let as_given_m = plan(job).map_or(0.0, |program| program.summary.drawn_m);
    let placed = |score| job_planner.place(job, &REGION, settings, score, &Unwatched);
    let ours = placed(Score::Bound)?;
    let chosen = ours.best();
    let program = chosen
        .program
        .as_deref()
        .expect("the chosen place was planned");
    let chosen_checked = verify_job(program, checker, planner.robot().joint_names()).is_ok();
    // The usual approach takes the place its score ranks first and plans it as it is.
    let usual = placed(Score::PointIk)?;
    let frame = PlaceFrame::of(job, REGION.moving);
    let first = job.moved(&frame.job_motion(&usual.refined[0].place))?;
    let (point_ik_m, point_ik_complete) = plan(&first).map_or((0.0, 0), |program| {
        (program.summary.drawn_m, program.summary.complete)
    });
    let top_places = |placement: &Placement| -> anyhow::Result<TopPlaces> {
        let top = placement
            .screened
            .iter()
            .map(|s| s.score)
            .fold(0.0, f64::max);
        let tied: Vec<_> = placement
            .screened
            .iter()
            .filter(|s| s.score >= top - SAME_SCORE)
            .collect();
        let planned = TIED_PLANNED.min(tied.len());
        let mut counted = TopPlaces {
            places: tied.len(),
            planned,
            unfinished: 0,
            drawn_m: 0.0,
            total_m: 0.0,
        };
        for k in 0..planned {
            let moved = job.moved(&frame.job_motion(&tied[k * tied.len() / planned].place))?;
            let (drawn, complete) = plan(&moved).map_or((0.0, 0), |program| {
                (program.summary.drawn_m, program.summary.complete)
            });
            counted.unfinished += usize::from(complete < job.strokes.len());
            counted.drawn_m += drawn;
            counted.total_m += moved.strokes.iter().map(|s| s.length_m()).sum::<f64>();
        }
        Ok(counted)
    };
    let point_ik_top = top_places(&usual)?;
    let bound_top = top_places(&ours)?;
    let mut rng = ChaCha8Rng::seed_from_u64(RANDOM_SEED);
    let random: Vec<Place> = (0..RANDOM_PLACES)
        .map(|_| Place {
            x_m: rng.random_range(REGION.x_m[0]..=REGION.x_m[1]),
            y_m: rng.random_range(REGION.y_m[0]..=REGION.y_m[1]),
            z_m: 0.0,
            rotation_deg: rng.random_range(REGION.rotation_deg[0]..=REGION.rotation_deg[1]),
        })
        .collect();
    let random_best_m = random
        .iter()
        .map(|place| {
            let moved = job.moved(&frame.job_motion(place))?;
            Ok(plan(&moved).map_or(0.0, |program| program.summary.drawn_m))
        })
        .collect::<anyhow::Result<Vec<f64>>>()?
        .into_iter()
        .fold(0.0, f64::max);
    let row = PlaceRow {
        job: name.to_string(),
        strokes: job.strokes.len(),
        total_m: job.strokes.iter().map(|s| s.length_m()).sum(),
        as_given_m,
        chosen_m: chosen.drawn_m,
        chosen_complete: chosen.complete,
        chosen_s: chosen.duration_s,
        chosen_checked,
        point_ik_m,
        point_ik_complete,
        point_ik_top,
        bound_top,
        random_best_m,
        screened: ours.screened.len(),
        screening_s: ours.screening_s,
    };
    Ok((row, ours))
}

/// The heat map of `placement`, as `emg place --map` draws it.
fn write_map(path: &Path, placement: &Placement) -> anyhow::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    emg_io::write_atomically(path, emg_job::placement_map(placement, Score::Bound))?;
    Ok(())
}

fn markdown(record: &Record) -> String {
    let mut md = comparison(record);
    if let Some(twenty) = record.rows.iter().find(|r| r.job == TWENTY) {
        md.push_str(&twenty_job(record, twenty));
    }
    md.push_str(&job_table(&record.rows));
    md.push_str("\n![heat map of the 20-stroke job](../figures/placement-map.svg)\n");
    md
}

/// The page's head: what was searched and how, and `emg place` against the usual approach
/// and against the places each score ranks first or drawn at random.
fn comparison(record: &Record) -> String {
    let rows = &record.rows;
    let unfinished = |complete: usize, row: &PlaceRow| complete < row.strokes;
    let ours_short = rows
        .iter()
        .filter(|r| unfinished(r.chosen_complete, r))
        .count();
    let usual_short = rows
        .iter()
        .filter(|r| unfinished(r.point_ik_complete, r))
        .count();
    let sum = |value: fn(&PlaceRow) -> f64| rows.iter().map(value).sum::<f64>();
    let count = |value: fn(&PlaceRow) -> usize| rows.iter().map(value).sum::<usize>();
    format!(
        "# Placement ({})\n\n\
         Written by `{}` on {} ({} threads). Each job's part is searched over shifts x in \
         [{}, {}] m and y in [{}, {}] m along its axes and turns in [{}°, {}°] about its \
         normal: {} × {} positions × {} turns screened by the strokes' bounds (a {} m scan, {} \
         restarts), the best {} and the places round the best refined by the full scan, the \
         best {} planned as full jobs (`emg place`'s defaults). The usual approach scores a \
         place by the share of stroke points with an IK solution in the cone, each on its own, \
         and takes the place it ranks first.\n\n\
         | | `emg place` | usual approach |\n|---|---|---|\n\
         | pen-down length drawn (Σ of {:.3} m; {:.3} m where the parts stand) | {:.3} ({:.1} %) | {:.3} ({:.1} %) |\n\
         | jobs with strokes left unfinished (of {}) | {} | {} |\n\n\
         A score ranks many places first where the whole job lies in reach. Of the places each \
         score ranks at its top (up to {TIED_PLANNED} per job, spread over the grid, each \
         planned as a job): the point-by-point IK score's leave strokes unfinished at {} of {} \
         ({:.1} % of their pen-down length drawn); the screening bound's at {} of {} ({:.1} %). \
         Neither score alone says where the arm draws the job: `emg place` plans its best \
         places before it chooses. At {RANDOM_PLACES} places per job drawn at random in the \
         region (seed {RANDOM_SEED}), each planned, {} of {} jobs have one drawing more than \
         `emg place`'s choice (to 1 mm).\n\n",
        record.robot,
        record.command,
        record.machine,
        record.threads,
        record.region.x_m[0],
        record.region.x_m[1],
        record.region.y_m[0],
        record.region.y_m[1],
        record.region.rotation_deg[0],
        record.region.rotation_deg[1],
        record.settings.positions,
        record.settings.positions,
        record.settings.rotations,
        record.settings.coarse_grid_m,
        record.settings.coarse_restarts,
        record.settings.refine,
        record.settings.certify,
        sum(|r| r.total_m),
        sum(|r| r.as_given_m),
        sum(|r| r.chosen_m),
        100.0 * sum(|r| r.chosen_m) / sum(|r| r.total_m),
        sum(|r| r.point_ik_m),
        100.0 * sum(|r| r.point_ik_m) / sum(|r| r.total_m),
        rows.len(),
        ours_short,
        usual_short,
        count(|r| r.point_ik_top.unfinished),
        count(|r| r.point_ik_top.planned),
        100.0 * sum(|r| r.point_ik_top.drawn_m)
            / sum(|r| r.point_ik_top.total_m).max(f64::MIN_POSITIVE),
        count(|r| r.bound_top.unfinished),
        count(|r| r.bound_top.planned),
        100.0 * sum(|r| r.bound_top.drawn_m) / sum(|r| r.bound_top.total_m).max(f64::MIN_POSITIVE),
        rows.iter()
            .filter(|r| r.random_best_m > r.chosen_m + SAME_LENGTH_M)
            .count(),
        rows.len(),
    )
}

/// The paragraph on the 20-stroke job (`twenty`): its screening and its chosen place against
/// the best refined places.
fn twenty_job(record: &Record, twenty: &PlaceRow) -> String {
    let t = &record.top_twenty;
    format!(
        "{TWENTY}: {} places screened in {:.1} s; the chosen place draws {:.3} m, the best \
         of the 20 best refined places, each planned, {:.3} m ({}); the places found on one \
         thread are {}.\n\n",
        twenty.screened,
        twenty.screening_s,
        t.chosen_m,
        t.best_of_top_m,
        if t.chosen_m >= t.best_of_top_m - SAME_LENGTH_M {
            "the chosen place draws as much as any"
        } else {
            "one of them draws more"
        },
        if t.same_on_one_thread {
            "the same"
        } else {
            "different"
        },
    )
}

/// One row per job: its places' lengths, completeness and screening.
fn job_table(rows: &[PlaceRow]) -> String {
    let mut md = String::from(
        "| job | strokes | of (m) | where it stands (m) | `emg place` (m) | complete | program (s) | usual approach (m) | complete | IK score's top places: unfinished / planned (of) | bound's top places: unfinished / planned (of) | most drawn at a random place (m) | screened | screening (s) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        md.push_str(&format!(
            "| {} | {} | {:.3} | {:.3} | {:.3} | {} | {:.2} | {:.3} | {} | {} / {} ({}) | {} / {} ({}) | {:.3} | {} | {:.1} |\n",
            r.job,
            r.strokes,
            r.total_m,
            r.as_given_m,
            r.chosen_m,
            r.chosen_complete,
            r.chosen_s,
            r.point_ik_m,
            r.point_ik_complete,
            r.point_ik_top.unfinished,
            r.point_ik_top.planned,
            r.point_ik_top.places,
            r.bound_top.unfinished,
            r.bound_top.planned,
            r.bound_top.places,
            r.random_best_m,
            r.screened,
            r.screening_s
        ));
    }
    md
}
