//! `cargo xtask train-ppo`: trains the RL null-space controller with PPO on the training pool
//! (resumable), ships its weights in `data/models/` and writes the learning curve to
//! `docs/results/`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use emg_control::RolloutConfig;
use emg_io::read_tasks;
use emg_policy::{
    Backend, EnvConfig, IterationLog, NetworkConfig, PpoConfig, Trainer, TrainingPool,
};
use emg_seeding::LabelSet;
use serde::{Deserialize, Serialize};

use crate::backend_choice::BackendChoice;
use crate::{figure, progress, workspace};

/// Options of `train-ppo`.
#[derive(clap::Args)]
pub struct Args {
    /// JSON run configuration (`network`, `ppo`, `env`, `rollout`); unset fields keep the
    /// shipped defaults.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Training task pool.
    #[arg(long, default_value_os_t = workspace::data("tasks/train-v1.tasks"))]
    tasks: PathBuf,
    /// Seed labels of the training pool (starting configurations); used when the file exists.
    #[arg(long, default_value_os_t = workspace::data("labels/train-v1.labels"))]
    labels: PathBuf,
    /// Shipped weights (the run configuration is written beside them as .json).
    #[arg(long, default_value_os_t = workspace::data("models/ppo-v1.weights"))]
    out: PathBuf,
    /// Checkpoint directory; a run finding one there resumes from it.
    #[arg(long, default_value_os_t = workspace::scratch("ppo-v1-checkpoint"))]
    checkpoint: PathBuf,
    /// Iterations between checkpoints.
    #[arg(long, default_value_t = 25)]
    checkpoint_every: u64,
    /// Stop (after a checkpoint) once this many minutes of this session have passed.
    #[arg(long)]
    stop_after_minutes: Option<f64>,
    /// Burn backend of the PPO update.
    #[arg(long, value_enum, default_value_t = BackendChoice::Flex)]
    backend: BackendChoice,
    /// Instead of training: time this many iterations on each backend and write
    /// docs/results/ppo-backends.md.
    #[arg(long)]
    measure_backends: Option<u64>,
    /// Worker threads of the rollouts (0 = one per core); results do not depend on it.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Directory of the learning curve and the backend measurement.
    #[arg(long, default_value_os_t = workspace::results_dir())]
    results: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
}

/// The run configuration (defaults: SPEC §5 adapted to two CPU cores).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunConfig {
    /// Actor and critic shape.
    pub network: NetworkConfig,
    /// PPO hyper-parameters.
    pub ppo: PpoConfig,
    /// Episode starts.
    pub env: EnvConfig,
    /// The shared rollout settings.
    pub rollout: RolloutConfig,
}

/// What is written beside the shipped weights.
#[derive(Serialize)]
struct ModelCard<'a> {
    weights: String,
    tasks: String,
    labels: Option<String>,
    labelled_tasks: usize,
    backend: &'static str,
    run: &'a RunConfig,
    iterations: u64,
    env_steps: u64,
    last: Option<&'a IterationLog>,
    training_wall_seconds: f64,
}

/// Runs `train-ppo`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let mut run_config: RunConfig =
        workspace::read_config(args.config.as_deref(), "run configuration")?;
    let robot = workspace::load_robot(&args.robot)?;
    // The observation and action follow the arm's joints.
    run_config.network.joints = robot.dof();
    let tasks = read_tasks(&args.tasks, &robot).with_context(|| {
        format!(
            "reading {} (create it with `cargo xtask make-tasks`)",
            args.tasks.display()
        )
    })?;
    let labels = if args.labels.exists() {
        Some(
            LabelSet::read(&args.labels)
                .with_context(|| format!("reading labels {}", args.labels.display()))?,
        )
    } else {
        println!(
            "no label file at {}: every episode starts from q0_seed",
            args.labels.display()
        );
        None
    };
    let stamp = emg_planner::robot_stamp(&robot);
    let pool = TrainingPool::new(
        robot,
        tasks,
        labels.as_ref(),
        run_config.rollout.clone(),
        run_config.env.clone(),
    )?;
    println!(
        "training pool: {} tasks, {} with labelled starts",
        pool.len(),
        pool.labelled_tasks()
    );
    let threads = workspace::thread_pool(args.threads)?;
    threads.install(|| match args.measure_backends {
        Some(iterations) => measure_backends(&run_config, &pool, iterations, &args.results),
        None => train(args, &run_config, &pool, labels.is_some(), &stamp),
    })
}

fn train(
    args: &Args,
    run_config: &RunConfig,
    pool: &TrainingPool,
    labelled: bool,
    stamp: &emg_learning::RobotStamp,
) -> anyhow::Result<()> {
    let backend = Backend::from(args.backend);
    let envs = pool.environments(run_config.ppo.envs);
    let (mut trainer, mut vec_env) = if args.checkpoint.join("state.json").exists() {
        println!("resuming from {}", args.checkpoint.display());
        Trainer::resume(
            &args.checkpoint,
            run_config.network.clone(),
            run_config.ppo.clone(),
            backend,
            envs,
        )?
    } else {
        let trainer = Trainer::new(run_config.network.clone(), run_config.ppo.clone(), backend)?;
        let vec_env = trainer.start_envs(envs)?;
        (trainer, vec_env)
    };
    let total = trainer.ppo().iterations();
    let bar = progress::bar(total, "ppo");
    bar.set_position(trainer.iteration());
    let session = Instant::now();
    let batch = trainer.ppo().batch_size() as f64;
    while !trainer.is_done() {
        let row = trainer.iterate(&mut vec_env)?.clone();
        let timing = *trainer.timing().last().expect("one per iteration");
        bar.set_message(format!(
            "{:.0} steps/s, return {:.1}, path {:.3} m",
            batch / (timing.collect_s + timing.update_s),
            row.mean_return.unwrap_or(f64::NAN),
            row.mean_score.unwrap_or(f64::NAN),
        ));
        bar.inc(1);
        let stop = args
            .stop_after_minutes
            .is_some_and(|m| session.elapsed().as_secs_f64() > 60.0 * m);
        if trainer.iteration() % args.checkpoint_every.max(1) == 0 || trainer.is_done() || stop {
            trainer.save_checkpoint(&args.checkpoint, &vec_env)?;
            write_outputs(args, run_config, &trainer, labelled, pool, stamp)?;
        }
        if stop {
            println!(
                "stopped after {:.1} min at iteration {}; rerun to resume",
                session.elapsed().as_secs_f64() / 60.0,
                trainer.iteration()
            );
            break;
        }
    }
    bar.finish();
    write_outputs(args, run_config, &trainer, labelled, pool, stamp)?;
    println!("wrote {}", args.out.display());
    Ok(())
}

/// Weights, model card, CSV learning curve, SVG plot and the run summary.
fn write_outputs(
    args: &Args,
    run_config: &RunConfig,
    trainer: &Trainer,
    labelled: bool,
    pool: &TrainingPool,
    stamp: &emg_learning::RobotStamp,
) -> anyhow::Result<()> {
    if let Some(dir) = args.out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let weights = trainer.weights().stamped(stamp.clone());
    weights.write(&args.out)?;
    let wall: f64 = trainer
        .timing()
        .iter()
        .map(|t| t.collect_s + t.update_s)
        .sum();
    let card = ModelCard {
        weights: workspace::relative(&args.out),
        tasks: workspace::relative(&args.tasks),
        labels: labelled.then(|| workspace::relative(&args.labels)),
        labelled_tasks: pool.labelled_tasks(),
        backend: Backend::from(args.backend).name(),
        run: run_config,
        iterations: trainer.iteration(),
        env_steps: weights.header().env_steps,
        last: trainer.log().last(),
        training_wall_seconds: wall,
    };
    emg_io::write_atomically(
        args.out.with_extension("json"),
        serde_json::to_string_pretty(&card)? + "\n",
    )?;
    write_learning_curve(trainer, &args.results)?;
    write_summary(trainer, run_config, card.backend, &args.results)
}

fn write_learning_curve(trainer: &Trainer, results: &Path) -> anyhow::Result<()> {
    use plotters::prelude::*;
    std::fs::create_dir_all(results)?;
    let mut csv = String::from(
        "iteration,env_steps,wall_s,episodes,mean_return,mean_path_length_m,policy_loss,value_loss,entropy,approx_kl,epochs,learning_rate\n",
    );
    let mut wall = 0.0;
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
    for (row, timing) in trainer.log().iter().zip(trainer.timing()) {
        wall += timing.collect_s + timing.update_s;
        csv += &format!(
            "{},{},{wall:.3},{},{},{},{},{},{},{},{},{}\n",
            row.iteration,
            row.env_steps,
            row.episodes,
            opt(row.mean_return),
            opt(row.mean_score),
            row.policy_loss,
            row.value_loss,
            row.entropy,
            row.approx_kl,
            row.epochs,
            row.learning_rate
        );
    }
    emg_io::write_atomically(results.join("ppo-learning-curve.csv"), csv)?;
    let points: Vec<(f64, f64)> = trainer
        .log()
        .iter()
        .filter_map(|r| r.mean_score.map(|s| (r.env_steps as f64 / 1e6, s)))
        .collect();
    if points.is_empty() {
        return Ok(());
    }
    let path = results.join("ppo-learning-curve.svg");
    let root = figure::canvas(&path, (720, 420))?;
    let max_x = points.last().map_or(1.0, |p| p.0).max(1e-3);
    let max_y = points.iter().fold(0.0f64, |m, p| m.max(p.1)) * 1.1;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "PPO learning curve: mean path length of training episodes",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(55)
        .build_cartesian_2d(0.0..max_x, 0.0..max_y.max(1e-3))?;
    chart
        .configure_mesh()
        .x_desc("environment steps (millions)")
        .y_desc("path length (m)")
        .draw()?;
    chart.draw_series(LineSeries::new(points, &BLUE))?;
    root.present()?;
    Ok(())
}

fn write_summary(
    trainer: &Trainer,
    run_config: &RunConfig,
    backend: &str,
    results: &Path,
) -> anyhow::Result<()> {
    let timing = trainer.timing();
    let collect: f64 = timing.iter().map(|t| t.collect_s).sum();
    let update: f64 = timing.iter().map(|t| t.update_s).sum();
    let steps = trainer.iteration() * trainer.ppo().batch_size() as u64;
    let last = trainer.log().last();
    let fmt = |v: Option<f64>| v.map_or("–".into(), |v| format!("{v:.3}"));
    let text = format!(
        "# PPO training run\n\n\
         Written by `cargo xtask train-ppo` (backend {backend}). Do not edit by hand.\n\n\
         | quantity | value |\n|---|---|\n\
         | network (actor and critic hidden layers) | {:?} |\n\
         | envs × rollout steps | {} × {} |\n\
         | minibatches × epochs | {} × {} |\n\
         | iterations | {} |\n\
         | environment steps | {steps} |\n\
         | wall time (rollouts + updates) | {:.1} min |\n\
         | throughput end to end | {:.0} env steps/s |\n\
         | rollout collection | {:.0} env steps/s |\n\
         | share of time in the update | {:.0} % |\n\
         | last iteration: mean training return | {} |\n\
         | last iteration: mean training path length (m) | {} |\n\n\
         The learning curve is in `ppo-learning-curve.csv` and `ppo-learning-curve.svg`.\n",
        run_config.network.hidden,
        run_config.ppo.envs,
        run_config.ppo.rollout_steps,
        run_config.ppo.minibatches,
        run_config.ppo.epochs,
        trainer.iteration(),
        (collect + update) / 60.0,
        steps as f64 / (collect + update).max(1e-9),
        steps as f64 / collect.max(1e-9),
        100.0 * update / (collect + update).max(1e-9),
        fmt(last.and_then(|r| r.mean_return)),
        fmt(last.and_then(|r| r.mean_score)),
    );
    emg_io::write_atomically(results.join("ppo-training.md"), text)?;
    Ok(())
}

/// Times `iterations` iterations (after one warm-up) on each backend; writes ppo-backends.md.
fn measure_backends(
    run_config: &RunConfig,
    pool: &TrainingPool,
    iterations: u64,
    results: &Path,
) -> anyhow::Result<()> {
    let mut rows = String::new();
    for backend in [Backend::Flex, Backend::Ndarray] {
        let mut trainer =
            Trainer::new(run_config.network.clone(), run_config.ppo.clone(), backend)?;
        let mut envs = trainer.start_envs(pool.environments(run_config.ppo.envs))?;
        trainer.iterate(&mut envs)?;
        for _ in 0..iterations {
            trainer.iterate(&mut envs)?;
        }
        let timing = &trainer.timing()[1..];
        let collect: f64 = timing.iter().map(|t| t.collect_s).sum();
        let update: f64 = timing.iter().map(|t| t.update_s).sum();
        let samples = (iterations * trainer.ppo().batch_size() as u64) as f64;
        println!(
            "{}: update {:.3} s/iteration, end to end {:.0} env steps/s",
            backend.name(),
            update / iterations as f64,
            samples / (collect + update)
        );
        rows += &format!(
            "| {} | {:.3} | {:.0} | {:.0} |\n",
            backend.name(),
            update / iterations as f64,
            samples / update,
            samples / (collect + update)
        );
    }
    let ppo = &run_config.ppo;
    let text = format!(
        "# PPO speed per Burn backend\n\n\
         Written by `cargo xtask train-ppo --measure-backends {iterations}`: {iterations} iterations after one \
         warm-up, actor and critic hidden layers {:?}, {} envs × {} steps, {} minibatches × {} epochs, on \
         this machine ({} threads) while other jobs shared its cores. Rollouts run the plain-Rust policy and \
         are the same for both; only the update runs in Burn.\n\n\
         | backend | update s/iteration | update samples/s | end to end env steps/s |\n|---|---|---|---|\n{rows}",
        run_config.network.hidden,
        ppo.envs,
        ppo.rollout_steps,
        ppo.minibatches,
        ppo.epochs,
        rayon::current_num_threads(),
    );
    std::fs::create_dir_all(results)?;
    emg_io::write_atomically(results.join("ppo-backends.md"), text)?;
    Ok(())
}
