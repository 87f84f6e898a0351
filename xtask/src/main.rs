//! `cargo xtask`: the workspace's pipelines.
//!
//! * `cargo xtask make-tasks`: the evaluation set and the training pool in `data/tasks/`.
//! * `cargo xtask eval --controller classical`: path-length statistics over the evaluation set,
//!   written to `docs/results/`.
//!
//! Every command takes `--robot <fr3|iiwa14|URDF>` (default `fr3`). The robot selects the
//! defaults of every other path: the FR3's files live at the top of `data/`, `docs/results/` and
//! `docs/figures/`; another shipped robot's under `<dir>/iiwa14/`; any other robot file's under
//! `<dir>/custom/<file stem>/`. Explicit path options still override each default.

mod ablate;
mod ablate_control;
mod backend_choice;
mod bench_report;
mod cartesian_eval;
mod corpus_eval;
mod eval;
mod figure;
mod figure_branches;
mod figure_dp_seeds;
mod gap_eval;
mod import_arms;
mod import_circles;
mod job_eval;
mod label_seeds;
mod limit;
mod make_tasks;
mod path_eval;
mod place_eval;
mod precision_eval;
mod progress;
mod protocol;
mod readme_picture;
mod regenerate;
mod report;
mod results;
mod search_eval;
mod search_shares;
mod stamp_weights;
mod surface_report;
mod task_set_options;
mod timing;
mod train_diffusion;
mod train_ppo;
mod velocity_limits;
mod workspace;

use clap::{Parser, Subcommand};

/// Pipelines of the extreme straight-line motion workspace.
#[derive(Parser)]
#[command(name = "cargo xtask")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Sample the evaluation set and the disjoint training pool (fixed seed, bit-for-bit regenerable).
    MakeTasks(make_tasks::Args),
    /// Evaluate a controller over the evaluation set and write the results to docs/results/.
    Eval(eval::Args),
    /// Regenerate docs/results.md (every table beside the paper's numbers) and its figures.
    Report(report::Args),
    /// Run the criterion benchmarks and write their medians to docs/results/benchmarks.md.
    BenchReport(bench_report::Args),
    /// Train the diffusion seeder on the seed labels (resumable); ship its EMA weights in data/models/.
    TrainDiffusion(train_diffusion::Args),
    /// Ablations written to docs/results/ablate-<variant>.{json,md}.
    #[command(subcommand)]
    Ablate(ablate::Variant),
    /// Draw several DP seeds of one task as arm stick figures (docs/figures/dp-seeds.svg).
    FigureDpSeeds(figure_dp_seeds::Args),
    /// Label seeds across self-motion branches (data/labels/), resumable and sharded; --report writes docs/results/labels.*.
    LabelSeeds(label_seeds::Args),
    /// Draw one task's self-motion branches along arc length (docs/figures/self-motion-branches.svg).
    FigureBranches(figure_branches::Args),
    /// Train the RL null-space controller with PPO (resumable); ship its weights in data/models/.
    TrainPpo(train_ppo::Args),
    /// Record in weights files which robot they were trained for (the values are unchanged).
    StampWeights(stamp_weights::Args),
    /// The search planner against the pipeline at several step budgets (docs/results/search.*).
    SearchEval(search_eval::Args),
    /// The baseline of motion-planning frameworks, a MoveIt-style Cartesian path, on the tasks
    /// of search-eval beside their bounds (docs/results/cartesian.*).
    CartesianEval(cartesian_eval::Args),
    /// The README's picture: its `emg plan` task planned and drawn by the viewer, a still taken
    /// by headless Chromium (docs/figures/readme-demo.png).
    ReadmePicture(readme_picture::Args),
    /// Best-known lengths (a large search) and reachability bounds of an evaluation subset
    /// (resumable, --shard i/n, --merge → docs/results/limit.*).
    Limit(limit::Args),
    /// Every task planned as `emg plan` plans it, timed rest to rest within the joint limits,
    /// written and checked as `emg check` checks it (docs/results/timing.*).
    Timing(timing::Args),
    /// The path population (rectangles, circles, arcs, S-curves) planned by the classical
    /// controller and the search beside the bound, checked and timed; rectangles also one line
    /// at a time (docs/results/paths.*).
    PathEval(path_eval::Args),
    /// Jobs on line-art icons and tilted seams planned as `emg job` plans them, checked, beside
    /// the baseline of strokes planned alone and joined straight (docs/results/jobs.*).
    JobEval(job_eval::Args),
    /// Drawings nobody here made (every icon of lucide-static and bootstrap-icons from npm,
    /// Hershey text from PyPI, generated coastlines and maps) planned on the shipped arms at
    /// `emg job`'s defaults and checked; resumable (docs/results/corpus.*).
    CorpusEval(corpus_eval::Args),
    /// `emg place` on icons near the edge of the arm's reach and a 20-stroke job, beside the
    /// usual point-by-point IK score; the screening timed (docs/results/placement.*).
    PlaceEval(place_eval::Args),
    /// The search at 20 mm, 0.5 mm and 0.1 mm with the paper's and the corrected step, on lines
    /// and paths, checked and timed (docs/results/precision.*).
    PrecisionEval(precision_eval::Args),
    /// The lines whose bound is likely loose, planned back from beyond the plan's end, with
    /// motions in place tried between the branches (docs/results/gaps.*).
    GapEval(gap_eval::Args),
    /// Every shipped task set, label file, model and result, each pipeline in dependency order
    /// (resumable: finished stages are journaled in target/regenerate/; --list, --from STAGE).
    Regenerate(regenerate::Args),
    /// Fail where the modules of a crate import each other in a circle (each circle listed).
    ImportCircles(import_circles::Args),
    /// Import the industrial arms shipped for their controllers' own programs (the ABB IRB 120
    /// of PyPI's compas-fab 2.0.1, the KUKA KR 16-2 of rtb-data 2.0.0) into data/robots/, each
    /// checked against its data sheet.
    ImportArms(import_arms::Args),
}

fn main() -> anyhow::Result<()> {
    workspace::select_robot(&std::env::args().collect::<Vec<_>>());
    match Cli::parse().command {
        Command::MakeTasks(args) => make_tasks::run(&args),
        Command::Eval(args) => eval::run(&args),
        Command::BenchReport(args) => bench_report::run(&args),
        Command::Report(args) => report::run(&args),
        Command::TrainDiffusion(args) => train_diffusion::run(&args),
        Command::Ablate(variant) => ablate::run(&variant),
        Command::FigureDpSeeds(args) => figure_dp_seeds::run(&args),
        Command::LabelSeeds(args) => label_seeds::run(&args),
        Command::TrainPpo(args) => train_ppo::run(&args),
        Command::FigureBranches(args) => figure_branches::run(&args),
        Command::StampWeights(args) => stamp_weights::run(&args),
        Command::SearchEval(args) => search_eval::run(&args),
        Command::CartesianEval(args) => cartesian_eval::run(&args),
        Command::ReadmePicture(args) => readme_picture::run(&args),
        Command::Limit(args) => limit::run(&args),
        Command::Timing(args) => timing::run(&args),
        Command::PathEval(args) => path_eval::run(&args),
        Command::PrecisionEval(args) => precision_eval::run(&args),
        Command::JobEval(args) => job_eval::run(&args),
        Command::CorpusEval(args) => corpus_eval::run(&args),
        Command::PlaceEval(args) => place_eval::run(&args),
        Command::GapEval(args) => gap_eval::run(&args),
        Command::Regenerate(args) => regenerate::run(&args),
        Command::ImportCircles(args) => import_circles::run(&args),
        Command::ImportArms(args) => import_arms::run(&args),
    }
}
