//! Command-line arguments of `emg` (clap derive) and the small value parsers they need.

use std::path::PathBuf;
use std::str::FromStr;

use clap::{Args, Parser, Subcommand};
use emg_kinematics::WorkSurface;
use emg_planner::{ControllerKind, PlannerKind, SeedSource};

/// Extreme straight-line motion on an arm of six or seven joints holding a pen.
#[derive(Debug, Parser)]
#[command(name = "emg", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
#[allow(
    clippy::large_enum_variant,
    reason = "parsed once per run: boxing saves nothing worth the indirection"
)]
pub enum Command {
    /// Plan straight-line motions: seed, roll out a controller, write the trajectories.
    Plan(PlanArgs),
    /// Verify a trajectory file (emg-trajectory/1 JSON, emg-joint-trajectory/2 JSON or the CSV)
    /// with the independent checker; exit status 1 names the point and the constraint.
    #[command(visible_alias = "replay")]
    Check(CheckArgs),
    /// Import a vendor robot description: fit capsules to every link's collision geometry
    /// (boxes, cylinders, spheres, STL and OBJ meshes), attach the pen to the tool link, and
    /// write a standard URDF the planners and the checker read, with an SRDF beside it listing
    /// the link pairs not checked for self-collision (see docs/robot-import.md).
    ImportRobot(ImportArgs),
    /// Export a joint trajectory for a robot's own stack: `ros2-mcap` (a ROS 2
    /// trajectory_msgs/msg/JointTrajectory in an MCAP bag, joint names as the vendor's driver
    /// names them) or `urscript` (a program for a Universal Robots e-Series controller); see
    /// docs/robot-export.md.
    Export(crate::export::ExportArgs),
    /// Plan a job: a job file or an SVG drawing, every stroke to the limit (resumed after a
    /// reconfiguration where one motion cannot finish it), safe moves between strokes, one timed
    /// program written as an emg-job/3 file (see docs/jobs.md).
    Job(crate::job::JobArgs),
    /// Find where to put a job's part (shifted on its surface, turned about its normal) so the
    /// arm draws the most of it: places screened by the strokes' reachability bounds, the best
    /// planned as full jobs; writes the program at the chosen place, and on request the heat
    /// map and the job file with the place as its transform (see docs/placement.md).
    Place(crate::place::PlaceArgs),
}

/// Options of `emg import-robot`.
#[derive(Debug, Args)]
pub struct ImportArgs {
    /// The vendor description (URDF).
    #[arg(value_name = "URDF")]
    pub file: PathBuf,
    /// The URDF to write (capsules as a cylinder plus two sphere caps; the pen's link is
    /// `pen_tip`, the TCP).
    #[arg(long, value_name = "URDF")]
    pub out: PathBuf,
    /// Where `package://NAME/...` meshes are: a directory of packages (DIR/NAME, or a directory
    /// below DIR whose package.xml names NAME), or NAME=DIR for one package. Repeatable.
    #[arg(long, value_name = "DIR|NAME=DIR")]
    pub package_path: Vec<emg_io::PackagePath>,
    /// The link the pen attaches to, along its z axis (default: the file's only leaf link; of
    /// several, `tool0`, else `flange`, as REP 199 names them).
    #[arg(long)]
    pub tool_link: Option<String>,
    /// The chain's base link, checked to reach the pen (default: the file's only root link).
    #[arg(long)]
    pub base_link: Option<String>,
    /// Pen length from the tool link's origin to the tip (m) (default: 0.1 m beyond the tool's
    /// collision geometry along its z axis, the links fixed to it included; 0.1 m when none lies
    /// ahead of its origin).
    #[arg(long, value_name = "M")]
    pub pen_length: Option<f64>,
    /// Pen radius (m).
    #[arg(long, value_name = "M", default_value_t = emg_io::Pen::default().radius_m)]
    pub pen_radius: f64,
    /// An SRDF file (MoveIt's) whose `disable_collisions` pairs are not checked for
    /// self-collision, besides adjacent links and links whose capsules overlap at mid-range.
    #[arg(long, value_name = "SRDF")]
    pub srdf: Option<PathBuf>,
    /// Most capsules fitted to one link (1 to 3): a loose single capsule is split along its
    /// axis when that saves a quarter of its volume.
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u8).range(1..=3))]
    pub max_capsules: u8,
}

/// Options of `emg check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The file to verify: `<stem>.json`, `<stem>.joint_trajectory.json`, `<stem>.csv`, a job's
    /// program (emg-job/3) or a URScript program exported from one for the UR5e (`.script`).
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// A URScript program's job program (emg-job/3), which it is read back against. Default: the
    /// `.json` of the script's name (`drawing.job.script` and `drawing.job-part1.script` →
    /// `drawing.job.json`).
    #[arg(long, value_name = "JOB")]
    pub program: Option<PathBuf>,
    /// Robot: a shipped robot's name (`fr3`, `iiwa14`, `ur5e`) or a robot file (URDF). Default: the
    /// file's `robot` field (a JSON file, or the --task-from file for a CSV), else `fr3`.
    #[arg(long, value_name = "NAME|URDF", value_parser = crate::robot::parse_robot)]
    pub robot: Option<PathBuf>,
    /// Base link of the kinematic chain (default: the file's root link).
    #[arg(long)]
    pub base_link: Option<String>,
    /// Tip link of the chain, the TCP whose z-axis is the tool axis (default: the file's only
    /// leaf link).
    #[arg(long)]
    pub tip_link: Option<String>,
    /// Take the task (and, without --config, the constraints) from this emg-trajectory/1 or
    /// emg-joint-trajectory/2 file instead of FILE (a CSV carries none).
    #[arg(long, value_name = "JSON", conflicts_with = "p0")]
    pub task_from: Option<PathBuf>,
    /// A task given on the command line instead of the file's.
    #[command(flatten)]
    pub line: TaskLineArgs,
    /// As `plan --config` (a JSON file, or inline JSON starting with `{`): its
    /// `rollout.constraints` replace the file's.
    #[arg(long, value_name = "FILE|JSON")]
    pub config: Option<PathBuf>,
    /// Check a joint-trajectory file against these joint limits (MoveIt joint_limits.yaml,
    /// scaled by --velocity-scaling and --acceleration-scaling) instead of the file's own.
    #[arg(long, value_name = "YAML")]
    pub limits: Option<PathBuf>,
    /// Scaling of the --limits file.
    #[command(flatten)]
    pub scaling: ScalingArgs,
}

/// Velocity and acceleration scaling of joint limits, as MoveIt and Pilz take them.
#[derive(Debug, Args)]
pub struct ScalingArgs {
    /// Factor in (0, 1] on the joint velocity limits.
    #[arg(long, value_name = "F", default_value_t = 1.0)]
    pub velocity_scaling: f64,
    /// Factor in (0, 1] on the joint acceleration and jerk limits.
    #[arg(long, value_name = "F", default_value_t = 1.0)]
    pub acceleration_scaling: f64,
}

impl ScalingArgs {
    /// The factors, checked to lie in (0, 1].
    pub fn scaling(&self) -> Result<emg_timing::Scaling, emg_timing::LimitsError> {
        emg_timing::Scaling::new(self.velocity_scaling, self.acceleration_scaling)
    }
}

/// A task line on the command line: all three of `--p0`, `--d` and `--n`, or none.
#[derive(Debug, Args)]
pub struct TaskLineArgs {
    /// Task start position p0 (m), as x,y,z. Needs --d and --n.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true,
          requires_all = ["d", "n"])]
    pub p0: Option<[f64; 3]>,
    /// Task motion direction d, as x,y,z (normalised; must be perpendicular to n).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true,
          requires_all = ["p0", "n"])]
    pub d: Option<[f64; 3]>,
    /// Task-plane normal n, as x,y,z (normalised; the tool axis must stay near it).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true,
          requires_all = ["p0", "d"])]
    pub n: Option<[f64; 3]>,
}

/// Options of `emg plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// Robot: a shipped robot's name (`fr3`, the default, `iiwa14` or `ur5e`) or a robot file
    /// (URDF) of any serial arm of six or seven revolute joints.
    #[arg(long, value_name = "NAME|URDF", value_parser = crate::robot::parse_robot,
          default_value = "fr3")]
    pub robot: PathBuf,
    /// Base link of the kinematic chain (default: the file's root link).
    #[arg(long)]
    pub base_link: Option<String>,
    /// Tip link of the chain, the TCP whose z-axis is the tool axis (default: the file's only
    /// leaf link).
    #[arg(long)]
    pub tip_link: Option<String>,
    /// A task given on the command line.
    #[command(flatten)]
    pub line: TaskLineArgs,
    /// Task set to plan: JSON or the binary EMGTASKS layout (told apart by the content).
    #[arg(long, value_name = "FILE", conflicts_with = "p0")]
    pub task_file: Option<PathBuf>,
    /// A path to follow instead of a line: a JSON path file (start, surface normal, straight
    /// and circular segments, blend radius; docs/paths.md). The plan says how far along the
    /// path the tool gets.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["p0", "task_file"])]
    pub path: Option<PathBuf>,
    /// Seed source: `dp` (the diffusion seeder), `generating` (the task's q0_seed), `home`
    /// (mid-range of the joint limits), `q_mu` / `q_jl` (heuristic ascents from q0_seed) or
    /// `q=v1,...,vN` (radians, one per joint). Default: `dp` when the --weights file exists,
    /// else `generating` when the task has a q0_seed, else `home`.
    #[arg(long, value_name = "SOURCE", value_parser = SeedSource::from_str, allow_hyphen_values = true)]
    pub seed: Option<SeedSource>,
    /// Diffusion-seeder weights for `--seed dp` (default: those shipped for a shipped robot).
    #[arg(long, value_name = "WEIGHTS")]
    pub weights: Option<PathBuf>,
    /// Planner configuration: a JSON file, or the JSON itself when the value starts with `{`
    /// (e.g. `--config '{"search": {"budget_steps": 50000}}'`). Any of `rollout` (with
    /// `constraints`), `gains`, `switch`, `measure`, `reach` and `search`; unset fields keep
    /// their defaults (the work plate on). The schema is emg_planner's PlannerConfig,
    /// documented in docs/ARCHITECTURE.md.
    #[arg(long, value_name = "FILE|JSON")]
    pub config: Option<PathBuf>,
    /// Output path stem: writes STEM.json and STEM.csv (the planned path) and
    /// STEM.joint_trajectory.json (the motion timed rest to rest within the joint limits)
    /// (STEM-00000.json, ... for a task file holding several tasks); missing parent directories
    /// are created.
    #[arg(long, value_name = "STEM", default_value = "trajectory")]
    pub out: PathBuf,
    /// Also write a self-contained HTML page that animates the planned motion in 3D (for a
    /// task file holding several tasks: PATH-00000.html, ..., the extension kept).
    #[arg(long, value_name = "PATH")]
    pub html: Option<PathBuf>,
    /// Planner: `search` (the pipeline's plan first, then many candidate starts ranked by
    /// rollouts and detours repairing the longest, within the config's `search.budget_steps`;
    /// never shorter than the pipeline's plan) or `controller` (the paper's pipeline: one seed,
    /// one rollout).
    #[arg(long, value_name = "NAME", value_parser = PlannerKind::from_str, default_value = "search")]
    pub planner: PlannerKind,
    /// Null-space controller: `classical` (Eq. 3), `rl` (the PPO policy, Sec. 4.2) or `hybrid`
    /// (learned inside, classical near the joint limits, Sec. 4.3). Default: `hybrid` when a
    /// policy is trained for the robot (--policy or the shipped one), else `classical`.
    #[arg(long, value_name = "NAME", value_parser = ControllerKind::from_str)]
    pub controller: Option<ControllerKind>,
    /// Policy weights of `--controller rl` and `hybrid` (default: those shipped for a shipped
    /// robot).
    #[arg(long, value_name = "WEIGHTS")]
    pub policy: Option<PathBuf>,
    /// The part the line is drawn on, which the arm, all but the pen, keeps off: `plate` (a
    /// plate under the line, its top face in the plane through p0 with normal n: 0.2 m wide,
    /// from 0.05 m behind p0 to 2 m beyond, or less where it would meet the arm's base, 0.05 m
    /// thick; under a path it covers the path with those margins; the config's
    /// `rollout.constraints.work_surface` sets other sizes), `half-space` (everything beyond
    /// that plane) or `off` (the paper's protocol). Default: the --config file's
    /// `work_surface` when it sets one, else `plate`.
    #[arg(long, value_name = "plate|half-space|off", value_parser = WorkSurface::from_str)]
    pub surface: Option<WorkSurface>,
    /// How far the tool may leave the line or path (mm): the line tolerance of every step, of
    /// the bound, of the timed motion and of the checker. Default: the --config file's
    /// `rollout.constraints.line_tolerance_m`, else 20 mm (the paper's benchmark; a pen or a
    /// bead wants 0.5 mm or less).
    #[arg(long, value_name = "MM", value_parser = tolerance_mm, allow_hyphen_values = true)]
    pub tolerance: Option<f64>,
    /// Half-angle of the cone around the surface normal the tool axis stays in (degrees).
    /// Default: the --config file's `rollout.constraints.theta_max_deg`, else 30°.
    #[arg(long, value_name = "DEG", value_parser = cone_deg, allow_hyphen_values = true)]
    pub cone: Option<f64>,
    /// Scene file (JSON) of obstacles the whole arm, pen included, keeps clear of: half-spaces,
    /// boxes, spheres and capsules in the base frame, each with its clearance (see
    /// docs/scene.md). Replaces the --config file's `rollout.constraints.scene`.
    #[arg(long, value_name = "JSON")]
    pub scene: Option<PathBuf>,
    /// Also scan the task's reachability bound (how far along the line the arm can be placed
    /// at all, on a 1 cm grid), print it beside the path length and record it as
    /// `reachable_m`.
    #[arg(long, value_name = "on|off", default_value = "on")]
    pub reach: OnOff,
    /// Joint limits the joint trajectory is timed for (MoveIt joint_limits.yaml with velocity,
    /// acceleration and jerk limits). Default: <robot file stem>.joint_limits.yaml beside the
    /// robot file, else the robot file's velocity limits with assumed acceleration and jerk
    /// limits (5 rad/s², 300 rad/s³; said in the output).
    #[arg(long, value_name = "YAML")]
    pub limits: Option<PathBuf>,
    /// Scaling of the joint limits.
    #[command(flatten)]
    pub scaling: ScalingArgs,
    /// Largest tool speed of the timed motion (m/s): the tool moves at it wherever the joints
    /// allow. Default: the rollout's line speed (`rollout.speed_m_per_s`, 0.2).
    #[arg(long, value_name = "M_PER_S")]
    pub tool_speed: Option<f64>,
    /// Samples per second of the joint trajectory (1000 for libfranka).
    #[arg(long, value_name = "HZ", default_value_t = emg_planner::DEFAULT_RATE_HZ)]
    pub rate_hz: f64,
    /// Also export each joint trajectory for a robot's own stack, as `emg export` does:
    /// `ros2-mcap` (STEM.mcap) or `urscript` (STEM.script).
    #[arg(long, value_name = "FORMAT", value_parser = crate::export::parse_format)]
    pub export: Option<emg_io::ExportFormat>,
    /// urscript: most servoj lines (2 ms each) per program.
    #[arg(long, value_name = "N", default_value_t = emg_io::ExportOptions::default().max_servoj_lines)]
    pub max_servoj: usize,
}

/// A feature switched on or off on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OnOff {
    /// Enabled.
    On,
    /// Disabled.
    Off,
}

impl PlanArgs {
    /// The diffusion-seeder weights: `--weights`, else those shipped for the robot (if any).
    pub fn weights_path(&self) -> Option<PathBuf> {
        self.weights.clone().or_else(|| {
            crate::robot::shipped_model(&self.robot, emg_planner::DIFFUSION_WEIGHTS_FILE)
        })
    }

    /// The policy weights: `--policy`, else those shipped for the robot (if any).
    pub fn policy_path(&self) -> Option<PathBuf> {
        self.policy
            .clone()
            .or_else(|| crate::robot::shipped_model(&self.robot, emg_planner::POLICY_WEIGHTS_FILE))
    }
}

/// Parses `--tolerance`: the line tolerance in millimetres, a number > 0 (a negative one is read
/// as a value, not as a flag, and refused in the flag's unit).
pub fn tolerance_mm(s: &str) -> Result<f64, String> {
    bounded(s, "> 0 mm", |mm| mm > 0.0)
}

/// Parses `--cone`: the tool cone's half-angle in degrees, in (0, 90).
pub fn cone_deg(s: &str) -> Result<f64, String> {
    bounded(s, "in (0, 90)°", |deg| deg > 0.0 && deg < 90.0)
}

/// Parses `--scale`: metres per unit of an SVG drawing, a number > 0, or `physical` for its own
/// physical size ([`emg_io::SVG_PX_M`] per CSS pixel).
pub fn parse_scale(s: &str) -> Result<f64, String> {
    match s.trim() {
        "physical" => Ok(emg_io::SVG_PX_M),
        _ => bounded(s, "> 0 m per unit, or 'physical'", |scale| scale > 0.0),
    }
}

/// A finite number for which `holds` is true; else an error saying what it must be
/// (`wanted`) and what it is.
fn bounded(s: &str, wanted: &str, holds: impl Fn(f64) -> bool) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(value) if value.is_finite() && holds(value) => Ok(value),
        Ok(_) => Err(format!("must be {wanted}, got {s}")),
        Err(_) => Err(format!("must be a number {wanted}, got '{s}'")),
    }
}

/// Parses `x,y,z`.
pub fn parse_vec3(s: &str) -> Result<[f64; 3], emg_planner::ParseError> {
    emg_planner::parse::numbers(s)
}
