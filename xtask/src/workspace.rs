//! Paths and shared loading of the workspace's data.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use anyhow::Context;
use emg_control::Task;
use emg_io::{TrajectoryContents, VerifyFailure, read_tasks};
use emg_kinematics::Robot;
use emg_planner::{
    DataDir, Models, MotionTiming, Planner, PlannerConfig, ShippedRobot, limits_file_beside,
};
use emg_timing::Scaling;
use emg_verify::ReferenceModel;
use serde::de::DeserializeOwned;

/// The workspace root (parent of `xtask/`).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives inside the workspace")
        .to_path_buf()
}

/// The workspace's `data/` directory, which the pipelines read and write.
pub fn data_dir() -> DataDir {
    DataDir::new(root().join("data"))
}

/// Where one robot's files live: its robot file and the sub-directory of its data, results,
/// figures and scratch files (empty for the FR3's top-level layout).
#[derive(Clone, Debug, PartialEq)]
struct RobotLayout {
    urdf: PathBuf,
    subdir: String,
}

static LAYOUT: OnceLock<RobotLayout> = OnceLock::new();

/// The robot file of `--robot` (a shipped robot's name or a URDF path).
pub fn robot_file(value: &str) -> Result<PathBuf, String> {
    Ok(layout_of(value).urdf)
}

/// A length in metres that is a finite number ≥ 0 (a clearance).
pub fn non_negative(value: &str) -> Result<f64, String> {
    match value.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("'{value}' is not a length ≥ 0 in metres")),
    }
}

/// The layout of `--robot` (a shipped robot's name or a URDF path): a shipped robot's own, or
/// `custom/<file stem>` directories for any other robot file.
fn layout_of(value: &str) -> RobotLayout {
    let data = data_dir();
    let shipped =
        ShippedRobot::by_name(value).or_else(|| ShippedRobot::by_path(Path::new(value), &data));
    if let Some(robot) = shipped {
        return RobotLayout {
            urdf: robot.path(&data),
            subdir: robot.data_subdir().into(),
        };
    }
    let urdf = PathBuf::from(value);
    let stem = urdf
        .file_stem()
        .map_or_else(|| "robot".into(), |s| s.to_string_lossy().into_owned());
    RobotLayout {
        urdf,
        subdir: format!("custom/{stem}"),
    }
}

/// Selects the robot whose files the commands' defaults point at, from the `--robot` value in
/// the command line (the FR3 when there is none). Call once, before parsing the arguments.
pub fn select_robot(args: &[String]) {
    let layout = layout_of(robot_value(args).unwrap_or("fr3"));
    LAYOUT.set(layout).expect("the robot is selected once");
}

/// The value of `--robot X` or `--robot=X` in `args`, if any.
fn robot_value(args: &[String]) -> Option<&str> {
    args.iter().enumerate().find_map(|(i, arg)| {
        arg.strip_prefix("--robot=").or_else(|| {
            (arg == "--robot")
                .then(|| args.get(i + 1).map(String::as_str))
                .flatten()
        })
    })
}

fn layout() -> &'static RobotLayout {
    LAYOUT.get_or_init(|| layout_of("fr3"))
}

/// The selected robot's file (the default of every `--robot`).
pub fn default_robot() -> PathBuf {
    layout().urdf.clone()
}

/// `relative` inside the selected robot's data directory (`data/` for the FR3).
pub fn data(relative: &str) -> PathBuf {
    data_dir().path().join(&layout().subdir).join(relative)
}

/// The selected robot's results directory (`docs/results/` for the FR3).
pub fn results_dir() -> PathBuf {
    root().join("docs/results").join(&layout().subdir)
}

/// `name` inside the selected robot's figure directory (`docs/figures/` for the FR3).
pub fn figure(name: &str) -> PathBuf {
    root()
        .join("docs/figures")
        .join(&layout().subdir)
        .join(name)
}

/// `name` inside the selected robot's scratch directory under `target/` (journals, checkpoints).
pub fn scratch(name: &str) -> PathBuf {
    root().join("target").join(&layout().subdir).join(name)
}

/// Path relative to the workspace root, for records that must not depend on the checkout place.
pub fn relative(path: &Path) -> String {
    let canonical = |p: &Path| p.canonicalize().unwrap_or_else(|_| p.to_path_buf());
    let (path, root) = (canonical(path), canonical(&root()));
    path.strip_prefix(&root)
        .unwrap_or(&path)
        .display()
        .to_string()
}

/// The JSON configuration in `path` (`what` names it in errors: serde's message names the
/// unknown or ill-typed field), or the default one when no file is given.
pub fn read_config<T: DeserializeOwned + Default>(
    path: Option<&Path>,
    what: &str,
) -> anyhow::Result<T> {
    let Some(path) = path else {
        return Ok(T::default());
    };
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("parsing {what} {}", path.display()))
}

/// Loads a robot file whose links form one chain (base = its root link, tip = its leaf).
pub fn load_robot(path: &Path) -> anyhow::Result<Robot> {
    Robot::from_chain_file(path).with_context(|| format!("loading robot {}", path.display()))
}

/// The independent checker of `robot`, read again from its file.
pub fn load_checker(path: &Path, robot: &Robot) -> anyhow::Result<ReferenceModel> {
    ReferenceModel::from_urdf_file(path, robot.base_link(), robot.tip_link())
        .with_context(|| format!("loading the checker's model of {}", path.display()))
}

/// What the planner comparisons start from: a shipped robot's planner (its shipped models, the
/// default config), its checker, and the first tasks of a task set.
pub struct PlannerSetup {
    /// The planner of the robot with its shipped models.
    pub planner: Planner,
    /// The independent checker of the same robot file.
    pub checker: ReferenceModel,
    /// The tasks.
    pub tasks: Vec<Task>,
}

/// The timing `emg plan` gives `planner`'s motions at `rate_hz` samples per second, within the
/// joint limits file beside the robot file `robot` (returned with it).
pub fn motion_timing(
    planner: &Planner,
    robot: &Path,
    rate_hz: f64,
) -> anyhow::Result<(MotionTiming, PathBuf)> {
    let limits_file = limits_file_beside(robot);
    let config = planner.config();
    let timing = MotionTiming::new(
        planner.robot(),
        &limits_file,
        Scaling::default(),
        config.rollout.speed_m_per_s,
        rate_hz,
        &config.rollout.constraints,
    )
    .with_context(|| format!("the joint limits {}", limits_file.display()))?;
    Ok((timing, limits_file))
}

/// Verifies the trajectory file `contents` of `task` as `emg check` verifies a file planned for
/// its own task: by `checker`, with the joints and constraints of `planner`.
pub fn verify_file(
    contents: &TrajectoryContents,
    planner: &Planner,
    checker: &ReferenceModel,
    task: &Task,
) -> Result<(), VerifyFailure> {
    contents
        .verify(
            checker,
            planner.robot().joint_names(),
            task,
            &planner.config().rollout.constraints,
            true,
            None,
        )
        .map(|_| ())
}

/// The [`PlannerSetup`] of the shipped robot file `robot` (its trained models, where it has
/// them) and the first `count` tasks of `task_file` (not read where `count` is 0); `command`
/// names the caller in errors.
pub fn planner_setup(
    robot: &Path,
    task_file: &Path,
    count: usize,
    command: &str,
) -> anyhow::Result<PlannerSetup> {
    let model = load_robot(robot)?;
    let checker = load_checker(robot, &model)?;
    let shipped = ShippedRobot::by_path(robot, &data_dir())
        .with_context(|| format!("{command} needs a shipped robot's models"))?;
    // An industrial arm ships without trained models: it plans by search alone.
    let models = if shipped.trained {
        Models::shipped(&model, &shipped.data_dir(&data_dir()))?
    } else {
        Models::load(&model, None, None)?
    };
    // No tasks asked for: none read (an industrial arm has no task sets).
    let mut tasks = if count == 0 {
        Vec::new()
    } else {
        read_tasks(task_file, &model)?
    };
    anyhow::ensure!(
        count <= tasks.len(),
        "{command} --tasks {count}: {} holds {} tasks",
        task_file.display(),
        tasks.len()
    );
    tasks.truncate(count);
    let planner = Planner::new(model, models, PlannerConfig::default())?;
    Ok(PlannerSetup {
        planner,
        checker,
        tasks,
    })
}

/// Builds a rayon pool with `threads` threads (0 = one per core).
pub fn thread_pool(threads: usize) -> anyhow::Result<rayon::ThreadPool> {
    Ok(rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?)
}

/// Writes a pipeline's results as `<out_dir>/<name>.json` (the record, pretty-printed) and
/// `<out_dir>/<name>.md` (its table), each atomically, creating the directory; says so.
pub fn write_results(
    out_dir: &Path,
    name: &str,
    record: &impl serde::Serialize,
    markdown: &str,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(out_dir)?;
    let json = out_dir.join(format!("{name}.json"));
    emg_io::write_atomically(&json, serde_json::to_string_pretty(record)? + "\n")?;
    let md = out_dir.join(format!("{name}.md"));
    emg_io::write_atomically(&md, markdown)?;
    println!("wrote {} and {}", json.display(), md.display());
    Ok(())
}

/// CPU model and core count of this machine.
pub fn machine() -> String {
    let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let model = cpuinfo
        .lines()
        .find_map(|l| {
            l.strip_prefix("model name")
                .map(|m| m.trim_start_matches([' ', '\t', ':']).to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    format!(
        "{model}, {} cores",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    )
}

/// The page, relative to the workspace root, of the generated tables the README links to rather
/// than shows (plan times, precision, loose bounds), each between its markers.
pub const RESULTS_SUMMARY: &str = "docs/results/summary.md";

/// Replaces the text between the `start` and `end` marker lines of `page` (a path relative to
/// the workspace root, such as [`RESULTS_SUMMARY`]) with `text` (atomically); an error when a
/// marker is missing.
pub fn replace_section(page: &str, start: &str, end: &str, text: &str) -> anyhow::Result<()> {
    let path = root().join(page);
    let content =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let (Some(from), Some(to)) = (content.find(start), content.find(end)) else {
        anyhow::bail!("{page} lacks the {start} … {end} markers");
    };
    let updated = format!("{}{start}\n{text}{}", &content[..from], &content[to..]);
    emg_io::write_atomically(&path, updated)?;
    Ok(())
}

/// The command line of `cargo xtask SUBCOMMAND` for `robot`: no `--robot` for the FR3, the
/// shipped arm's name for another, else the file.
pub fn command_for(subcommand: &str, robot: &Path) -> String {
    match emg_planner::ShippedRobot::by_path(robot, &data_dir()).map(|shipped| shipped.name) {
        Some("fr3") => format!("cargo xtask {subcommand}"),
        Some(name) => format!("cargo xtask {subcommand} --robot {name}"),
        None => format!("cargo xtask {subcommand} --robot {}", robot.display()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn robot_values_pick_shipped_or_custom_layouts() {
        let args = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert_eq!(
            robot_value(&args(&["xtask", "eval", "--robot", "iiwa14"])),
            Some("iiwa14")
        );
        assert_eq!(
            robot_value(&args(&["xtask", "eval", "--robot=fr3"])),
            Some("fr3")
        );
        assert_eq!(robot_value(&args(&["xtask", "eval"])), None);
        let iiwa = layout_of("iiwa14");
        assert_eq!(iiwa.subdir, "iiwa14");
        assert!(iiwa.urdf.ends_with("data/robots/iiwa14_pen.urdf") && iiwa.urdf.exists());
        let by_path = layout_of(iiwa.urdf.to_str().unwrap());
        assert_eq!(
            by_path, iiwa,
            "the shipped file by path is the shipped robot"
        );
        assert_eq!(layout_of("fr3").subdir, "");
        let custom = layout_of("arms/my_arm.urdf");
        assert_eq!(custom.subdir, "custom/my_arm");
        assert_eq!(custom.urdf, PathBuf::from("arms/my_arm.urdf"));
    }
}
