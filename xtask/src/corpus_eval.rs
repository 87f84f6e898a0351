//! `cargo xtask corpus-eval`: drawings nobody here made, planned at `emg job`'s defaults on the
//! shipped arms and checked: every icon of two public icon sets and lines of text in six
//! Hershey fonts, fetched from the registries at pinned versions (not committed), and generated
//! coastlines and maps. Resumable: each finished job is appended to a record in the cache, and
//! a run started again plans only the jobs it lacks.

mod fetch;
mod generated;

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use emg_io::{Placement, read_svg};
use emg_job::{DrawingTolerance, JobCheckError, JobFile, JobPlanner, Unwatched, verify_job};
use emg_planner::ShippedRobot;
use serde::{Deserialize, Serialize};

use crate::{job_eval, progress, workspace};

/// Options of `corpus-eval`.
#[derive(clap::Args)]
pub struct Args {
    /// The shipped arms to plan on (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "fr3,iiwa14,ur5e")]
    robots: Vec<String>,
    /// Plan every N-th icon of each icon set (1: all of them); all the text and outlines.
    #[arg(long, default_value_t = 1)]
    every: usize,
    /// The corner tolerances (mm, comma-separated; `emg job --corner-tolerance`) each drawing
    /// is planned with.
    #[arg(long, value_delimiter = ',', default_value = "0,0.125")]
    corner_tolerances: Vec<f64>,
    /// Where the fetched packages, the generated drawings (`generated/`, each planned again by
    /// `emg job`) and the resumable records are kept.
    #[arg(long, default_value_os_t = workspace::root().join("target/corpus"))]
    cache: PathBuf,
    /// Output directory of corpus.{json,md}.
    #[arg(long, default_value_os_t = workspace::root().join("docs/results"))]
    out_dir: PathBuf,
}

/// One drawing of a set.
struct Drawing {
    set: &'static str,
    name: String,
    svg: String,
}

/// What became of one drawing on one arm.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CorpusRow {
    /// The shipped arm.
    pub robot: String,
    /// The corner tolerance (mm).
    pub corner_mm: f64,
    /// The set.
    pub set: String,
    /// The drawing.
    pub name: String,
    /// How it ended: `planned`, `refused: …` (the reader's or the planner's error) or
    /// `panic: …`.
    pub outcome: String,
    /// Strokes of the drawing.
    pub strokes: usize,
    /// The stretches its program leaves undrawn, by cause ([`emg_job::Shortfall::label`]).
    pub undrawn_by_cause: BTreeMap<String, usize>,
    /// Length drawn and in all (m).
    pub drawn_m: f64,
    /// See `drawn_m`.
    pub total_m: f64,
    /// Program duration and its lower bound (s).
    pub duration_s: f64,
    /// See `duration_s`.
    pub least_s: f64,
    /// Planning time (s) on this machine.
    pub planning_s: f64,
    /// The checker's refusal, if it refused the program.
    pub check_failure: Option<String>,
    /// Whether it refused it for a pen-up tip within half the lift of the part.
    pub pen_up_low: bool,
}

/// The record written to `corpus.json`.
#[derive(Serialize, Deserialize)]
pub struct Record {
    /// The command that wrote it.
    pub command: String,
    /// The packages and their versions.
    pub sources: Vec<String>,
    /// Machine and threads.
    pub machine: String,
    /// Every job.
    pub rows: Vec<CorpusRow>,
}

/// Plans every drawing on every arm (resuming from the cache's records), writes the table.
pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(args.every >= 1, "--every must be at least 1");
    let drawings = drawings(&args.cache, args.every)?;
    let mut rows = Vec::new();
    for name in &args.robots {
        let shipped = ShippedRobot::by_name(name)
            .with_context(|| format!("--robots: '{name}' is not a shipped arm"))?;
        for &corner_mm in &args.corner_tolerances {
            rows.extend(evaluate_arm(args, &shipped, corner_mm, &drawings)?);
        }
    }
    let record = Record {
        command: format!(
            "cargo xtask corpus-eval --robots {} --every {} --corner-tolerances {}",
            args.robots.join(","),
            args.every,
            args.corner_tolerances
                .iter()
                .map(f64::to_string)
                .collect::<Vec<_>>()
                .join(",")
        ),
        sources: fetch::ICON_SETS
            .iter()
            .map(|set| format!("{}@{} (npm)", set.package, set.version))
            .chain(std::iter::once(format!(
                "{}=={} (PyPI)",
                fetch::HERSHEY.0,
                fetch::HERSHEY.1
            )))
            .collect(),
        machine: workspace::machine(),
        rows,
    };
    workspace::write_results(&args.out_dir, "corpus", &record, &markdown(&record))?;
    let panics = record
        .rows
        .iter()
        .filter(|r| r.outcome.starts_with("panic"))
        .count();
    anyhow::ensure!(panics == 0, "{panics} jobs panicked");
    Ok(())
}

/// Every drawing of the corpus, every `every`-th of each set.
fn drawings(cache: &Path, every: usize) -> anyhow::Result<Vec<Drawing>> {
    let mut drawings = Vec::new();
    for set in &fetch::ICON_SETS {
        for (index, icon) in fetch::icons(set, cache)?.iter().enumerate() {
            if index % every == 0 {
                drawings.push(Drawing {
                    set: set.name,
                    name: icon
                        .file_stem()
                        .unwrap_or_default()
                        .to_string_lossy()
                        .into(),
                    svg: std::fs::read_to_string(icon)?,
                });
            }
        }
    }
    let fonts = fetch::hershey_lines(cache)?;
    let sets = [
        ("hershey text", generated::text(&fonts, &fetch::LINES)),
        ("outlines", generated::outlines()),
    ];
    let written = cache.join("generated");
    std::fs::create_dir_all(&written)?;
    for (set, list) in sets {
        for (name, svg) in list {
            std::fs::write(written.join(file_name(&name)), &svg)?;
            drawings.push(Drawing { set, name, svg });
        }
    }
    Ok(drawings)
}

/// The file a generated drawing is kept in (so that `emg job` can plan it again): its name,
/// every character but letters and digits a `-`, with `.svg`.
fn file_name(name: &str) -> String {
    let plain: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    format!("{plain}.svg")
}

/// The rows of `drawings` on `shipped`: those the cache's record holds, the rest planned and
/// appended to it one by one.
fn evaluate_arm(
    args: &Args,
    shipped: &ShippedRobot,
    corner_mm: f64,
    drawings: &[Drawing],
) -> anyhow::Result<Vec<CorpusRow>> {
    let data = workspace::data_dir();
    let robot_file = shipped.path(&data);
    let tasks = shipped.data_dir(&data).join("tasks/eval-v1.tasks");
    let (job_planner, checker) = job_eval::setup_with_tasks(&robot_file, &tasks)?;
    let record = args
        .cache
        .join(format!("{}-corner-{corner_mm}.rows.jsonl", shipped.name));
    std::fs::create_dir_all(&args.cache)?;
    let mut done: Vec<CorpusRow> = match std::fs::read_to_string(&record) {
        Ok(text) => text
            .lines()
            .filter_map(|line| serde_json::from_str(line).ok())
            .collect(),
        Err(_) => Vec::new(),
    };
    let mut out = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&record)
        .with_context(|| format!("cannot open {}", record.display()))?;
    let tolerance = DrawingTolerance::new(emg_job::JOB_TOLERANCE_M, corner_mm * 1e-3)?;
    let bar = progress::bar(drawings.len() as u64, shipped.name);
    let mut rows = Vec::new();
    for drawing in drawings {
        let known = done
            .iter()
            .position(|r| r.set == drawing.set && r.name == drawing.name);
        let row = match known {
            Some(index) => done.swap_remove(index),
            None => {
                let row = evaluate(&job_planner, &checker, shipped, &tolerance, drawing);
                writeln!(out, "{}", serde_json::to_string(&row)?)?;
                out.flush()?;
                row
            }
        };
        rows.push(row);
        bar.inc(1);
    }
    bar.finish();
    Ok(rows)
}

/// One drawing planned on the arm as `emg job` plans it at the defaults, and checked.
fn evaluate(
    job_planner: &JobPlanner,
    checker: &emg_verify::ReferenceModel,
    shipped: &ShippedRobot,
    tolerance: &DrawingTolerance,
    drawing: &Drawing,
) -> CorpusRow {
    let planner = job_planner.planner();
    let mut row = CorpusRow {
        robot: shipped.name.to_string(),
        corner_mm: tolerance.corner_m * 1e3,
        set: drawing.set.to_string(),
        name: drawing.name.clone(),
        outcome: String::new(),
        strokes: 0,
        undrawn_by_cause: BTreeMap::new(),
        drawn_m: 0.0,
        total_m: 0.0,
        duration_s: 0.0,
        least_s: 0.0,
        planning_s: 0.0,
        check_failure: None,
        pen_up_low: false,
    };
    let job = read_svg(
        &drawing.svg,
        &Placement::default(),
        &tolerance.svg_options(),
    )
    .map_err(anyhow::Error::from)
    .and_then(|read| Ok(tolerance.job(read, planner.robot())?))
    .and_then(|job| Ok(job.with_home(shipped.home, planner.robot())?));
    let job = match job {
        Ok(job) => job,
        Err(error) => {
            row.outcome = format!("refused: {error}");
            return row;
        }
    };
    row.strokes = job.strokes.len();
    row.total_m = job.strokes.iter().map(|s| s.length_m()).sum();
    let started = Instant::now();
    let planned = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        job_planner.plan(&job, &Unwatched)
    }));
    row.planning_s = started.elapsed().as_secs_f64();
    match planned {
        Err(panic) => {
            let message = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            row.outcome = format!("panic: {message}");
        }
        Ok(Err(error)) => row.outcome = format!("refused: {error}"),
        Ok(Ok(program)) => {
            row.outcome = "planned".to_string();
            measure(&program, &mut row);
            let checked = verify_job(&program, checker, planner.robot().joint_names());
            row.pen_up_low = matches!(checked, Err(JobCheckError::PenUp { .. }));
            row.check_failure = checked.err().map(|e| e.to_string());
        }
    }
    row
}

/// The program's lengths, durations and undrawn stretches by cause, into `row`.
fn measure(program: &JobFile, row: &mut CorpusRow) {
    let s = &program.summary;
    row.drawn_m = s.drawn_m;
    row.duration_s = s.duration_s;
    row.least_s = s.least_pen_down_s + s.least_pen_up_s;
    for cause in program.strokes.iter().flat_map(|s| &s.unreached_causes) {
        *row.undrawn_by_cause
            .entry(cause.label().into())
            .or_default() += 1;
    }
}

/// The undrawn stretches of `rows` by cause, as `reach 3, not_searched 1` (`none` without any).
fn by_cause(rows: &[&CorpusRow]) -> String {
    let mut total: BTreeMap<&str, usize> = BTreeMap::new();
    for (cause, count) in rows.iter().flat_map(|r| &r.undrawn_by_cause) {
        *total.entry(cause).or_default() += count;
    }
    if total.is_empty() {
        return "none".into();
    }
    let causes: Vec<String> = total.iter().map(|(c, n)| format!("{c} {n}")).collect();
    causes.join(", ")
}

/// The value at share `q` of the sorted `values` (nearest rank); 0 when empty.
fn quantile(values: &mut [f64], q: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    let rank = ((q * values.len() as f64).ceil() as usize).clamp(1, values.len());
    values[rank - 1]
}

/// The table: per arm and set, the jobs, what became of them, and how fast they are drawn.
fn markdown(record: &Record) -> String {
    let mut text = format!(
        "# Corpus: drawings nobody here made\n\nWritten by `{}` ({}); sources: {}. Every \
         drawing 0.2 m wide at the default place, planned as `emg job` plans it, its program \
         checked by `emg check`'s checker. Undrawn stretches by cause (docs/jobs.md, \
         \"Why a stroke stops short\"). Duration over the lower bound the program prints.\n\n\
         | arm | corners (mm) | set | jobs | panics | refused | check fails | pen-up low | drawn / length | \
         undrawn stretches by cause | duration / bound (median, p95) | planning (s) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
        record.command,
        record.machine,
        record.sources.join(", ")
    );
    let mut keys: Vec<(String, f64, String)> = record
        .rows
        .iter()
        .map(|r| (r.robot.clone(), r.corner_mm, r.set.clone()))
        .collect();
    keys.dedup();
    for (robot, corner_mm, set) in keys {
        let rows: Vec<&CorpusRow> = record
            .rows
            .iter()
            .filter(|r| r.robot == robot && r.corner_mm == corner_mm && r.set == set)
            .collect();
        let count = |f: &dyn Fn(&CorpusRow) -> bool| rows.iter().filter(|r| f(r)).count();
        let sum = |f: &dyn Fn(&CorpusRow) -> f64| rows.iter().map(|r| f(r)).sum::<f64>();
        let mut ratios: Vec<f64> = rows
            .iter()
            .filter(|r| r.outcome == "planned" && r.least_s > 0.0)
            .map(|r| r.duration_s / r.least_s)
            .collect();
        text += &format!(
            "| {robot} | {corner_mm} | {set} | {} | {} | {} | {} | {} | {:.1} % of {:.2} m | {} | \
             {:.2}×, {:.2}× | {:.0} |\n",
            rows.len(),
            count(&|r| r.outcome.starts_with("panic")),
            count(&|r| r.outcome.starts_with("refused")),
            count(&|r| r.check_failure.is_some()),
            count(&|r| r.pen_up_low),
            100.0 * sum(&|r| r.drawn_m) / sum(&|r| r.total_m).max(f64::MIN_POSITIVE),
            sum(&|r| r.total_m),
            by_cause(&rows),
            quantile(&mut ratios.clone(), 0.5),
            quantile(&mut ratios, 0.95),
            sum(&|r| r.planning_s),
        );
    }
    let failures: Vec<&CorpusRow> = record
        .rows
        .iter()
        .filter(|r| r.outcome != "planned" || r.check_failure.is_some())
        .collect();
    if !failures.is_empty() {
        text += "\n## Jobs refused, panicked or failing the check\n\n| arm | corners (mm) | set | drawing | what |\n|---|---|---|---|---|\n";
        for r in failures {
            let what = r.check_failure.as_deref().unwrap_or(&r.outcome);
            text += &format!(
                "| {} | {} | {} | {} | {} |\n",
                r.robot,
                r.corner_mm,
                r.set,
                r.name,
                what.replace('|', "\\|").replace('\n', " ")
            );
        }
    }
    text
}
