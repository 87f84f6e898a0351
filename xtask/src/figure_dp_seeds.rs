//! `cargo xtask figure-dp-seeds`: several DP seeds of one task drawn as arm stick figures in two
//! views, each labelled with the classical path length it reaches (the paper's Fig. 5).

use std::path::PathBuf;

use anyhow::{Context, bail};
use emg_control::{ClassicalController, RolloutConfig, Task, first_violation, rollout};
use emg_diffusion::{DenoiserWeights, DpSeedConfig, DpSeeder, SeedWorkspace};
use emg_io::read_tasks;
use emg_kinematics::{MAX_DOF, PoseTarget, Robot, Vec3, project_to_pose};
use plotters::prelude::*;

use crate::{figure, workspace};

/// Options of `figure-dp-seeds`.
#[derive(clap::Args)]
pub struct Args {
    /// Index of the evaluation task to draw.
    #[arg(long, default_value_t = 0)]
    task: usize,
    /// Candidates sampled (the IK-valid ones are drawn).
    #[arg(long, default_value_t = 16)]
    candidates: usize,
    /// Diffusion weights.
    #[arg(long, default_value_os_t = workspace::data("models/diffusion-v1.weights"))]
    weights: PathBuf,
    /// Task set.
    #[arg(long, default_value_os_t = workspace::data("tasks/eval-v1.tasks"))]
    tasks: PathBuf,
    /// Output SVG.
    #[arg(long, default_value_os_t = workspace::figure("dp-seeds.svg"))]
    out: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
}

/// One drawn seed: its stick-figure points and the length it reaches.
struct Drawn {
    points: Vec<Vec3>,
    length_m: f64,
}

/// Runs `figure-dp-seeds`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let robot = workspace::load_robot(&args.robot)?;
    let tasks = read_tasks(&args.tasks, &robot)
        .with_context(|| format!("reading {}", args.tasks.display()))?;
    let Some(task) = tasks.get(args.task) else {
        bail!(
            "--task {} is past the {} tasks of {}",
            args.task,
            tasks.len(),
            args.tasks.display()
        );
    };
    let drawn = ik_valid_seeds(args, &robot, task)?;
    if drawn.is_empty() {
        bail!(
            "none of the {} candidates of task {} is IK-valid; try another --task",
            args.candidates,
            args.task
        );
    }
    draw(args, task, &drawn)?;
    println!(
        "wrote {} ({} IK-valid seeds of {} candidates)",
        workspace::relative(&args.out),
        drawn.len(),
        args.candidates
    );
    Ok(())
}

/// The DP seed candidates of `task` that project onto its start pose within the constraints,
/// each with the length the classical controller reaches from it.
fn ik_valid_seeds(args: &Args, robot: &Robot, task: &Task) -> anyhow::Result<Vec<Drawn>> {
    let weights = DenoiserWeights::read(&args.weights)
        .with_context(|| format!("reading {}", args.weights.display()))?;
    let config = DpSeedConfig::default();
    let seeder = DpSeeder::new(robot, &weights, config.clone())?;
    let candidates =
        seeder.candidates(robot, task, args.candidates, &mut SeedWorkspace::default())?;
    let rollout_config = RolloutConfig::default();
    let target = PoseTarget {
        position: task.p0,
        tool_axis: task.n,
        roll_axis: None,
    };
    let mut drawn = Vec::new();
    for start in &candidates {
        let Ok((q, _)) = project_to_pose(robot, start, &target, &config.projection) else {
            continue;
        };
        let kinematics = robot.forward(&q);
        if first_violation(robot, task, &kinematics, &rollout_config.constraints).is_some() {
            continue;
        }
        let mut points = vec![Vec3::zeros()];
        points.extend((0..MAX_DOF).map(|i| kinematics.joint_origin(i)));
        points.push(kinematics.tcp());
        let trajectory = rollout(
            robot,
            task,
            &q,
            &mut ClassicalController::default(),
            &rollout_config,
        );
        drawn.push(Drawn {
            points,
            length_m: trajectory.path_length_m,
        });
    }
    Ok(drawn)
}

/// The stick figures of `drawn` beside `task`'s line, in a side and a top view.
fn draw(args: &Args, task: &Task, drawn: &[Drawn]) -> anyhow::Result<()> {
    let root = figure::canvas(&args.out, (1100, 520))?;
    let (left, right) = root.split_horizontally(550);
    let line_end = task.p0 + task.d * 0.8;
    for (area, (a, b), title) in [
        (left, (0, 2), "side view (x–z)"),
        (right, (0, 1), "top view (x–y)"),
    ] {
        let mut chart = ChartBuilder::on(&area)
            .caption(
                format!("DP seeds of evaluation task {}: {title}", args.task),
                ("sans-serif", 16),
            )
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(-0.9..0.9, if b == 2 { -0.2..1.3 } else { -0.9..0.9 })?;
        chart
            .configure_mesh()
            .x_desc(["x", "y", "z"][a])
            .y_desc(["x", "y", "z"][b])
            .draw()?;
        chart.draw_series(LineSeries::new(
            [task.p0, line_end].iter().map(|p| (p[a], p[b])),
            ShapeStyle::from(&RGBColor(150, 150, 150)).stroke_width(2),
        ))?;
        for (i, seed) in drawn.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            let series = chart.draw_series(LineSeries::new(
                seed.points.iter().map(|p| (p[a], p[b])),
                ShapeStyle::from(&color).stroke_width(2),
            ))?;
            if b == 2 {
                series
                    .label(format!("seed {}: L = {:.2} m", i + 1, seed.length_m))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
            }
            chart.draw_series(
                seed.points
                    .iter()
                    .map(|p| Circle::new((p[a], p[b]), 2, color.filled())),
            )?;
        }
        if b == 2 {
            figure::draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
        }
    }
    root.present()?;
    Ok(())
}
