//! Jobs at production scale in `job-eval`: generated drawings of many short strokes
//! ([`emg_io::scattered_strokes_svg`]) planned as `emg job` plans them, on all threads and on
//! one, each stage timed, the peak memory, the program's size and duration against the least
//! duration the arm's limits allow, and the independent check's time.

use std::sync::Mutex;
use std::time::Instant;

use emg_io::{read_svg, scattered_strokes_svg};
use emg_job::{JobFile, JobPlanner, Watch, verify_job};
use serde::{Deserialize, Serialize};

/// One large job planned on some number of threads.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LargeRow {
    /// Strokes of the generated drawing, and of them those the job holds (the tiny ones
    /// dropped as `emg job` drops them).
    pub drawing_strokes: usize,
    /// See `drawing_strokes`.
    pub strokes: usize,
    /// Threads it was planned on.
    pub threads: usize,
    /// Each stage's time (s) as the planner reports its progress (`ordering`, `planning`,
    /// `connecting`, `reordering`, and `branches` where the job is connected again on the
    /// branches chosen for it), then `writing` (the program serialised as its file holds it).
    pub stages: Vec<(String, f64)>,
    /// Planning and writing (s), the stages' sum.
    pub total_s: f64,
    /// The process's peak resident memory while the job was planned and written (MB), where
    /// the system reports it (Linux).
    pub peak_memory_mb: Option<f64>,
    /// The program file's size (MB).
    pub file_mb: f64,
    /// Pen-down length drawn and in all (m).
    pub drawn_m: f64,
    /// See `drawn_m`.
    pub total_m: f64,
    /// The program's duration pen down and pen up (s).
    pub pen_down_s: f64,
    /// See `pen_down_s`.
    pub pen_up_s: f64,
    /// The least duration pen down and pen up the arm's limits allow for the same parts (s).
    pub least_pen_down_s: f64,
    /// See `least_pen_down_s`.
    pub least_pen_up_s: f64,
    /// The independent check of the program (s), and why it failed, if it did.
    pub check_s: f64,
    /// See `check_s`.
    pub checker_failure: Option<String>,
}

/// A watcher that notes when each stage first reports progress.
struct StageClock {
    started: Instant,
    stages: Mutex<Vec<(String, f64)>>,
}

impl Watch for StageClock {
    fn progress(&self, stage: &str, _done: usize, _total: usize) {
        let mut stages = self
            .stages
            .lock()
            .expect("the stage clock is never poisoned");
        if stages.last().is_none_or(|(last, _)| last != stage) {
            stages.push((stage.to_string(), self.started.elapsed().as_secs_f64()));
        }
    }

    fn stop_requested(&self) -> bool {
        false
    }
}

/// The drawing of `strokes` scattered strokes planned with `threads` threads (all where `None`),
/// written and checked; with its program.
pub fn evaluate(
    job_planner: &JobPlanner,
    checker: &emg_verify::ReferenceModel,
    home: &[f64],
    strokes: usize,
    threads: Option<usize>,
) -> anyhow::Result<(LargeRow, JobFile)> {
    let planner = job_planner.planner();
    let tolerance = emg_job::DrawingTolerance::new(emg_job::JOB_TOLERANCE_M, 0.0)?;
    let drawing = read_svg(
        &scattered_strokes_svg(strokes),
        &emg_job::default_placement(planner.robot()),
        &tolerance.svg_options(),
    )?;
    let job = tolerance
        .job(drawing, planner.robot())?
        .with_home(home, planner.robot())?;
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(threads) = threads {
        pool = pool.num_threads(threads);
    }
    let pool = pool.build()?;
    reset_peak_memory();
    let clock = StageClock {
        started: Instant::now(),
        stages: Mutex::new(Vec::new()),
    };
    let (program, text) = pool.install(|| -> anyhow::Result<_> {
        let program = job_planner.plan(&job, &clock)?;
        clock.progress("writing", 0, 1);
        let text = serde_json::to_vec(&program)?;
        Ok((program, text))
    })?;
    let total_s = clock.started.elapsed().as_secs_f64();
    let peak_memory_mb = peak_memory_mb();
    let marks = clock.stages.into_inner().expect("not poisoned");
    let stages = marks
        .iter()
        .enumerate()
        .map(|(k, (stage, at))| {
            let until = marks.get(k + 1).map_or(total_s, |(_, next)| *next);
            (stage.clone(), until - at)
        })
        .collect();
    let checking = Instant::now();
    let checked = pool.install(|| verify_job(&program, checker, planner.robot().joint_names()));
    let check_s = checking.elapsed().as_secs_f64();
    let s = &program.summary;
    let row = LargeRow {
        drawing_strokes: strokes,
        strokes: job.strokes.len(),
        threads: pool.current_num_threads(),
        stages,
        total_s,
        peak_memory_mb,
        file_mb: text.len() as f64 / 1e6,
        drawn_m: s.drawn_m,
        total_m: s.total_m,
        pen_down_s: s.pen_down_s,
        pen_up_s: s.pen_up_s,
        least_pen_down_s: s.least_pen_down_s,
        least_pen_up_s: s.least_pen_up_s,
        check_s,
        checker_failure: checked.err().map(|e| e.to_string()),
    };
    Ok((row, program))
}

/// Resets the process's peak resident memory to what it holds now (Linux: `clear_refs` 5);
/// elsewhere a no-op, and [`peak_memory_mb`] reports nothing.
fn reset_peak_memory() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// The process's peak resident memory since the last [`reset_peak_memory`] (MB), where the
/// system reports it (`VmHWM` of `/proc/self/status`).
fn peak_memory_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|line| line.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1e3)
}

/// The large jobs' table.
pub fn markdown(rows: &[LargeRow]) -> String {
    let mut md = String::from(
        "\n## Jobs at production scale\n\n\
         Drawings of short strokes (3–12 mm, one `<path>` each) scattered over a 0.2 m square \
         (`emg_io::scattered_strokes_svg`), at the default place, planned as `emg job` plans \
         them from the home and back, the program serialised as its file holds it, then \
         checked by the independent checker. Stages as the planner reports them; peak memory \
         is the process's while planning and writing; the least duration is what the arm's \
         limits allow for the same parts (docs/jobs.md, \"Cycle time\").\n\n\
         | strokes | threads | ordering / planning / connecting / reordering / branches / writing (s) | planned and written (s) | peak memory (MB) | file (MB) | drawn (m) | program (s): pen down / pen up | least (s): pen down / pen up | program / least | check (s) | checker |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let stage = |name: &str| {
            r.stages
                .iter()
                .find(|(stage, _)| stage == name)
                .map_or_else(|| "—".to_string(), |(_, s)| format!("{s:.2}"))
        };
        let least = r.least_pen_down_s + r.least_pen_up_s;
        md.push_str(&format!(
            "| {} | {} | {} / {} / {} / {} / {} / {} | {:.2} | {} | {:.1} | {:.3} of {:.3} | {:.1}: {:.1} / {:.1} | {:.1}: {:.1} / {:.1} | {:.2} | {:.2} | {} |\n",
            r.strokes,
            r.threads,
            stage("ordering"),
            stage("planning"),
            stage("connecting"),
            stage("reordering"),
            stage("branches"),
            stage("writing"),
            r.total_s,
            r.peak_memory_mb
                .map_or_else(|| "—".to_string(), |mb| format!("{mb:.0}")),
            r.file_mb,
            r.drawn_m,
            r.total_m,
            r.pen_down_s + r.pen_up_s,
            r.pen_down_s,
            r.pen_up_s,
            least,
            r.least_pen_down_s,
            r.least_pen_up_s,
            (r.pen_down_s + r.pen_up_s) / least.max(f64::MIN_POSITIVE),
            r.check_s,
            r.checker_failure.as_deref().unwrap_or("passes"),
        ));
    }
    md
}
