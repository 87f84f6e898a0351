//! `check`: a trajectory file or a job's program verified by the independent checker.

use std::path::{Path, PathBuf};

use emg_io::{ReadError, TrajectoryContents, task_file_beside};
use emg_verify::ReferenceModel;
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;

use crate::errors::{CheckFailed, InputError, input_error, message};
use crate::robot::Robot;

/// What the independent checker measured on a trajectory file that holds up.
#[pyclass(frozen, get_all, module = "extreme_line_motion")]
pub struct CheckReport {
    /// The file's layout (`emg-trajectory/1`, `emg-joint-trajectory/2`).
    layout: &'static str,
    /// The robot file it was checked with.
    robot: PathBuf,
    /// Number of points.
    points: usize,
    /// Time of the last point (s).
    duration_s: f64,
    /// `(p_last − p0)·d` (m), from the checker's own forward kinematics.
    path_length_m: f64,
    /// Largest distance of the tool centre point from the line (m).
    max_line_deviation_m: f64,
    /// Largest angle between the tool axis and the surface normal (degrees).
    max_tool_angle_deg: f64,
    /// Smallest clearance between checked link pairs (m).
    min_clearance_m: f64,
    /// The two links of the smallest clearance.
    min_clearance_links: (String, String),
    /// Per joint, the fastest segment speed as a fraction of its velocity limit.
    peak_speed_fraction: Vec<f64>,
    /// Per joint, the largest change of point velocity over its time gap (rad/s²).
    peak_acceleration_rad_s2: Vec<f64>,
    /// Whether the recorded TCP, path length and end were verified too (an
    /// `emg-trajectory/1` file).
    recorded_end_verified: bool,
}

#[pymethods]
impl CheckReport {
    fn __repr__(&self) -> String {
        format!(
            "CheckReport(points={}, path_length_m={:.4}, max_line_deviation_m={:.2e}, \
             max_tool_angle_deg={:.3}, min_clearance_m={:.4})",
            self.points,
            self.path_length_m,
            self.max_line_deviation_m,
            self.max_tool_angle_deg,
            self.min_clearance_m
        )
    }
}

/// What the independent checker verified on a job's program that holds up, as `emg check`
/// reports it.
#[pyclass(frozen, get_all, module = "extreme_line_motion")]
pub struct JobCheckReport {
    /// The program's format (`emg_job::JOB_FILE_FORMAT`).
    layout: &'static str,
    /// The robot file it was checked with.
    robot: PathBuf,
    /// Stroke parts verified on their paths.
    stroke_parts: usize,
    /// Moves between strokes verified clear of the arm, the plates and the scene.
    moves: usize,
    /// Samples verified from rest to rest within the file's joint limits.
    points: usize,
}

#[pymethods]
impl JobCheckReport {
    fn __repr__(&self) -> String {
        format!(
            "JobCheckReport(stroke_parts={}, moves={}, points={})",
            self.stroke_parts, self.moves, self.points
        )
    }
}

/// Verifies a file written by `Plan.save`, `JobPlan.write`, `emg plan` or `emg job` with the
/// independent checker, as `emg check` does: a trajectory file (either JSON layout, or the CSV
/// with the JSON of the same stem beside it) against the task, constraints and robot it
/// carries, returning a `CheckReport`; or a job's program segment by segment,
/// returning a `JobCheckReport`. `robot` overrides the robot the file names (a shipped robot's
/// name or a robot file). Raises `CheckFailed` naming the first failing point or segment and
/// the constraint.
#[pyfunction]
#[pyo3(signature = (path, robot = None))]
pub fn check(py: Python<'_>, path: PathBuf, robot: Option<PathBuf>) -> PyResult<Py<PyAny>> {
    let text = std::fs::read_to_string(&path)
        .map_err(|e| PyOSError::new_err(format!("cannot read {}: {e}", path.display())))?;
    if emg_job::JobFile::is_job(&text) {
        let report = check_job(&path, &text, robot.as_deref())?;
        return Ok(Py::new(py, report)?.into_any());
    }
    Ok(Py::new(py, check_trajectory(path, robot)?)?.into_any())
}

/// [`check`] of a job's program, `text` read from `path`.
fn check_job(path: &Path, text: &str, robot: Option<&Path>) -> PyResult<JobCheckReport> {
    let job = emg_job::JobFile::parse(text)
        .map_err(|e| InputError::new_err(format!("{} {e}", path.display())))?;
    let robot = Robot::named(&job.robot, path, robot)?;
    let model = checker(&robot)?;
    let check =
        emg_job::verify_job(&job, &model, robot.inner.joint_names()).map_err(|failure| {
            CheckFailed::new_err(format!("{} does not hold up: {failure}", path.display()))
        })?;
    Ok(JobCheckReport {
        layout: emg_job::JOB_FILE_FORMAT,
        robot: robot.file,
        stroke_parts: check.stroke_parts,
        moves: check.moves,
        points: check.points,
    })
}

/// The independent checker's model of `robot`, read again from its file.
fn checker(robot: &Robot) -> PyResult<ReferenceModel> {
    ReferenceModel::from_urdf_file(&robot.file, robot.inner.base_link(), robot.inner.tip_link())
        .map_err(|e| input_error(format!("the checker's robot {}", robot.file.display()), &e))
}

/// [`check`] of a trajectory file.
fn check_trajectory(path: PathBuf, robot: Option<PathBuf>) -> PyResult<CheckReport> {
    let read = |path: &Path| {
        TrajectoryContents::read(path).map_err(|e| match &e {
            ReadError::Io { .. } => PyOSError::new_err(message(&e)),
            ReadError::Format { .. } => InputError::new_err(message(&e)),
        })
    };
    let contents = read(&path)?;
    let own = contents.carried();
    let own_task = own.is_some();
    let beside = match &own {
        Some(_) => None,
        None => task_file_beside(&path)
            .map(|json| read(&json))
            .transpose()?,
    };
    let carried = own
        .or_else(|| beside.as_ref().and_then(TrajectoryContents::carried))
        .ok_or_else(|| {
            InputError::new_err(format!(
                "{} is a CSV file, which carries no task, and no {} lies beside it: check it \
                 with `emg check {} --task-from <emg-trajectory JSON>`",
                path.display(),
                path.with_extension("json").display(),
                path.display()
            ))
        })?;
    let named_by = if own_task {
        path.clone()
    } else {
        task_file_beside(&path).unwrap_or_else(|| path.clone())
    };
    let robot = Robot::named(&carried.robot, &named_by, robot.as_deref())?;
    let model = checker(&robot)?;
    let task = &carried.task;
    let task = task
        .revalidated(&robot.inner)
        .map_err(|e| input_error(format!("field 'task' of {}", path.display()), &e))?;
    let report = contents
        .verify(
            &model,
            robot.inner.joint_names(),
            &task,
            &carried.constraints,
            own_task,
            None,
        )
        .map_err(|failure| {
            CheckFailed::new_err(format!("{} does not hold up: {failure}", path.display()))
        })?;
    let (min_clearance_m, a, b) = report.min_clearance;
    Ok(CheckReport {
        layout: contents.layout(),
        robot: robot.file,
        points: report.points,
        duration_s: report.duration_s,
        path_length_m: report.path_length_m,
        max_line_deviation_m: report.max_line_deviation_m,
        max_tool_angle_deg: report.max_tool_angle_deg,
        min_clearance_m,
        min_clearance_links: (a, b),
        peak_speed_fraction: report.peak_speed_fraction,
        peak_acceleration_rad_s2: report.peak_acceleration_rad_s2,
        recorded_end_verified: matches!(contents, TrajectoryContents::Rollout(_)),
    })
}
