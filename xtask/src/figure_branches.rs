//! `cargo xtask figure-branches`: the self-motion branches of one task's full pose as joint
//! trajectories along arc length, circles where a joint reaches its limit (the paper's Fig. 3e),
//! written to docs/figures/self-motion-branches.svg.
//!
//! The pose is the task's exact `(p0, n)` with the roll of SPEC §6 (`x = normalise(d − (d·n)n)`),
//! so its self-motion family is 1-D. IK solutions from many restarts are projected onto it; each
//! solution not already on a drawn branch is walked both ways until a limit, a collision or the
//! step cap, giving one branch.

use std::path::PathBuf;

use anyhow::{Context, bail};
use emg_control::{ClassicalController, rollout};
use emg_io::read_tasks;
use emg_kinematics::{JointVector, PoseTarget, project_to_pose};
use emg_seeding::{
    LabelConfig, SelfMotionWalk, WalkEnd, cone_ik_solutions, tangent_directions, walk,
};
use plotters::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::{figure, workspace};

/// Options of `figure-branches`.
#[derive(clap::Args)]
pub struct Args {
    /// Index of the evaluation task to draw.
    #[arg(long, default_value_t = 3)]
    task: usize,
    /// Most branches drawn.
    #[arg(long, default_value_t = 4)]
    max_branches: usize,
    /// Step cap of each walk direction.
    #[arg(long, default_value_t = 400)]
    max_steps: usize,
    /// Task set.
    #[arg(long, default_value_os_t = workspace::data("tasks/eval-v1.tasks"))]
    tasks: PathBuf,
    /// Output SVG.
    #[arg(long, default_value_os_t = workspace::figure("self-motion-branches.svg"))]
    out: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
}

/// One branch: the joint path along arc length, how each end stops, and the classical length.
struct Branch {
    points: Vec<JointVector>,
    arc_length_rad: Vec<f64>,
    ends: [WalkEnd; 2],
    length_m: f64,
}

/// Finds the branches and draws them.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let robot = workspace::load_robot(&args.robot)?;
    let tasks = read_tasks(&args.tasks, &robot)?;
    let task = tasks
        .get(args.task)
        .with_context(|| format!("--task {} but the set has {} tasks", args.task, tasks.len()))?;
    let mut config = LabelConfig::default();
    config.branch.max_steps = args.max_steps;
    let target = PoseTarget::with_roll_from_direction(task.p0, task.n, task.d);
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    rng.set_stream(args.task as u64);
    let mut starts = cone_ik_solutions(&robot, &task.p0, &task.n, &config.ik, &mut rng);
    starts.extend(task.q0_seed);
    let mut branches: Vec<Branch> = Vec::new();
    for start in &starts {
        let Ok((q, _)) = project_to_pose(&robot, start, &target, &config.projection) else {
            continue;
        };
        let valid = robot.limits().first_violation(&q, 0.0).is_none()
            && robot.first_collision(&robot.forward(&q), 0.0).is_none();
        let known = branches.iter().any(|b| {
            b.points
                .iter()
                .any(|p| (p - q).amax() < 2.0 * config.branch.reach_rad)
        });
        if !valid || known || branches.len() == args.max_branches {
            continue;
        }
        let [direction, _] = tangent_directions(&robot, &q, &target, &config.branch);
        let forward = walk(
            &robot,
            &q,
            &target,
            &direction,
            &config.branch,
            &config.projection,
        );
        let backward = walk(
            &robot,
            &q,
            &target,
            &-direction,
            &config.branch,
            &config.projection,
        );
        let mut controller = ClassicalController::new(config.gains.clone());
        let length_m = rollout(&robot, task, &q, &mut controller, &config.rollout).path_length_m;
        branches.push(join(&backward, &forward, length_m));
    }
    if branches.is_empty() {
        bail!(
            "no IK solution of task {} reaches its exact pose",
            args.task
        );
    }
    draw(args, &robot, &branches)?;
    println!(
        "wrote {} ({} branches of task {})",
        workspace::relative(&args.out),
        branches.len(),
        args.task
    );
    Ok(())
}

/// The branch through both walks' common start: backward walk reversed, then forward.
fn join(backward: &SelfMotionWalk, forward: &SelfMotionWalk, length_m: f64) -> Branch {
    let back_total = backward.arc_length_rad.last().copied().unwrap_or(0.0);
    let mut points: Vec<JointVector> = backward.points.iter().rev().copied().collect();
    let mut arc_length_rad: Vec<f64> = backward
        .arc_length_rad
        .iter()
        .rev()
        .map(|s| back_total - s)
        .collect();
    points.extend(forward.points.iter().skip(1));
    arc_length_rad.extend(
        forward
            .arc_length_rad
            .iter()
            .skip(1)
            .map(|s| back_total + s),
    );
    Branch {
        points,
        arc_length_rad,
        ends: [backward.end, forward.end],
        length_m,
    }
}

fn draw(args: &Args, robot: &emg_kinematics::Robot, branches: &[Branch]) -> anyhow::Result<()> {
    let height = 260 * branches.len() as u32;
    let root = figure::canvas(&args.out, (900, height))?;
    let limits = robot.limits();
    for (b, (branch, area)) in branches
        .iter()
        .zip(root.split_evenly((branches.len(), 1)))
        .enumerate()
    {
        let end_name = |end: &WalkEnd| match end {
            WalkEnd::JointLimit { joint } => format!("q{joint} at limit"),
            WalkEnd::SelfCollision => "self-collision".into(),
            WalkEnd::Stalled => "singular".into(),
            WalkEnd::StepCap => "step cap".into(),
        };
        let total = branch
            .arc_length_rad
            .last()
            .copied()
            .unwrap_or(0.0)
            .max(1e-3);
        let mut chart = ChartBuilder::on(&area)
            .caption(
                format!(
                    "branch {}: bounded by {} and {}; classical L = {:.2} m",
                    (b'b' + b as u8) as char,
                    end_name(&branch.ends[0]),
                    end_name(&branch.ends[1]),
                    branch.length_m
                ),
                ("sans-serif", 15),
            )
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(40)
            .build_cartesian_2d(0.0..total, -3.2..4.6)?;
        chart
            .configure_mesh()
            .x_desc("joint-space arc length (rad)")
            .y_desc("q (rad)")
            .draw()?;
        for joint in 0..robot.dof() {
            let color = Palette99::pick(joint).to_rgba();
            chart
                .draw_series(LineSeries::new(
                    branch
                        .arc_length_rad
                        .iter()
                        .zip(&branch.points)
                        .map(|(s, q)| (*s, q[joint])),
                    ShapeStyle::from(&color).stroke_width(2),
                ))?
                .label(format!("q{}", joint + 1))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
        }
        for (end, at) in branch.ends.iter().zip([0, branch.points.len() - 1]) {
            if let WalkEnd::JointLimit { joint } = end {
                let q = branch.points[at][joint - 1];
                let nearest =
                    if (q - limits.lower[joint - 1]).abs() < (q - limits.upper[joint - 1]).abs() {
                        limits.lower[joint - 1]
                    } else {
                        limits.upper[joint - 1]
                    };
                chart.draw_series(std::iter::once(Circle::new(
                    (branch.arc_length_rad[at], nearest),
                    7,
                    ShapeStyle::from(&BLACK).stroke_width(2),
                )))?;
            }
        }
        figure::draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    }
    root.present()?;
    Ok(())
}
