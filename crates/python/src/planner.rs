//! `Planner`, `Plan`, `Task` and `load_tasks`: planning from Python.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use emg_control::Trajectory;
use emg_io::PlanPaths;
use emg_kinematics::{Vec3, WorkSurface};
use emg_planner::{
    BoundNote, ControllerKind, DIFFUSION_WEIGHTS_FILE, Models, MotionTiming, POLICY_WEIGHTS_FILE,
    PlanError, PlanFiles, PlanRecord, PlanRequest, PlannerConfig, PlannerKind, SeedSource,
};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use crate::data::data_dir;
use crate::errors::{InputError, PlanningError, input_error, message};
use crate::robot::{Robot, array1, joint_array, joint_rows, joint_vector};
use crate::timing::Motion;
use emg_timing::Scaling;

/// Plans extreme straight-line motions for one robot with its models and configuration.
///
/// `robot`: a shipped robot (`"fr3"`, `"iiwa14"`) or a robot file. `models`: a directory holding
/// `diffusion-v1.weights` and/or `ppo-v1.weights` (default: the ones shipped for a shipped
/// robot; none for another robot file, which then plans with the classical controller).
/// `config`: a planner configuration, as a JSON file or a dict of its fields (`rollout`,
/// `gains`, `switch`, `measure`, `reach`, `search`); unset fields keep the defaults, the work
/// plate on. `surface`: the part the line is drawn on, `"plate"` (the default: a plate under
/// the line), `"half-space"` or `"off"` (the paper's protocol), over the config's;
/// `tolerance_mm`: how far the tool may leave the line or path (default: the config's, else
/// 20 mm); `cone_deg`: the tool cone's half-angle (default: the config's, else 30°); the same
/// defaults as `emg plan`.
#[pyclass(frozen, module = "extreme_line_motion")]
pub struct Planner {
    inner: Arc<emg_planner::Planner>,
    robot: Py<Robot>,
}

/// A task: move the tool from `p0` along the unit direction `d` on the surface with unit normal
/// `n` (base frame, m); `q0_seed` is the configuration a sampled task was generated from.
#[pyclass(frozen, module = "extreme_line_motion")]
pub struct Task {
    inner: emg_control::Task,
    /// Joints of the arm the task was validated for (the length of its `q0_seed`).
    joints: usize,
}

/// A planned task: the seed it started from and the motion, every step holding every
/// constraint. Arrays have one row per step, the seed first.
#[pyclass(frozen, module = "extreme_line_motion")]
pub struct Plan {
    planner: Arc<emg_planner::Planner>,
    /// The robot file (its limits file lies beside it).
    robot: String,
    /// How the saved files name the robot.
    reference: String,
    request: PlanRequest,
    task: emg_control::Task,
    plan: emg_planner::Plan,
    bound: Option<BoundNote>,
}

/// What `plan` and `plan_many` are asked for, parsed from their arguments.
struct Request {
    request: PlanRequest,
    reach: bool,
}

impl Request {
    /// The request of the arguments, for `planning` (its robot's joints, its models).
    fn parse(
        planning: &emg_planner::Planner,
        seed: Option<&Bound<'_, PyAny>>,
        controller: Option<&str>,
        planner: Option<&str>,
        reach: bool,
    ) -> PyResult<Self> {
        let seed = match seed {
            None => None,
            Some(value) => Some(match value.extract::<String>() {
                Ok(name) => name
                    .parse::<SeedSource>()
                    .map_err(|e| input_error("seed", &e))?,
                Err(_) => {
                    let angles = value.extract::<Vec<f64>>().map_err(|_| {
                        InputError::new_err(format!(
                            "seed: give a seed name (dp, generating, home, q_mu, q_jl) or {} \
                             joint angles (rad)",
                            planning.robot().dof()
                        ))
                    })?;
                    let q = joint_vector(planning.robot(), &angles, "seed")?;
                    SeedSource::Given(planning.robot().joints_of(&q).to_vec())
                }
            }),
        };
        let controller = match controller {
            Some(name) => name
                .parse::<ControllerKind>()
                .map_err(|e| input_error("controller", &e))?,
            None => planning.models().best_controller(),
        };
        let planner = match planner {
            Some(name) => name
                .parse::<PlannerKind>()
                .map_err(|e| input_error("planner", &e))?,
            None => PlanRequest::default().planner,
        };
        Ok(Self {
            request: PlanRequest {
                planner,
                seed,
                controller,
            },
            reach,
        })
    }
}

impl Planner {
    fn task(
        &self,
        p0: [f64; 3],
        d: [f64; 3],
        n: [f64; 3],
        q0_seed: Option<Vec<f64>>,
    ) -> PyResult<emg_control::Task> {
        let robot = self.inner.robot();
        let q0_seed = q0_seed
            .map(|q| joint_vector(robot, &q, "q0_seed"))
            .transpose()?;
        emg_control::Task::new(robot, Vec3::from(p0), Vec3::from(d), Vec3::from(n), q0_seed)
            .map_err(|e| input_error("task", &e))
    }

    /// The job `plan_job` and `place_job` plan: `job` read as [`crate::job::read_job`] reads
    /// it, starting and ending at `home` as [`crate::job::with_home`] sets it.
    fn homed_job(
        &self,
        py: Python<'_>,
        job: &Bound<'_, PyAny>,
        placement: Option<&Bound<'_, PyDict>>,
        tolerances: (f64, Option<f64>),
        home: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<emg_job::Job> {
        let job = crate::job::read_job(py, self.inner.robot(), job, placement, tolerances)?;
        crate::job::with_home(job, self.robot.get(), home)
    }

    /// One plan (and its reachability bound when asked), made without the GIL.
    fn plan_one(&self, task: &emg_control::Task, request: &Request) -> Result<Planned, PlanError> {
        let plan = self.inner.plan(task, &request.request)?;
        let bound = request.reach.then(|| self.inner.bound_note(task, &plan));
        Ok((plan, bound))
    }

    /// The plan of one validated `task`, made without the GIL, as its Python object.
    fn plan_task(
        &self,
        py: Python<'_>,
        task: emg_control::Task,
        request: &Request,
    ) -> PyResult<Plan> {
        let planned = py
            .detach(|| self.plan_one(&task, request))
            .map_err(|e| plan_error(e, &request.request, None))?;
        Ok(self.wrap(task, request, planned))
    }

    /// The Python object of a plan of `task`.
    fn wrap(&self, task: emg_control::Task, request: &Request, planned: Planned) -> Plan {
        let (plan, bound) = planned;
        Plan {
            planner: Arc::clone(&self.inner),
            robot: self.robot.get().file.display().to_string(),
            reference: self.robot.get().reference.clone(),
            request: request.request.clone(),
            task,
            plan,
            bound,
        }
    }
}

/// A plan and, when asked, what its output says of its task's reachability bound.
type Planned = (emg_planner::Plan, Option<BoundNote>);

/// A [`PlanError`] as the Python exception it raises (its message prefixed by `tasks[i]: ` for
/// task `i` of a batch): a controller that cannot be built is bad input (a learned controller
/// without its policy), a seed that cannot be prepared is a planning failure.
fn plan_error(error: PlanError, request: &PlanRequest, index: Option<usize>) -> PyErr {
    let task = index.map_or(String::new(), |i| format!("tasks[{i}]: "));
    match &error {
        PlanError::Controller(_) => InputError::new_err(format!(
            "{task}controller {:?}: {} (pass models= a directory with {POLICY_WEIGHTS_FILE}, or \
             use controller=\"classical\")",
            request.controller.name(),
            message(&error)
        )),
        PlanError::Seed(_) => PlanningError::new_err(format!(
            "{task}seed {:?}: {}",
            request.seed.as_ref().map_or("default", SeedSource::name),
            message(&error)
        )),
    }
}

/// The configuration a `config` argument gives: a JSON file or a dict of its fields.
fn read_config(config: Option<&Bound<'_, PyAny>>) -> PyResult<PlannerConfig> {
    let Some(config) = config else {
        return Ok(PlannerConfig::cell());
    };
    if config.is_instance_of::<PyDict>() {
        let text: String = config
            .py()
            .import("json")?
            .call_method1("dumps", (config,))?
            .extract()?;
        return PlannerConfig::from_json("config", &text).map_err(|e| input_error("config", &e));
    }
    let path: PathBuf = config
        .extract()
        .map_err(|_| InputError::new_err("config: give a JSON file's path or a dict"))?;
    PlannerConfig::read(&path).map_err(|e| input_error("config", &e))
}

/// The model files to load: those in `models`, or those shipped for `robot_file`.
fn model_files(robot_file: &Path, models: Option<&Path>) -> PyResult<[Option<PathBuf>; 2]> {
    let data = data_dir()?;
    let pick = |name: &str| match models {
        Some(dir) => Some(dir.join(name)).filter(|p| p.is_file()),
        None => data.shipped_model(robot_file, name).filter(|p| p.is_file()),
    };
    if let Some(dir) = models.filter(|dir| !dir.is_dir()) {
        return Err(InputError::new_err(format!(
            "models: {} is not a directory",
            dir.display()
        )));
    }
    Ok([pick(DIFFUSION_WEIGHTS_FILE), pick(POLICY_WEIGHTS_FILE)])
}

pub(crate) fn array2<'py, const N: usize>(
    py: Python<'py>,
    rows: impl ExactSizeIterator<Item = [f64; N]>,
) -> Bound<'py, PyArray2<f64>> {
    let count = rows.len();
    let flat: Vec<f64> = rows.flatten().collect();
    Array2::from_shape_vec((count, N), flat)
        .expect("rows of N values")
        .into_pyarray(py)
}

#[pymethods]
impl Planner {
    #[new]
    #[pyo3(signature = (robot = PathBuf::from("fr3"), models = None, config = None, surface = None, tolerance_mm = None, cone_deg = None),
           text_signature = "(robot='fr3', models=None, config=None, surface=None, tolerance_mm=None, cone_deg=None)")]
    fn new(
        py: Python<'_>,
        robot: PathBuf,
        models: Option<PathBuf>,
        config: Option<&Bound<'_, PyAny>>,
        surface: Option<&str>,
        tolerance_mm: Option<f64>,
        cone_deg: Option<f64>,
    ) -> PyResult<Self> {
        let robot = Robot::load(&robot)?;
        let mut config = read_config(config)?;
        if let Some(surface) = surface {
            config.rollout.constraints.work_surface = surface
                .parse::<WorkSurface>()
                .map_err(|e| InputError::new_err(format!("surface: {e}")))?;
        }
        let positive = |name: &str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(value)
            } else {
                Err(InputError::new_err(format!(
                    "{name}: must be a positive number, got {value}"
                )))
            }
        };
        if let Some(tolerance_mm) = tolerance_mm {
            config.rollout.constraints.line_tolerance_m =
                positive("tolerance_mm", tolerance_mm)? * 1e-3;
        }
        if let Some(cone_deg) = cone_deg {
            config.rollout.constraints.theta_max_deg = positive("cone_deg", cone_deg)?;
        }
        let [diffusion, policy] = model_files(&robot.file, models.as_deref())?;
        let loaded = Models::load(&robot.inner, diffusion.as_deref(), policy.as_deref())
            .map_err(|e| input_error("models", &e))?;
        let inner = emg_planner::Planner::new((*robot.inner).clone(), loaded, config)
            .map_err(|e| input_error("config", &e))?;
        Ok(Self {
            inner: Arc::new(inner),
            robot: Py::new(py, robot)?,
        })
    }

    /// The robot.
    #[getter]
    fn robot(&self, py: Python<'_>) -> Py<Robot> {
        self.robot.clone_ref(py)
    }

    /// Whether the diffusion seeder (seed `"dp"`) and the policy (controllers `"rl"`,
    /// `"hybrid"`) are loaded: `{"diffusion": bool, "policy": bool}`.
    #[getter]
    fn models(&self) -> std::collections::BTreeMap<&'static str, bool> {
        let models = self.inner.models();
        [
            ("diffusion", models.seeder.is_some()),
            ("policy", models.policy.is_some()),
        ]
        .into()
    }

    /// Plans the task `(p0, d, n)` (3 floats each, base frame).
    ///
    /// `seed`: `"dp"`, `"generating"`, `"home"`, `"q_mu"`, `"q_jl"` or n joint angles (rad);
    /// `None` picks `"dp"` when the seeder is loaded, else `"home"`. `controller`: `"hybrid"`,
    /// `"rl"` or `"classical"`; `None` picks `"hybrid"` when the policy is loaded, else
    /// `"classical"`. `planner`: `"search"` (the default, as `emg plan`: many starts within a
    /// step budget, never shorter than the pipeline) or `"controller"` (the paper's pipeline:
    /// one seed, one rollout). `reach`: also the task's reachability bound
    /// (`Plan.reachable_m`), as `emg plan` prints it. The GIL is released while planning.
    #[pyo3(signature = (p0, d, n, seed = None, controller = None, planner = None, reach = true))]
    #[allow(clippy::too_many_arguments)]
    fn plan(
        &self,
        py: Python<'_>,
        p0: [f64; 3],
        d: [f64; 3],
        n: [f64; 3],
        seed: Option<&Bound<'_, PyAny>>,
        controller: Option<&str>,
        planner: Option<&str>,
        reach: bool,
    ) -> PyResult<Plan> {
        let request = Request::parse(&self.inner, seed, controller, planner, reach)?;
        let task = self.task(p0, d, n, None)?;
        self.plan_task(py, task, &request)
    }

    /// Plans a path task: the tool follows `path` — a path file (`str` or `os.PathLike`) or a
    /// `dict` in the same layout (docs/paths.md: `version`, `start`, `normal`, `segments` of
    /// lines and arcs, `blend_radius_m`) — as far as it can; the plan's `termination` is
    /// `"completed"` when it reaches the end. Other arguments as for `plan`. A malformed path
    /// raises `InputError` naming the field.
    #[pyo3(signature = (path, seed = None, controller = None, planner = None, reach = true))]
    fn plan_path(
        &self,
        py: Python<'_>,
        path: &Bound<'_, PyAny>,
        seed: Option<&Bound<'_, PyAny>>,
        controller: Option<&str>,
        planner: Option<&str>,
        reach: bool,
    ) -> PyResult<Plan> {
        let request = Request::parse(&self.inner, seed, controller, planner, reach)?;
        let path = if path.is_instance_of::<PyDict>() {
            let text: String = py
                .import("json")?
                .call_method1("dumps", (path,))?
                .extract()?;
            emg_io::parse_path(&text)
                .map_err(|message| InputError::new_err(format!("path: {message}")))?
        } else {
            let file: PathBuf = path.extract()?;
            emg_io::read_path(&file).map_err(|e| input_error("path", &e))?
        };
        let task = emg_control::Task::on_path(self.inner.robot(), path, None)
            .map_err(|e| input_error("path", &e))?;
        self.plan_task(py, task, &request)
    }

    /// Plans a job — a drawing or a set of seams — as one program (docs/jobs.md): `job` a job
    /// file or an SVG drawing (a path; an SVG placed by `placement`, a dict of `origin_m`,
    /// `normal`, `x_axis`, `width_m`, by default pen down on a plate in front of the arm) or a
    /// dict in the job file's layout; `tolerance_mm` the strokes' line tolerance (default
    /// 0.5 mm, as `emg job`). Every stroke is searched to the limit, resumed where one motion
    /// cannot finish it, the strokes joined by checked free moves; the GIL is released while
    /// planning. `home` (rad, one value per joint) is where the program starts and ends, as
    /// `emg job --home`: by default the job's `home`, else the shipped arm's (`Robot.home`);
    /// a robot file with neither starts above its first stroke and ends above its last. A
    /// malformed job or home raises `InputError` naming the field; one of which no stroke can
    /// be drawn raises `PlanningError`. `corner_tolerance_mm` (SVG only) is how far the rounding
    /// of a corner may leave it, out of `tolerance_mm`, as `emg job --corner-tolerance`
    /// (by default none: every corner kept).
    // Literal defaults, which `help()` shows (an expression shows as `...`): `emg job`'s.
    #[pyo3(signature = (job, placement = None, tolerance_mm = 0.5, home = None, corner_tolerance_mm = None))]
    fn plan_job(
        &self,
        py: Python<'_>,
        job: &Bound<'_, PyAny>,
        placement: Option<&Bound<'_, PyDict>>,
        tolerance_mm: f64,
        home: Option<&Bound<'_, PyAny>>,
        corner_tolerance_mm: Option<f64>,
    ) -> PyResult<crate::job::JobPlan> {
        let tolerances = (tolerance_mm, corner_tolerance_mm);
        let job = self.homed_job(py, job, placement, tolerances, home)?;
        let robot = self.robot.get();
        crate::job::plan(py, &self.inner, robot, &job, tolerance_mm)
    }

    /// Finds where to put a job's part (docs/placement.md): `job` and `placement` as for
    /// `plan_job`; `region` a dict of `x_m`, `y_m` (shifts along the part's axes, m),
    /// `z_m` (shifts along its normal toward the tool, default `[-0.03, 0.03]`, three heights) and
    /// `rotation_deg` (turns about its normal), each `[low, high]`, and `moving` (`"part"`, the
    /// default, or `"base"`: the robot's base on its mount); `positions² × 3 × rotations` places
    /// screened by `score` (`"bound"`, each stroke's reachability bound, or `"point_ik"`,
    /// the share of stroke points with an IK solution), the best `certify` planned as full jobs,
    /// each starting and ending at `home` (and the corners rounded) as for `plan_job`. Returns a `JobPlacement`; a bad
    /// region, setting or home raises `InputError` naming it, a region the arm cannot reach
    /// `PlanningError`.
    #[pyo3(signature = (job, region, placement = None, tolerance_mm = 0.5, positions = 10, rotations = 5, certify = 5, score = "bound", home = None, corner_tolerance_mm = None))]
    #[allow(clippy::too_many_arguments)]
    fn place_job(
        &self,
        py: Python<'_>,
        job: &Bound<'_, PyAny>,
        region: &Bound<'_, PyDict>,
        placement: Option<&Bound<'_, PyDict>>,
        tolerance_mm: f64,
        positions: usize,
        rotations: usize,
        certify: usize,
        score: &str,
        home: Option<&Bound<'_, PyAny>>,
        corner_tolerance_mm: Option<f64>,
    ) -> PyResult<crate::job::JobPlacement> {
        let tolerances = (tolerance_mm, corner_tolerance_mm);
        let job = self.homed_job(py, job, placement, tolerances, home)?;
        let robot = self.robot.get();
        crate::job::place(
            py,
            &self.inner,
            robot,
            &job,
            region,
            tolerance_mm,
            (positions, rotations, certify),
            score,
        )
    }

    /// Plans every task of `tasks` (`Task` objects, e.g. from `load_tasks`, or `(p0, d, n)`
    /// triples) in parallel on all cores with the GIL released; the plans come in task order
    /// and do not depend on the number of threads. Arguments as for `plan`; the first task
    /// that fails raises, naming its index.
    #[pyo3(signature = (tasks, seed = None, controller = None, planner = None, reach = true))]
    fn plan_many(
        &self,
        py: Python<'_>,
        tasks: &Bound<'_, PyAny>,
        seed: Option<&Bound<'_, PyAny>>,
        controller: Option<&str>,
        planner: Option<&str>,
        reach: bool,
    ) -> PyResult<Vec<Plan>> {
        let request = Request::parse(&self.inner, seed, controller, planner, reach)?;
        let mut parsed = Vec::new();
        for (index, item) in tasks.try_iter()?.enumerate() {
            let item = item?;
            let task = match item.cast::<Task>() {
                Ok(task) => {
                    let task = &task.get().inner;
                    let robot = self.inner.robot();
                    let q0 = task.q0_seed.map(|q| robot.joints_of(&q).to_vec());
                    self.task(task.p0.into(), task.d.into(), task.n.into(), q0)
                }
                Err(_) => match item.extract::<([f64; 3], [f64; 3], [f64; 3])>() {
                    Ok((p0, d, n)) => self.task(p0, d, n, None),
                    Err(_) => Err(InputError::new_err(
                        "give a Task or a (p0, d, n) triple of 3 floats each",
                    )),
                },
            };
            parsed.push(
                task.map_err(|e| InputError::new_err(format!("tasks[{index}]: {}", e.value(py))))?,
            );
        }
        let planned: Vec<Result<Planned, PlanError>> = py.detach(|| {
            parsed
                .par_iter()
                .map(|task| self.plan_one(task, &request))
                .collect()
        });
        parsed
            .into_iter()
            .zip(planned)
            .enumerate()
            .map(|(index, (task, planned))| match planned {
                Ok(planned) => Ok(self.wrap(task, &request, planned)),
                Err(error) => Err(plan_error(error, &request.request, Some(index))),
            })
            .collect()
    }

    /// The reachability bound of the task `(p0, d, n)` (m): how far along the line the arm can
    /// be placed at all (every point within the line tolerance, tool in the cone, within the
    /// joint limits, collision-free); an upper bound on any plan's path length, only as good as
    /// its IK sampling.
    fn reach(&self, py: Python<'_>, p0: [f64; 3], d: [f64; 3], n: [f64; 3]) -> PyResult<f64> {
        let task = self.task(p0, d, n, None)?;
        Ok(py.detach(|| self.inner.reach(&task, &[]).reachable_m))
    }

    fn __repr__(&self) -> String {
        format!(
            "Planner(robot={:?})",
            self.robot.get().file.display().to_string()
        )
    }
}

impl Plan {
    /// The timing the keyword arguments of `timed` and `save` ask for, for the plan's robot
    /// read from its robot file: `limits` a MoveIt joint_limits.yaml (default: the one beside
    /// the robot file, else the robot file's velocities with assumed acceleration and jerk
    /// limits), `tool_speed` in m/s (default: the rollout's line speed).
    fn timing(
        &self,
        limits: Option<PathBuf>,
        velocity_scaling: f64,
        acceleration_scaling: f64,
        tool_speed: Option<f64>,
        rate_hz: f64,
    ) -> PyResult<MotionTiming> {
        let scaling = Scaling::new(velocity_scaling, acceleration_scaling)
            .map_err(|e| input_error("scaling", &e))?;
        let config = self.planner.config();
        MotionTiming::for_robot_file(
            self.planner.robot(),
            Path::new(&self.robot),
            limits.as_deref(),
            scaling,
            tool_speed.unwrap_or(config.rollout.speed_m_per_s),
            rate_hz,
            &config.rollout.constraints,
        )
        .map_err(|e| input_error("timing", &e))
    }
}

fn trajectory(plan: &Plan) -> &Trajectory {
    &plan.plan.trajectory
}

#[pymethods]
impl Plan {
    /// Joint configurations (rad), shape (T, n).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let steps = &trajectory(self).steps;
        joint_rows(py, self.planner.robot().dof(), steps.iter().map(|s| &s.q))
    }

    /// Times since the start (s), shape (T,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, trajectory(self).steps.iter().map(|s| s.time_s))
    }

    /// Tool-centre-point positions (m, base frame), shape (T, 3).
    #[getter]
    fn tcp<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let steps = &trajectory(self).steps;
        array2(py, steps.iter().map(|s| [s.tcp.x, s.tcp.y, s.tcp.z]))
    }

    /// Angle between the tool axis and the surface normal (degrees), shape (T,).
    #[getter]
    fn tool_angle_deg<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, trajectory(self).steps.iter().map(|s| s.tool_angle_deg))
    }

    /// Joint-limit proximity ρ(q) per step, shape (T,).
    #[getter]
    fn rho<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, trajectory(self).steps.iter().map(|s| s.rho))
    }

    /// The controller acting from each step (`"classical"`, `"learned"`, `"search"`; `None` on a
    /// final step that issued no command).
    #[getter]
    fn controllers(&self) -> Vec<Option<&'static str>> {
        trajectory(self)
            .steps
            .iter()
            .map(|s| s.controller.map(|c| c.name()))
            .collect()
    }

    /// Path length `(p_T − p0)·d` (m).
    #[getter]
    fn path_length_m(&self) -> f64 {
        trajectory(self).path_length_m
    }

    /// Why the motion ended (the constraint that stopped it, the step cap, …).
    #[getter]
    fn termination(&self) -> String {
        trajectory(self).termination.to_string()
    }

    /// The seed configuration the motion started from (rad), shape (n,).
    #[getter]
    fn seed<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        joint_array(py, self.planner.robot(), &self.plan.seed.q)
    }

    /// Where the seed came from (`dp`, `generating`, `home`, `given`, `q_mu`, `q_jl`).
    #[getter]
    fn seed_source(&self) -> &'static str {
        self.plan.seed.source
    }

    /// The task's reachability bound (m) when `reach=True` was asked, else `None`.
    #[getter]
    fn reachable_m(&self) -> Option<f64> {
        self.bound.as_ref().map(|bound| bound.reachable_m)
    }

    /// Why the plan ends below 0.9 × the bound, when `reach=True` was asked and it does (as
    /// `emg plan` prints it and the trajectory file records it), else `None`.
    #[getter]
    fn below_bound(&self) -> Option<String> {
        self.bound
            .as_ref()
            .and_then(|bound| bound.shortfall.clone())
    }

    /// The task.
    #[getter]
    fn task(&self) -> Task {
        Task {
            inner: self.task.clone(),
            joints: self.planner.robot().dof(),
        }
    }

    /// The motion timed rest to rest: `limits` a MoveIt joint_limits.yaml (default: the one
    /// beside the robot file), `velocity_scaling` and `acceleration_scaling` in (0, 1],
    /// `tool_speed` (m/s; default: the rollout's line speed), `rate_hz` samples per second.
    #[pyo3(signature = (limits = None, velocity_scaling = 1.0, acceleration_scaling = 1.0, tool_speed = None, rate_hz = 1000.0))]
    fn timed(
        &self,
        py: Python<'_>,
        limits: Option<PathBuf>,
        velocity_scaling: f64,
        acceleration_scaling: f64,
        tool_speed: Option<f64>,
        rate_hz: f64,
    ) -> PyResult<Motion> {
        let timing = self.timing(
            limits,
            velocity_scaling,
            acceleration_scaling,
            tool_speed,
            rate_hz,
        )?;
        let constraints = &self.planner.config().rollout.constraints;
        let motion = py
            .detach(|| {
                timing.time(
                    self.planner.robot(),
                    &self.task,
                    constraints,
                    trajectory(self),
                )
            })
            .map_err(|e| PlanningError::new_err(format!("timing: {}", message(&e))))?;
        Ok(Motion { motion, timing })
    }

    /// Writes the files `emg plan --out STEM` writes, byte for byte: `STEM.json`
    /// (emg-trajectory/1), `STEM.csv` and `STEM.joint_trajectory.json` (timed as `timed` says,
    /// with the same keyword arguments as `emg plan`'s options); returns their paths. A plan
    /// refused at its start (`termination` `"invalid_start"`) has nothing to save and raises
    /// `PlanningError`, as `emg plan` writes nothing for it.
    #[pyo3(signature = (stem, limits = None, velocity_scaling = 1.0, acceleration_scaling = 1.0, tool_speed = None, rate_hz = 1000.0))]
    fn save(
        &self,
        stem: PathBuf,
        limits: Option<PathBuf>,
        velocity_scaling: f64,
        acceleration_scaling: f64,
        tool_speed: Option<f64>,
        rate_hz: f64,
    ) -> PyResult<Vec<PathBuf>> {
        if let emg_control::Termination::InvalidStart { violation } =
            &self.plan.trajectory.termination
        {
            return Err(PlanningError::new_err(format!(
                "refused, nothing to save: the start configuration breaks a constraint: \
                 {violation}"
            )));
        }
        let timing = self.timing(
            limits,
            velocity_scaling,
            acceleration_scaling,
            tool_speed,
            rate_hz,
        )?;
        let record = PlanRecord {
            robot: &self.reference,
            request: &self.request,
            bound: self.bound.as_ref(),
            timing: &timing,
        };
        let files = PlanFiles::new(&self.planner, &self.task, &self.plan, &record)
            .map_err(|e| input_error("plan", &e))?;
        let paths = PlanPaths::new(&stem, None);
        files
            .write(&paths)
            .map_err(|e| PyOSError::new_err(message(&e)))?;
        Ok(vec![paths.json, paths.csv, paths.joint_trajectory])
    }

    fn __repr__(&self) -> String {
        format!(
            "Plan(path_length_m={:.4}, steps={}, termination={:?})",
            trajectory(self).path_length_m,
            trajectory(self).steps.len(),
            trajectory(self).termination.to_string()
        )
    }
}

#[pymethods]
impl Task {
    /// Start point `p0` (m), shape (3,).
    #[getter]
    fn p0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.inner.p0.iter().copied())
    }

    /// Unit direction `d`, shape (3,).
    #[getter]
    fn d<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.inner.d.iter().copied())
    }

    /// Unit surface normal `n`, shape (3,).
    #[getter]
    fn n<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.inner.n.iter().copied())
    }

    /// The length of the task's path (m), or `None` for a line.
    #[getter]
    fn path_length_m(&self) -> Option<f64> {
        self.inner.length_m()
    }

    /// The configuration the task was generated from (rad), shape (n,), or `None`.
    #[getter]
    fn q0_seed<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.inner
            .q0_seed
            .map(|q| array1(py, q.as_slice()[..self.joints].iter().copied()))
    }

    fn __repr__(&self) -> String {
        let v = |v: &Vec3| format!("[{}, {}, {}]", v.x, v.y, v.z);
        format!(
            "Task(p0={}, d={}, n={})",
            v(&self.inner.p0),
            v(&self.inner.d),
            v(&self.inner.n)
        )
    }
}

/// The tasks of a task file (JSON or the binary `EMGTASKS` set, told apart by the content),
/// each validated for `robot` (a shipped robot's name or a robot file).
#[pyfunction]
#[pyo3(signature = (path, robot = PathBuf::from("fr3")), text_signature = "(path, robot='fr3')")]
pub fn load_tasks(path: PathBuf, robot: PathBuf) -> PyResult<Vec<Task>> {
    let robot = Robot::load(&robot)?;
    let tasks = emg_io::read_tasks(&path, &robot.inner)
        .map_err(|e| input_error(format!("task file {}", path.display()), &e))?;
    let joints = robot.inner.dof();
    Ok(tasks
        .into_iter()
        .map(|inner| Task { inner, joints })
        .collect())
}
