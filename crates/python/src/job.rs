//! `Planner.plan_job` and `JobPlan`: a drawing or a set of seams planned as one program from
//! Python (`emg_job::plan_job`).

use std::path::PathBuf;

use emg_job::{Job, JobError, JobFile};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::{InputError, PlanningError, input_error, message};

/// A job's program: every stroke to the limit, the safe moves between them, one timed joint
/// trajectory (docs/jobs.md). Arrays have one row per sample at 1 kHz.
#[pyclass(frozen, module = "extreme_line_motion")]
pub struct JobPlan {
    pub(crate) file: JobFile,
    /// The program's samples ([`JobFile::points`]).
    points: Vec<emg_io::JointTrajectoryPoint>,
}

/// The job of `job`: a job file or an SVG drawing (`str` or `os.PathLike`; an SVG is placed by
/// `placement`, a dict of `origin_m`, `normal`, `x_axis`, `width_m` or `scale_m_per_unit`), or
/// a `dict` in the job file's layout. An SVG drawing's corners are rounded within
/// `corner_tolerance_mm` (none by default), as `emg job --corner-tolerance` rounds them.
pub(crate) fn read_job(
    py: Python<'_>,
    robot: &emg_kinematics::Robot,
    job: &Bound<'_, PyAny>,
    placement: Option<&Bound<'_, PyDict>>,
    (tolerance_mm, corner_tolerance_mm): (f64, Option<f64>),
) -> PyResult<Job> {
    if !(tolerance_mm.is_finite() && tolerance_mm > 0.0) {
        return Err(InputError::new_err(format!(
            "tolerance_mm: must be a positive number, got {tolerance_mm}"
        )));
    }
    let dumps = |value: &Bound<'_, PyAny>| -> PyResult<String> {
        py.import("json")?
            .call_method1("dumps", (value,))?
            .extract()
    };
    let invalid =
        |e: &(dyn std::error::Error + 'static)| InputError::new_err(format!("job: {}", message(e)));
    if job.is_instance_of::<PyDict>() {
        if corner_tolerance_mm.is_some() {
            return Err(InputError::new_err(
                "corner_tolerance_mm: rounds an SVG drawing's corners; a job's strokes are \
                 followed as they are",
            ));
        }
        return Job::from_json("job", &dumps(job)?, robot).map_err(|e| invalid(&e));
    }
    let path: PathBuf = job
        .extract()
        .map_err(|_| InputError::new_err("job: give a job file's or an SVG's path, or a dict"))?;
    if path
        .extension()
        .is_some_and(|ext| ext.eq_ignore_ascii_case("svg"))
    {
        let placement = match placement {
            Some(dict) => placement_of(&dumps(dict.as_any())?)?,
            None => emg_job::default_placement(robot),
        };
        let tolerance = emg_job::DrawingTolerance::new(
            tolerance_mm * 1e-3,
            corner_tolerance_mm.unwrap_or(0.0) * 1e-3,
        )
        .map_err(|e| input_error("corner_tolerance_mm", &e))?;
        let drawing = emg_io::read_svg_file(&path, &placement, &tolerance.svg_options())
            .map_err(|e| invalid(&e))?;
        return tolerance.job(drawing, robot).map_err(|e| invalid(&e));
    }
    if placement.is_some() {
        return Err(InputError::new_err(
            "placement: places an SVG drawing; a job file's strokes are already placed",
        ));
    }
    if corner_tolerance_mm.is_some() {
        return Err(InputError::new_err(
            "corner_tolerance_mm: rounds an SVG drawing's corners; a job file's strokes are \
             followed as they are",
        ));
    }
    let text = std::fs::read_to_string(&path)
        .map_err(|e| PyOSError::new_err(format!("cannot read {}: {e}", path.display())))?;
    Job::from_json(&path.display().to_string(), &text, robot).map_err(|e| invalid(&e))
}

/// `job` with the home its program starts and ends at, as `emg job --home` sets it: `home`
/// when given (a sequence of floats, rad, one per joint, within the limits; else `InputError`
/// naming `home`), else the job's own, else the shipped arm's for a shipped robot; else none.
pub(crate) fn with_home(
    job: Job,
    robot: &crate::robot::Robot,
    home: Option<&Bound<'_, PyAny>>,
) -> PyResult<Job> {
    let given = home
        .map(|home| {
            home.extract::<Vec<f64>>().map_err(|_| {
                InputError::new_err(format!(
                    "home: give {} joint angles (rad), one per joint of the arm",
                    robot.inner.dof()
                ))
            })
        })
        .transpose()?;
    job.homed(given.as_deref(), robot.home, &robot.inner)
        .map_err(|e| match e {
            JobError::Home(problem) => InputError::new_err(format!("home: {problem}")),
            other => input_error("home", &other),
        })
}

/// What a job plans with at `tolerance_mm` (positive, as [`read_job`] checks it): `planner`
/// at that tolerance, timed and asked as `emg job` plans ([`emg_job::JobPlanner`]).
fn job_planner(
    planner: &emg_planner::Planner,
    robot: &crate::robot::Robot,
    tolerance_mm: f64,
) -> PyResult<emg_job::JobPlanner> {
    let mut config = planner.config().clone();
    config.rollout.constraints.line_tolerance_m = tolerance_mm * 1e-3;
    let planner = planner
        .with_config(config)
        .map_err(|e| input_error("tolerance_mm", &e))?;
    emg_job::JobPlanner::new(planner, &robot.file, robot.reference.clone())
        .map_err(|e| input_error("timing", &e))
}

/// The placement a dict's JSON `text` gives: the default's fields with the dict's over them (a
/// `scale_m_per_unit` given without `width_m` replaces the default width).
fn placement_of(text: &str) -> PyResult<emg_io::Placement> {
    let invalid = |e: serde_json::Error| InputError::new_err(format!("placement: {e}"));
    let given: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(text).map_err(invalid)?;
    let serde_json::Value::Object(mut fields) =
        serde_json::to_value(emg_io::Placement::default()).expect("a placement serialises")
    else {
        unreachable!("a placement serialises to an object")
    };
    if given.contains_key("scale_m_per_unit") && !given.contains_key("width_m") {
        fields.remove("width_m");
    }
    fields.extend(given);
    serde_json::from_value(serde_json::Value::Object(fields)).map_err(invalid)
}

/// Plans `job` with `planner` at `tolerance_mm`; the GIL is released while planning.
pub(crate) fn plan(
    py: Python<'_>,
    planner: &emg_planner::Planner,
    robot: &crate::robot::Robot,
    job: &Job,
    tolerance_mm: f64,
) -> PyResult<JobPlan> {
    let planner = job_planner(planner, robot, tolerance_mm)?;
    let file = py
        .detach(|| planner.plan(job, &emg_job::Unwatched))
        .map_err(|e| PlanningError::new_err(message(&e)))?;
    Ok(JobPlan::new(file))
}

/// A JSON value of the program as Python objects.
fn python<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).expect("a job's program serialises");
    py.import("json")?.call_method1("loads", (text,))
}

#[pymethods]
impl JobPlan {
    /// The totals `emg job` prints: `complete`, `resumed`, `short`, `drawn_m`, `total_m`,
    /// `travel_given_m`, `travel_m`, `duration_s`, `pen_down_s`, `pen_up_s`, `straight_moves`,
    /// `sampled_moves`, `searches`, `planning_s`, `ends_at_home`, and the least duration the
    /// arm's limits allow, `least_pen_down_s` and `least_pen_up_s`.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        python(py, &self.file.summary)
    }

    /// Every stroke's outcome in drawing order (dicts: `stroke`, `reversed`, `length_m`,
    /// `drawn_m`, `parts`, `unreached`, `unreached_at`, `unreached_causes` (dicts with a
    /// `cause`: `reach`, `no_start`, `left_out`, `untimed`, `not_searched`, `timed_short`),
    /// `parts_left_out`, and `unsearched_from_s` where the stroke's searches were spent before
    /// its end).
    #[getter]
    fn strokes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        python(py, &self.file.strokes)
    }

    /// The segments in time order, each a dict: `kind` (`stroke`, `retreat`, `travel`,
    /// `approach`), `stroke` and `part` for a stroke, `start_s`, `end_s`, and its samples as
    /// arrays `time_s` (n,) and `q` (n, joints).
    #[getter]
    fn segments<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let times = self.times();
        let list = PyList::empty(py);
        for segment in &self.file.segments {
            let dict = PyDict::new(py);
            let first = times.partition_point(|t| *t < segment.start_s - 1e-9);
            let last = times.partition_point(|t| *t <= segment.end_s + 1e-9);
            match segment.kind {
                emg_job::SegmentKind::Stroke { stroke, part, .. } => {
                    dict.set_item("kind", "stroke")?;
                    dict.set_item("stroke", stroke)?;
                    dict.set_item("part", part)?;
                }
                emg_job::SegmentKind::Retreat => dict.set_item("kind", "retreat")?,
                emg_job::SegmentKind::Travel => dict.set_item("kind", "travel")?,
                emg_job::SegmentKind::Approach => dict.set_item("kind", "approach")?,
            }
            dict.set_item("start_s", segment.start_s)?;
            dict.set_item("end_s", segment.end_s)?;
            dict.set_item("time_s", times[first..last].to_vec().into_pyarray(py))?;
            dict.set_item("q", self.rows(py, first..last, |p| &p.positions))?;
            list.append(dict)?;
        }
        Ok(list)
    }

    /// Time of every sample (s), shape (n,).
    #[getter]
    fn time_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.times().into_pyarray(py)
    }

    /// Joint positions of every sample (rad), shape (n, joints).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.rows(py, 0..self.points.len(), |p| &p.positions)
    }

    /// Joint velocities of every sample (rad/s), shape (n, joints).
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.rows(py, 0..self.points.len(), |p| &p.velocities)
    }

    /// Joint accelerations of every sample (rad/s²), shape (n, joints).
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.rows(py, 0..self.points.len(), |p| &p.accelerations)
    }

    /// Writes the program as an `emg-job/3` file (`emg check` verifies it).
    fn write(&self, path: PathBuf) -> PyResult<()> {
        let text = serde_json::to_string(&self.file).expect("a job's program serialises") + "\n";
        emg_io::write_atomically(&path, text)
            .map_err(|e| PyOSError::new_err(format!("cannot write {}: {e}", path.display())))
    }

    fn __repr__(&self) -> String {
        let s = &self.file.summary;
        format!(
            "JobPlan({} strokes: {} complete, {} resumed, {} short; {:.4} m of {:.4} m drawn; {:.2} s)",
            self.file.strokes.len(),
            s.complete,
            s.resumed,
            s.short,
            s.drawn_m,
            s.total_m,
            s.duration_s
        )
    }
}

impl JobPlan {
    /// The program `file`, its samples evaluated.
    pub(crate) fn new(file: JobFile) -> Self {
        let points = file.points();
        Self { file, points }
    }

    fn times(&self) -> Vec<f64> {
        self.points
            .iter()
            .map(|p| p.time_from_start.seconds())
            .collect()
    }

    fn rows<'py>(
        &self,
        py: Python<'py>,
        range: std::ops::Range<usize>,
        values: impl Fn(&emg_io::JointTrajectoryPoint) -> &Vec<f64>,
    ) -> Bound<'py, PyArray2<f64>> {
        let joints = self.file.joint_names.len();
        let points = &self.points[range];
        let flat: Vec<f64> = points.iter().flat_map(|p| values(p).clone()).collect();
        Array2::from_shape_vec((points.len(), joints), flat)
            .expect("one value per joint")
            .into_pyarray(py)
    }
}

/// Where to put a job's part (`emg_job::place_job`, docs/placement.md): the places planned, the
/// chosen one as a transform, its program, and the heat map.
#[pyclass(frozen, module = "extreme_line_motion")]
pub struct JobPlacement {
    placement: emg_job::Placement,
    score: emg_job::Score,
}

/// The region of `region`, a dict of `x_m`, `y_m`, `z_m` (shifts, m; `z_m` by default
/// [`emg_job::Region::DEFAULT_Z_M`]) and `rotation_deg` (turns), each `[low, high]`.
fn read_region(py: Python<'_>, region: &Bound<'_, PyDict>) -> PyResult<emg_job::Region> {
    let text: String = py
        .import("json")?
        .call_method1("dumps", (region,))?
        .extract()?;
    let region: emg_job::Region =
        serde_json::from_str(&text).map_err(|e| InputError::new_err(format!("region: {e}")))?;
    region
        .validate()
        .map_err(|e| InputError::new_err(message(&e)))?;
    Ok(region)
}

/// Places `job` over `region` with `planner` at `tolerance_mm`, screening `positions² ×
/// rotations` places by `score` (`"bound"` or `"point_ik"`) and planning the best `certify`; the
/// GIL is released meanwhile.
#[allow(clippy::too_many_arguments)]
pub(crate) fn place(
    py: Python<'_>,
    planner: &emg_planner::Planner,
    robot: &crate::robot::Robot,
    job: &Job,
    region: &Bound<'_, PyDict>,
    tolerance_mm: f64,
    (positions, rotations, certify): (usize, usize, usize),
    score: &str,
) -> PyResult<JobPlacement> {
    let region = read_region(py, region)?;
    let score = match score {
        "bound" => emg_job::Score::Bound,
        "point_ik" => emg_job::Score::PointIk,
        other => {
            return Err(InputError::new_err(format!(
                "score: '{other}' is not a score: bound or point_ik"
            )));
        }
    };
    let settings = emg_job::PlaceSettings {
        positions,
        rotations,
        certify,
        ..emg_job::PlaceSettings::default()
    };
    settings
        .validate()
        .map_err(|e| InputError::new_err(message(&e)))?;
    let planner = job_planner(planner, robot, tolerance_mm)?;
    let placement = py
        .detach(|| planner.place(job, &region, &settings, score, &emg_job::Unwatched))
        .map_err(|e| PlanningError::new_err(message(&e)))?;
    Ok(JobPlacement { placement, score })
}

#[pymethods]
impl JobPlacement {
    /// The places planned as full jobs, best first (dicts: `place` with `x_m`, `y_m`,
    /// `rotation_deg`; `score`, `depth_m`, `drawn_m`, `total_m`, `complete`, `strokes`,
    /// `duration_s`); the first is the chosen place.
    #[getter]
    fn certified<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        python(py, &self.placement.certified)
    }

    /// Every screened place in grid order (dicts: `place`, `score`, `depth_m`).
    #[getter]
    fn screened<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        python(py, &self.placement.screened)
    }

    /// Moving the base: its new pose in its present frame (`translation_m`, `rpy`); else `None`.
    #[getter]
    fn base_pose<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.placement
            .base_pose()
            .map(|pose| python(py, &pose))
            .transpose()
    }

    /// The chosen place as a job file's (and, moving the base, a scene file's) `transform`
    /// (`translation_m`, `rpy`).
    #[getter]
    fn transform<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        python(py, &self.placement.transform())
    }

    /// The program planned at the chosen place.
    #[getter]
    fn program(&self) -> JobPlan {
        JobPlan::new(
            (**self
                .placement
                .best()
                .program
                .as_ref()
                .expect("the chosen place was planned"))
            .clone(),
        )
    }

    /// The heat map as SVG text (what `emg place --map` writes).
    fn map_svg(&self) -> String {
        emg_job::placement_map(&self.placement, self.score)
    }

    fn __repr__(&self) -> String {
        let best = self.placement.best();
        format!(
            "JobPlacement({} places screened; chosen shift ({:.3}, {:.3}, {:.3}) m, turn {:.1}°: {:.4} m of {:.4} m drawn)",
            self.placement.screened.len(),
            best.scored.place.x_m,
            best.scored.place.y_m,
            best.scored.place.z_m,
            best.scored.place.rotation_deg,
            best.drawn_m,
            best.total_m
        )
    }
}
