//! How a job is set up to plan: the planner configuration, the program's timing and the
//! [`JobPlanner`] that `emg job`, the Python module and the evaluations share.

use emg_kinematics::Robot;
use emg_planner::{
    DEFAULT_RATE_HZ, MotionTiming, PlanRequest, Planner, PlannerConfig, TimingSetupError,
};

use crate::pipeline::plan_job;
use crate::place::{PlaceError, PlaceSettings, Placement, Region, Score, place_job};
use crate::plan_error::JobPlanError;
use crate::program::JobFile;
use crate::spec::Job;
use crate::watch::Watch;

/// The planner configuration a job plans with: `emg plan`'s ([`PlannerConfig::cell`]: the work
/// plate, the corrected step) at `tolerance_m`.
pub fn job_config(tolerance_m: f64) -> PlannerConfig {
    let mut config = PlannerConfig::cell();
    config.rollout.constraints.line_tolerance_m = tolerance_m;
    config
}

/// The timing of a job's program for `robot` read from `robot_file`, as `emg job` times it:
/// the limits file beside the robot file (else assumed ones), unscaled, the tool at the
/// configuration's speed, sampled at [`DEFAULT_RATE_HZ`].
pub fn job_timing(
    robot: &Robot,
    robot_file: &std::path::Path,
    config: &PlannerConfig,
) -> Result<MotionTiming, TimingSetupError> {
    MotionTiming::for_robot_file(
        robot,
        robot_file,
        None,
        emg_timing::Scaling::default(),
        config.rollout.speed_m_per_s,
        DEFAULT_RATE_HZ,
        &config.rollout.constraints,
    )
}

/// Everything a job plans with, set up once for every front end (`emg job` and `emg place`,
/// the Python module, the evaluations): the planner at the job's tolerance, cone and scene,
/// the program's timing ([`job_timing`]), the search with the planner's strongest controller,
/// and the robot file as programs name it.
///
/// ```no_run
/// use emg_job::{JOB_TOLERANCE_M, Job, JobPlanner, Unwatched, job_config};
/// use emg_kinematics::Robot;
/// use emg_planner::{Models, Planner};
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let robot_file = std::path::Path::new("data/robots/fr3_pen.urdf");
/// let robot = Robot::from_chain_file(robot_file)?;
/// let text = std::fs::read_to_string("examples/seams.json")?;
/// let job = Job::from_json("examples/seams.json", &text, &robot)?;
/// let models = Models::shipped(&robot, "data".as_ref())?;
/// let planner = Planner::new(robot, models, job_config(JOB_TOLERANCE_M))?;
/// let program = JobPlanner::new(planner, robot_file, "fr3")?.plan(&job, &Unwatched)?;
/// println!("{:.3} m of {:.3} m drawn", program.summary.drawn_m, program.summary.total_m);
/// # Ok(())
/// # }
/// ```
pub struct JobPlanner {
    planner: Planner,
    timing: MotionTiming,
    request: PlanRequest,
    robot_file: String,
}

impl JobPlanner {
    /// Plans with `planner` (its configuration the job's: [`job_config`] with the cone and
    /// scene the user gave), timed from the limits beside `robot_file`; programs record the
    /// robot as `recorded_as`.
    pub fn new(
        planner: Planner,
        robot_file: &std::path::Path,
        recorded_as: impl Into<String>,
    ) -> Result<Self, TimingSetupError> {
        let timing = job_timing(planner.robot(), robot_file, planner.config())?;
        let request = PlanRequest {
            controller: planner.models().best_controller(),
            ..PlanRequest::default()
        };
        Ok(Self {
            planner,
            timing,
            request,
            robot_file: recorded_as.into(),
        })
    }

    /// The planner strokes are searched with.
    pub fn planner(&self) -> &Planner {
        &self.planner
    }

    /// The arm.
    pub fn robot(&self) -> &Robot {
        self.planner.robot()
    }

    /// How programs are timed.
    pub fn timing(&self) -> &MotionTiming {
        &self.timing
    }

    /// Plans `job` ([`plan_job`]), telling `watch` its progress.
    pub fn plan(&self, job: &Job, watch: &dyn Watch) -> Result<JobFile, JobPlanError> {
        plan_job(
            &self.planner,
            &self.request,
            job,
            &self.timing,
            &self.robot_file,
            watch,
        )
    }

    /// Places `job` over `region` ([`place_job`]): `settings.positions² × rotations` places
    /// screened by `score`, the best planned; `watch` told the progress.
    pub fn place(
        &self,
        job: &Job,
        region: &Region,
        settings: &PlaceSettings,
        score: Score,
        watch: &dyn Watch,
    ) -> Result<Placement, PlaceError> {
        place_job(
            &self.planner,
            &self.request,
            job,
            &self.timing,
            &self.robot_file,
            region,
            settings,
            score,
            watch,
        )
    }
}
