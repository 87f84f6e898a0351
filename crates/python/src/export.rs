//! `export`: a joint trajectory written for a robot's own stack, as `emg export` writes it.

use std::path::{Path, PathBuf};

use emg_io::{DriverProfile, ExportError, ExportFormat, ExportOptions, ExportRobot};
use emg_planner::ShippedRobot;
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;

use crate::data::data_dir;
use crate::errors::{InputError, message};
use crate::robot::Robot;

/// What an export wrote.
#[pyclass(frozen, get_all, module = "extreme_line_motion")]
pub struct ExportReport {
    /// `"ros2-mcap"`, `"urscript"`, `"rapid"` or `"krl"`.
    format: &'static str,
    /// The files written (several URScript programs for a motion split where it rests).
    files: Vec<PathBuf>,
    /// What was exported, in words (as `emg export` prints it).
    summary: String,
    /// ros2-mcap: points of the joint trajectory, and points kept in the message.
    points_before: Option<usize>,
    /// ros2-mcap: points kept.
    points_after: Option<usize>,
    /// ros2-mcap: the tolerance (rad) of the quintic spline through the kept points.
    tolerance_rad: Option<f64>,
    /// ros2-mcap: its largest joint deviation from any sample (rad).
    max_joint_deviation_rad: Option<f64>,
    /// ros2-mcap: its largest deviation at the tool (m).
    max_tool_deviation_m: Option<f64>,
    /// urscript servoj: the `servoj` targets, one every 2 ms (0 for a native program).
    servoj_targets: usize,
}

/// Exports the joint trajectory at `path` (`STEM.joint_trajectory.json`) or the job's program
/// there (an `emg-job/3` file) as `format` (`"ros2-mcap"`, `"urscript"`, or for a job's program
/// `"rapid"` on a six-joint ABB arm, one RAPID module, or `"krl"` on a six-joint KUKA arm, a
/// `.src` and its `.dat`) to `out`, for its own
/// robot or `robot` (a shipped robot's name or a robot file), as `emg export` does: nothing is
/// written on an error, and `out` never replaces `path`. `urscript` is `"native"` (one program of
/// movej, movel and blended movep with the tool's output: a job's program on the shipped UR5e,
/// its default there) or `"servoj"` (the joint values every 2 ms, split where the arm rests
/// into programs of at most `max_servoj_lines`).
#[pyfunction]
#[pyo3(signature = (path, format, out, robot = None, tolerance_rad = None, max_servoj_lines = None, urscript = None))]
pub fn export(
    path: PathBuf,
    format: &str,
    out: PathBuf,
    robot: Option<PathBuf>,
    tolerance_rad: Option<f64>,
    max_servoj_lines: Option<usize>,
    urscript: Option<&str>,
) -> PyResult<ExportReport> {
    let fail = |e: ExportError| match &e {
        ExportError::Read { .. } | ExportError::Write { .. } => PyOSError::new_err(message(&e)),
        _ => InputError::new_err(message(&e)),
    };
    let format: ExportFormat = format.parse().map_err(fail)?;
    let native = match urscript {
        None => None,
        Some("native") => Some(true),
        Some("servoj") => Some(false),
        Some(other) => {
            return Err(InputError::new_err(format!(
                "urscript is '{other}': give 'native' or 'servoj'"
            )));
        }
    };
    let text = std::fs::read_to_string(&path)
        .map_err(|e| PyOSError::new_err(format!("cannot read {}: {e}", path.display())))?;
    let job = if emg_job::JobFile::is_job(&text) {
        Some(
            emg_job::JobFile::parse(&text)
                .map_err(|e| InputError::new_err(format!("{} {e}", path.display())))?,
        )
    } else {
        None
    };
    let trajectory = match &job {
        Some(_) => None,
        None => Some(emg_io::read_joint_trajectory(&path).map_err(fail)?),
    };
    let (job_points, switches) = job
        .as_ref()
        .map(|job| (job.points(), job.tool_switches()))
        .unwrap_or_default();
    let output = job
        .as_ref()
        .map(|job| job.settings.tool_output.to_string())
        .unwrap_or_default();
    let tool = emg_io::ToolSwitching {
        switches: &switches,
        output: &output,
    };
    let (points, robot_field) = match (&job, &trajectory) {
        (Some(job), _) => (job.timed_points(&job_points, tool), job.robot.as_str()),
        (None, Some(trajectory)) => (trajectory.into(), trajectory.robot.as_str()),
        (None, None) => unreachable!("a file is read as one or the other"),
    };
    let robot = Robot::named(robot_field, &path, robot.as_deref())?;
    let shipped = ShippedRobot::by_path(&robot.file, &data_dir()?)
        .and_then(|s| DriverProfile::for_shipped(s.name));
    let file = robot.file.display().to_string();
    let defaults = ExportOptions::default();
    let options = ExportOptions {
        tolerance_rad: tolerance_rad.unwrap_or(defaults.tolerance_rad),
        max_servoj_lines: max_servoj_lines.unwrap_or(defaults.max_servoj_lines),
    };
    let target = ExportRobot {
        file: &file,
        reference: &robot.reference,
        shipped,
        kinematics: Some(&robot.inner),
    };
    let frames = shipped.is_some_and(DriverProfile::has_ur_controller_frames);
    let export = match (&job, format, native) {
        (Some(job), ExportFormat::UrScript, Some(true) | None) if frames => {
            emg_job::ur_program::ur_program_export(job, &robot.inner, &robot.reference, &out)
                .map_err(|e| InputError::new_err(message(&e)))?
        }
        (Some(job), ExportFormat::Rapid, _) => {
            emg_job::rapid_program::rapid_program_export(job, &robot.inner, &robot.reference, &out)
                .map_err(|e| InputError::new_err(message(&e)))?
        }
        (Some(job), ExportFormat::Krl, _) => {
            let flange = emg_kinematics::Robot::from_urdf_file(
                &robot.file,
                robot.inner.base_link(),
                "tool0",
            )
            .map_err(|e| {
                InputError::new_err(format!(
                    "a KRL program gives its tool in the flange's frame: robot {file} has no \
                     chain to tool0 (ROS-Industrial's flange link): {e}"
                ))
            })?;
            let tool = emg_job::krl_program::tool_in_flange(&robot.inner, &flange)
                .map_err(|e| InputError::new_err(message(&e)))?;
            emg_job::krl_program::krl_program_export(
                job,
                &robot.inner,
                &tool,
                &robot.reference,
                &out,
            )
            .map_err(|e| InputError::new_err(message(&e)))?
        }
        (_, ExportFormat::UrScript, Some(true)) => {
            return Err(InputError::new_err(format!(
                "urscript='native' writes a job's program (emg-job/3) for the shipped ur5e, \
                 whose frames are the controller's; {} for robot {file} is not one: give \
                 urscript='servoj'",
                path.display()
            )));
        }
        _ => emg_io::export(points, format, &out, &target, &options).map_err(fail)?,
    };
    export
        .write(&[
            ("joint trajectory", path.as_path()),
            ("robot", Path::new(&robot.file)),
        ])
        .map_err(fail)?;
    let thinning = export.thinning.as_ref();
    Ok(ExportReport {
        format: format.name(),
        files: export.files.iter().map(|(p, _)| p.clone()).collect(),
        summary: export.summary.clone(),
        points_before: thinning.map(|t| t.points_before),
        points_after: thinning.map(|t| t.points_after),
        tolerance_rad: thinning.map(|t| t.tolerance_rad),
        max_joint_deviation_rad: thinning.map(|t| t.max_joint_deviation_rad),
        max_tool_deviation_m: thinning.and_then(|t| t.max_tool_deviation_m),
        servoj_targets: export.servoj_targets,
    })
}
