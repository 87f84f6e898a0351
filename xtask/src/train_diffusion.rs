//! `cargo xtask train-diffusion`: trains the DP denoiser on the seed labels (resumable), ships
//! its EMA weights in `data/models/` and writes the loss curve to `docs/results/`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use emg_diffusion::{Backend, DiffusionConfig, TrainConfig, Trainer, TrainingSet, training_set};
use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_seeding::{LabelSet, hex};
use serde::{Deserialize, Serialize};

use crate::backend_choice::BackendChoice;
use crate::{figure, progress, workspace};

/// Options of `train-diffusion`.
#[derive(clap::Args)]
pub struct Args {
    /// JSON run configuration (`network`, `training`); unset fields keep the shipped defaults.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Training labels.
    #[arg(long, default_value_os_t = workspace::data("labels/train-v1.labels"))]
    labels: PathBuf,
    /// The task set the labels index.
    #[arg(long, default_value_os_t = workspace::data("tasks/train-v1.tasks"))]
    tasks: PathBuf,
    /// Shipped EMA weights (the run configuration is written beside them as .json).
    #[arg(long, default_value_os_t = workspace::data("models/diffusion-v1.weights"))]
    out: PathBuf,
    /// Checkpoint directory; a run finding one there resumes from it.
    #[arg(long, default_value_os_t = workspace::scratch("diffusion-v1-checkpoint"))]
    checkpoint: PathBuf,
    /// Burn backend.
    #[arg(long, value_enum, default_value_t = BackendChoice::Flex)]
    backend: BackendChoice,
    /// Instead of training: time this many steps on each backend and write
    /// docs/results/diffusion-backends.md.
    #[arg(long)]
    measure_backends: Option<usize>,
    /// Directory of the loss curve and the backend measurement.
    #[arg(long, default_value_os_t = workspace::results_dir())]
    results: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
}

/// The run configuration: the shipped network is smaller than the paper's (SPEC §6's defaults)
/// so that a 50-step, 32-candidate DP seed stays within a couple of milliseconds on one core.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunConfig {
    /// Network shape.
    pub network: DiffusionConfig,
    /// Training hyper-parameters.
    pub training: TrainConfig,
}

impl Default for RunConfig {
    fn default() -> Self {
        Self {
            network: DiffusionConfig {
                width: 64,
                hidden: 128,
                blocks: 2,
                time_dim: 64,
                ..DiffusionConfig::default()
            },
            training: TrainConfig {
                steps: 60_000,
                batch_size: 256,
                learning_rate: 1e-3,
                checkpoint_every_steps: 5_000,
                ..TrainConfig::default()
            },
        }
    }
}

/// What is written beside the shipped weights.
#[derive(Serialize)]
struct ModelCard<'a> {
    weights: String,
    labels: String,
    label_task_set_sha256: String,
    tasks: String,
    training_pairs: usize,
    backend: &'static str,
    run: &'a RunConfig,
    steps_done: usize,
    final_loss: Option<f64>,
    wall_seconds_this_session: f64,
}

/// Runs `train-diffusion`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let mut run_config: RunConfig =
        workspace::read_config(args.config.as_deref(), "run configuration")?;
    let robot = workspace::load_robot(&args.robot)?;
    // The denoiser's samples are the arm's joint configurations.
    run_config.network.data_dim = robot.dof();
    let (labels, data) = labelled_training_set(args, &robot)?;
    if let Some(steps) = args.measure_backends {
        return measure_backends(&run_config, &data, steps, &args.results);
    }
    let backend = Backend::from(args.backend);
    let mut trainer = open_trainer(args, &run_config, backend, &data)?;
    let started = Instant::now();
    train(args, &run_config, &mut trainer, &data)?;
    if let Some(dir) = args.out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    trainer
        .ema_weights()
        .clone()
        .stamped(emg_planner::robot_stamp(&robot))
        .write(&args.out)?;
    let card = ModelCard {
        weights: workspace::relative(&args.out),
        labels: workspace::relative(&args.labels),
        label_task_set_sha256: hex(labels.task_set_sha256()),
        tasks: workspace::relative(&args.tasks),
        training_pairs: data.len(),
        backend: backend.name(),
        run: &run_config,
        steps_done: trainer.step_count(),
        final_loss: trainer.loss_log().last().map(|row| row.loss),
        wall_seconds_this_session: started.elapsed().as_secs_f64(),
    };
    emg_io::write_atomically(
        args.out.with_extension("json"),
        serde_json::to_string_pretty(&card)? + "\n",
    )?;
    println!("wrote {} and its .json", workspace::relative(&args.out));
    Ok(())
}

/// The labels of `--labels` and the training pairs they make on the tasks of `--tasks`.
fn labelled_training_set(args: &Args, robot: &Robot) -> anyhow::Result<(LabelSet, TrainingSet)> {
    let tasks = read_tasks(&args.tasks, robot)
        .with_context(|| format!("reading {}", args.tasks.display()))?;
    let labels = LabelSet::read(&args.labels).with_context(|| {
        format!(
            "reading {} (create it with `cargo xtask label-seeds`)",
            args.labels.display()
        )
    })?;
    let name = format!(
        "{} (task set sha256 {})",
        workspace::relative(&args.labels),
        hex(labels.task_set_sha256())
    );
    let data = training_set(robot, &tasks, &labels, &name)?;
    println!(
        "{} training pairs from {} labelled tasks; mirror augmentation {}",
        data.len(),
        labels.tasks().len(),
        if data.has_mirror() {
            "on"
        } else {
            "off (the robot is not mirror-symmetric)"
        }
    );
    Ok((labels, data))
}

/// The trainer resumed from the checkpoint of `--checkpoint`, or a new one where there is none.
fn open_trainer(
    args: &Args,
    run_config: &RunConfig,
    backend: Backend,
    data: &TrainingSet,
) -> anyhow::Result<Trainer> {
    Ok(if args.checkpoint.join("state.json").exists() {
        let trainer = Trainer::resume(
            &args.checkpoint,
            run_config.network.clone(),
            run_config.training.clone(),
            backend,
            data,
        )?;
        println!(
            "resuming from step {} ({})",
            trainer.step_count(),
            args.checkpoint.display()
        );
        trainer
    } else {
        Trainer::new(
            run_config.network.clone(),
            run_config.training.clone(),
            backend,
            data,
        )?
    })
}

/// Trains to the configured step count, checkpointing and writing the loss curve on the way
/// and at the end.
fn train(
    args: &Args,
    run_config: &RunConfig,
    trainer: &mut Trainer,
    data: &TrainingSet,
) -> anyhow::Result<()> {
    let total = run_config.training.steps;
    let bar = progress::bar(total as u64, "training");
    bar.set_position(trainer.step_count() as u64);
    let mut recent = 0.0;
    while trainer.step_count() < total {
        let loss = trainer.train_step(data);
        recent = if recent == 0.0 {
            loss
        } else {
            0.98 * recent + 0.02 * loss
        };
        bar.inc(1);
        if trainer.step_count().is_multiple_of(50) {
            bar.set_message(format!("loss {recent:.4}"));
        }
        if trainer
            .step_count()
            .is_multiple_of(run_config.training.checkpoint_every_steps)
        {
            trainer.save_checkpoint(&args.checkpoint)?;
            write_loss_curve(trainer, &args.results)?;
        }
    }
    bar.finish();
    trainer.save_checkpoint(&args.checkpoint)?;
    write_loss_curve(trainer, &args.results)?;
    Ok(())
}

/// Times `steps` training steps on each backend; writes diffusion-backends.md.
fn measure_backends(
    run_config: &RunConfig,
    data: &TrainingSet,
    steps: usize,
    results: &Path,
) -> anyhow::Result<()> {
    let mut rows = String::new();
    for backend in [Backend::Flex, Backend::Ndarray] {
        let mut trainer = Trainer::new(
            run_config.network.clone(),
            run_config.training.clone(),
            backend,
            data,
        )?;
        trainer.train_step(data);
        let started = Instant::now();
        for _ in 0..steps {
            trainer.train_step(data);
        }
        let rate = steps as f64 / started.elapsed().as_secs_f64();
        println!("{}: {rate:.1} steps/s", backend.name());
        rows += &format!("| {} | {rate:.1} |\n", backend.name());
    }
    let network = &run_config.network;
    let text = format!(
        "# Diffusion training speed per Burn backend\n\n\
         Written by `cargo xtask train-diffusion --measure-backends {steps}`: optimiser steps per second \
         (batch {}, network width {}, hidden {}, {} blocks, time embedding {}), after one warm-up step, \
         on this machine while other jobs shared its cores.\n\n| backend | steps/s |\n|---|---|\n{rows}",
        run_config.training.batch_size,
        network.width,
        network.hidden,
        network.blocks,
        network.time_dim
    );
    std::fs::create_dir_all(results)?;
    emg_io::write_atomically(results.join("diffusion-backends.md"), text)?;
    Ok(())
}

/// The loss log as CSV and an SVG curve.
fn write_loss_curve(trainer: &Trainer, results: &Path) -> anyhow::Result<()> {
    use plotters::prelude::*;
    std::fs::create_dir_all(results)?;
    let log = trainer.loss_log();
    let mut csv = String::from("step,loss\n");
    for row in log {
        csv += &format!("{},{}\n", row.step, row.loss);
    }
    emg_io::write_atomically(results.join("diffusion-training.csv"), csv)?;
    if log.is_empty() {
        return Ok(());
    }
    let path = results.join("diffusion-training.svg");
    let root = figure::canvas(&path, (720, 420))?;
    let max_step = log.last().map_or(1, |r| r.step) as f64;
    let (low, high) = log.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
        (lo.min(r.loss), hi.max(r.loss))
    });
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Diffusion training loss (v-prediction MSE)",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(55)
        .build_cartesian_2d(
            0.0..max_step,
            libm::log10(low * 0.9)..libm::log10(high * 1.1),
        )?;
    chart
        .configure_mesh()
        .x_desc("optimiser step")
        .y_desc("log10 loss")
        .draw()?;
    chart.draw_series(LineSeries::new(
        log.iter().map(|r| (r.step as f64, libm::log10(r.loss))),
        &BLUE,
    ))?;
    root.present()?;
    Ok(())
}
