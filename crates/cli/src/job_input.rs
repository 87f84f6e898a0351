//! What a job is and how it is planned: the options `emg job` and `emg place` share, the job
//! read from a job file or an SVG drawing, and the planner and timing it is planned with.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use emg_io::{Placement, read_svg_file};
use emg_job::{Job, JobPlanner, Order, Tool};
use emg_planner::{Models, Planner};

use crate::options;
use crate::output::count;
use crate::robot;

/// What a job is and how it is planned: the options `emg job` and `emg place` share.
#[derive(Debug, Args)]
pub struct JobInput {
    /// The job: a job file (JSON, docs/jobs.md) or an SVG drawing (every subpath a stroke).
    #[arg(value_name = "JOB")]
    pub file: PathBuf,
    /// Robot: fr3, iiwa14, ur5e, irb120, kr16, or a URDF path.
    #[arg(long, value_parser = robot::parse_robot, default_value = "fr3")]
    pub robot: PathBuf,
    /// The strokes' line tolerance (mm).
    #[arg(long, value_name = "MM", default_value_t = emg_job::JOB_TOLERANCE_M * 1e3,
          value_parser = options::tolerance_mm, allow_hyphen_values = true)]
    pub tolerance: f64,
    /// The tool cone's half-angle around the surface normal (degrees).
    #[arg(long, value_name = "DEG", default_value_t = 30.0, value_parser = options::cone_deg,
          allow_hyphen_values = true)]
    pub cone: f64,
    /// The drawing order: `shortest` (default: order and directions that cut the pen-up travel)
    /// or `given`; overrides the job file's.
    #[arg(long, value_enum, hide_possible_values = true)]
    pub order: Option<Order>,
    /// The tool, whose lift between strokes is the default: `pen` (2 mm), `dispenser` (1 cm)
    /// or `torch` (3 cm); overrides the job file's.
    #[arg(long, value_enum, hide_possible_values = true)]
    pub tool: Option<Tool>,
    /// How far the tool lifts off the surface between strokes (mm); overrides the tool's and
    /// the job file's.
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub lift: Option<f64>,
    /// SVG only: how far the rounding of a corner may leave it (mm), out of --tolerance: the
    /// strokes are followed within the rest (docs/jobs.md#corner-rounding). 0 keeps every
    /// corner, passed at rest.
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub corner_tolerance: Option<f64>,
    /// SVG only: where the drawing's centre goes (m, base frame). Default: 0.45,0,0.25, or on
    /// an arm that reaches it only folded or stretched, in front of its shoulder where it
    /// reaches (docs/jobs.md).
    #[arg(long, value_name = "X,Y,Z", value_parser = options::parse_vec3, allow_hyphen_values = true)]
    pub origin: Option<[f64; 3]>,
    /// SVG only: the surface normal the pen points along.
    #[arg(long, value_name = "X,Y,Z", value_parser = options::parse_vec3, allow_hyphen_values = true)]
    pub normal: Option<[f64; 3]>,
    /// SVG only: the drawing's x axis on the surface.
    #[arg(long, value_name = "X,Y,Z", value_parser = options::parse_vec3, allow_hyphen_values = true)]
    pub x_axis: Option<[f64; 3]>,
    /// SVG only: the drawing's width (m). Default: 0.2 m, unless --scale sets the size.
    #[arg(long, value_name = "M")]
    pub width: Option<f64>,
    /// SVG only, instead of --width: metres per unit of the drawing (its CSS pixels), or
    /// `physical` for the drawing at its own physical size (`width="200mm"` draws 0.2 m wide).
    #[arg(long, value_name = "M_PER_UNIT|physical", value_parser = options::parse_scale,
          conflicts_with = "width")]
    pub scale: Option<f64>,
    /// The cell's obstacles (a scene file, docs/scene.md), which the arm keeps clear of while
    /// drawing and between strokes.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// The arm's home (rad, one value per joint, comma-separated): the program starts and ends
    /// there, through checked free moves. Default: the job file's `home`, else the shipped
    /// arm's (docs/jobs.md#home); a robot file with neither starts above its first stroke.
    #[arg(
        long,
        value_name = "Q,Q,…",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub home: Option<Vec<f64>>,
}

/// A job ready to plan: the job read, and what `emg job` and `emg place` plan it with.
pub struct Ready {
    /// The job.
    pub job: Job,
    /// The planner at the job's tolerance, cone and scene, its timing and request.
    pub planner: JobPlanner,
}

impl JobInput {
    /// The files the job is read from, named as an overwrite refusal names them.
    pub fn files(&self) -> Vec<(&'static str, &std::path::Path)> {
        let mut files = vec![
            ("job", self.file.as_path()),
            ("robot file", self.robot.as_path()),
        ];
        files.extend(self.scene.as_deref().map(|path| ("--scene", path)));
        files
    }

    /// The job read (its size printed, [`print_size`]) and its planner set up.
    pub fn ready(&self) -> Result<Ready> {
        let robot = robot::load_robot(&self.robot, None, None)?;
        let drawing = self.drawing_tolerance()?;
        let job = read_job(self, drawing.as_ref(), &robot)?;
        let shipped_home = robot::shipped(&self.robot).map(|shipped| shipped.home);
        let job = job
            .homed(self.home.as_deref(), shipped_home, &robot)
            .map_err(|e| match e {
                emg_job::JobError::Home(problem) if self.home.is_some() => {
                    anyhow::anyhow!("--home {problem}")
                }
                other => other.into(),
            })?;
        let mut config = emg_job::job_config(self.tolerance * 1e-3);
        config.rollout.constraints.theta_max_deg = self.cone;
        if let Some(path) = &self.scene {
            config.rollout.constraints.scene = emg_io::read_scene(path)?;
        }
        config.validate()?;
        let diffusion = robot::shipped_model(&self.robot, emg_planner::DIFFUSION_WEIGHTS_FILE);
        let policy = robot::shipped_model(&self.robot, emg_planner::POLICY_WEIGHTS_FILE);
        let models = Models::load(&robot, diffusion.as_deref(), policy.as_deref())?;
        let planner = Planner::new(robot, models, config)?;
        let recorded_as = robot::reference(&self.robot)?.to_string();
        let planner = JobPlanner::new(planner, &self.robot, recorded_as)?;
        print_size(&job);
        Ok(Ready { job, planner })
    }

    /// Whether the job is an SVG drawing (else a job file).
    fn is_svg(&self) -> bool {
        self.file
            .extension()
            .is_some_and(|ext| ext.eq_ignore_ascii_case("svg"))
    }

    /// A drawing's tolerance, shared between its corners and its strokes; `None` for a job
    /// file, whose strokes are followed as they are within --tolerance.
    fn drawing_tolerance(&self) -> Result<Option<emg_job::DrawingTolerance>> {
        if !self.is_svg() {
            if self.corner_tolerance.is_some() {
                anyhow::bail!(
                    "--corner-tolerance rounds the corners of an SVG drawing; {} is a job file, \
                     whose strokes are followed as they are",
                    self.file.display()
                );
            }
            return Ok(None);
        }
        let corner_m = self.corner_tolerance.unwrap_or(0.0) * 1e-3;
        emg_job::DrawingTolerance::new(self.tolerance * 1e-3, corner_m)
            .map(Some)
            .map_err(|e| anyhow::anyhow!("--corner-tolerance: {e}"))
    }
}

/// Prints a job's size before it is planned: its strokes and their length.
fn print_size(job: &Job) {
    println!(
        "{}, {:.3} m to draw",
        count(job.strokes.len(), "stroke"),
        job.strokes.iter().map(|s| s.length_m()).sum::<f64>()
    );
}

/// The job of a job file, or of an SVG drawing placed as the options say.
/// `tolerance` is the drawing's, for an SVG drawing.
fn read_job(
    args: &JobInput,
    tolerance: Option<&emg_job::DrawingTolerance>,
    robot: &emg_kinematics::Robot,
) -> Result<Job> {
    let mut job = if let Some(tolerance) = tolerance {
        let placement = placement(args, robot)?;
        let options = tolerance.svg_options();
        let drawing = read_svg_file(&args.file, &placement, &options)?;
        if drawing.dropped_tiny > 0 {
            println!(
                "{}: {} shorter than {} mm dropped",
                args.file.display(),
                count(drawing.dropped_tiny, "stroke"),
                options.min_stroke_m * 1e3
            );
        }
        tolerance.job(drawing, robot)?
    } else {
        if [&args.origin, &args.normal, &args.x_axis]
            .iter()
            .any(|o| o.is_some())
            || args.width.is_some()
            || args.scale.is_some()
        {
            anyhow::bail!(
                "--origin, --normal, --x-axis, --width and --scale place an SVG drawing; {} is a \
                 job file, whose strokes are already placed",
                args.file.display()
            );
        }
        let text = std::fs::read_to_string(&args.file)
            .with_context(|| format!("cannot read {}", args.file.display()))?;
        Job::from_json(&args.file.display().to_string(), &text, robot)?
    };
    if let Some(order) = args.order {
        job.settings.order = order;
    }
    if let Some(tool) = args.tool {
        job.settings.tool = tool;
        job.settings.lift_m = None;
    }
    if let Some(lift_mm) = args.lift {
        let lift_m = lift_mm * 1e-3;
        if !(lift_m.is_finite() && lift_m > 0.0 && lift_m <= 0.5) {
            anyhow::bail!("--lift must be in (0, 500] mm, got {lift_mm}");
        }
        job.settings.lift_m = Some(lift_m);
    }
    Ok(job)
}

/// The drawing's placement: the default for `robot` ([`emg_job::default_placement`]) with what
/// the options set.
fn placement(args: &JobInput, robot: &emg_kinematics::Robot) -> Result<Placement> {
    let mut placement = emg_job::default_placement(robot);
    if let Some(origin) = args.origin {
        placement.origin_m = origin;
    }
    if let Some(normal) = args.normal {
        placement.normal = normal;
    }
    if let Some(x_axis) = args.x_axis {
        placement.x_axis = x_axis;
    }
    if let Some(width) = args.width {
        placement.width_m = Some(width);
        placement.scale_m_per_unit = None;
    }
    if let Some(scale) = args.scale {
        placement.width_m = None;
        placement.scale_m_per_unit = Some(scale);
    }
    Ok(placement)
}
