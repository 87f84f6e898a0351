//! `cargo xtask readme-picture`: the README's pictures. The task of the README's own
//! `emg plan --p0 … --d … --n …` command, planned as `emg plan` plans it (the search, the work
//! plate, the shipped models), drawn by the viewer and taken as a still by headless Chromium
//! (`docs/figures/readme-demo.png`); with `--job`, the drawing of the README's `emg job FILE`
//! command planned as `emg job` plans it, its program drawn by the viewer
//! (`docs/figures/job-demo.png`).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};
use emg_control::Task;
use emg_kinematics::Vec3;
use emg_planner::{Models, PlanRequest, Planner, PlannerConfig};

use crate::workspace;

/// Options of `cargo xtask readme-picture`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Share of the motion the still shows (0 = the start, 1 = the end).
    #[arg(long, default_value_t = 0.6)]
    at: f64,
    /// Picture the README's `emg job` command instead of its `emg plan` command.
    #[arg(long)]
    job: bool,
    /// Output PNG (default: `docs/figures/readme-demo.png`, with `--job`
    /// `docs/figures/job-demo.png`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Chromium (default: $EMG_CHROMIUM, else `chromium` on PATH).
    #[arg(long)]
    chromium: Option<PathBuf>,
}

/// Plans the README's task, renders its page and takes the still.
pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(
        (0.0..=1.0).contains(&args.at),
        "--at must be in [0, 1], got {}",
        args.at
    );
    let readme = workspace::root().join("README.md");
    let text = std::fs::read_to_string(&readme)
        .with_context(|| format!("reading {}", readme.display()))?;
    let figures = workspace::root().join("docs/figures");
    if args.job {
        let out = args
            .out
            .clone()
            .unwrap_or_else(|| figures.join("job-demo.png"));
        return job_picture(args, &text, &out);
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| figures.join("readme-demo.png"));
    let [p0, d, n] = readme_task(&text)?;
    let robot_path = workspace::default_robot();
    let robot = workspace::load_robot(&robot_path)?;
    let models = Models::shipped(&robot, workspace::data_dir().path())?;
    let planner = Planner::new(robot, models, PlannerConfig::cell())?;
    let task = Task::new(planner.robot(), p0, d, n, None)?;
    let plan = planner.plan(&task, &PlanRequest::default())?;
    let page = emg_viewer::render_html(&emg_viewer::ViewerInput {
        robot: planner.robot(),
        task: &task,
        trajectory: &plan.trajectory,
        constraints: &planner.config().rollout.constraints,
        title: &format!(
            "emg plan: {:.2} m along the line",
            plan.trajectory.path_length_m
        ),
    });
    let html = workspace::root().join("target/readme-picture.html");
    emg_io::write_atomically(&html, page)?;
    screenshot(args, &html, &out)?;
    println!(
        "planned {:.4} m; wrote {}",
        plan.trajectory.path_length_m,
        out.display()
    );
    Ok(())
}

/// The README's `emg job FILE` drawing planned as `emg job` plans it (its default placement and
/// tolerance, the shipped models), its program's page and the still of it at `out`.
fn job_picture(args: &Args, readme: &str, out: &Path) -> anyhow::Result<()> {
    let line = readme
        .lines()
        .find(|line| line.trim_start().starts_with("emg job "))
        .context("README.md holds no `emg job …` command")?;
    let file = line
        .split_whitespace()
        .nth(2)
        .context("the README's `emg job` command names no file")?;
    let robot_path = workspace::default_robot();
    let robot = workspace::load_robot(&robot_path)?;
    let models = Models::shipped(&robot, workspace::data_dir().path())?;
    let config = emg_job::job_config(emg_job::JOB_TOLERANCE_M);
    let planner = Planner::new(robot, models, config)?;
    let job_planner =
        emg_job::JobPlanner::new(planner, &robot_path, robot_path.display().to_string())?;
    let planner = job_planner.planner();
    let tolerance = emg_job::DrawingTolerance::new(emg_job::JOB_TOLERANCE_M, 0.0)?;
    let drawing = emg_io::read_svg_file(
        &workspace::root().join(file),
        &emg_io::Placement::default(),
        &tolerance.svg_options(),
    )?;
    let job = tolerance.job(drawing, planner.robot())?;
    let program = job_planner.plan(&job, &emg_job::Unwatched)?;
    let name = Path::new(file).file_stem().map_or_else(
        || file.to_string(),
        |stem| stem.to_string_lossy().into_owned(),
    );
    let page = emg_job::viewer_page(&program, &job, planner.robot(), &name);
    let html = workspace::root().join("target/readme-job-picture.html");
    emg_io::write_atomically(&html, page)?;
    screenshot(args, &html, out)?;
    println!(
        "planned {:.4} m of {:.4} m in {:.2} s; wrote {}",
        program.summary.drawn_m,
        program.summary.total_m,
        program.summary.duration_s,
        out.display()
    );
    Ok(())
}

/// `p0`, `d` and `n` of the README's `emg plan --p0 X,Y,Z --d X,Y,Z --n X,Y,Z` line.
fn readme_task(readme: &str) -> anyhow::Result<[Vec3; 3]> {
    let line = readme
        .lines()
        .find(|line| line.trim_start().starts_with("emg plan --p0"))
        .context("README.md holds no `emg plan --p0 …` command")?;
    let words: Vec<&str> = line.split_whitespace().collect();
    let vector = |flag: &str| -> anyhow::Result<Vec3> {
        let value = words
            .iter()
            .position(|w| *w == flag)
            .and_then(|i| words.get(i + 1))
            .with_context(|| format!("the README's command lacks {flag}"))?;
        let numbers: [f64; 3] = emg_planner::parse::numbers(value)?;
        Ok(Vec3::from(numbers))
    };
    Ok([vector("--p0")?, vector("--d")?, vector("--n")?])
}

/// Headless Chromium's still of `html` at `args.at` of the motion, written to `out`.
fn screenshot(args: &Args, html: &Path, out: &Path) -> anyhow::Result<()> {
    let chromium = args
        .chromium
        .clone()
        .or_else(|| std::env::var_os("EMG_CHROMIUM").map(PathBuf::from))
        .unwrap_or_else(|| PathBuf::from("chromium"));
    if let Some(parent) = out.parent() {
        std::fs::create_dir_all(parent)?;
    }
    let url = format!("file://{}#t={}", html.canonicalize()?.display(), args.at);
    let output = Command::new(&chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
            "--window-size=1100,650",
            "--virtual-time-budget=2000",
        ])
        .arg(format!("--screenshot={}", out.display()))
        .arg(url)
        .output()
        .with_context(|| {
            format!(
                "running {} (install Chromium or pass --chromium)",
                chromium.display()
            )
        })?;
    if !output.status.success() || !out.exists() {
        bail!(
            "{} failed: {}",
            chromium.display(),
            String::from_utf8_lossy(&output.stderr)
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_readme_task_is_read_from_its_command() {
        let readme = "text\n\n    emg plan --p0 0.45,-0.2,0.25 --d 0,1,0 --n 0,0,-1 --out line\n";
        let [p0, d, n] = readme_task(readme).unwrap();
        assert_eq!(p0, Vec3::new(0.45, -0.2, 0.25));
        assert_eq!((d, n), (Vec3::y(), -Vec3::z()));
        assert!(readme_task("no command").is_err());
        let text = std::fs::read_to_string(workspace::root().join("README.md")).unwrap();
        readme_task(&text).expect("the README's own command");
    }
}
