//! Where a rollout starts: the seed sources, and putting a seed exactly on the task's start
//! pose.

use std::str::FromStr;

use emg_control::{ConstraintConfig, SEED_POSITION_TOLERANCE_M, Task, tool_angle_deg};
use emg_diffusion::{DpSeedError, DpSeeder, SeedOrigin, SeedWorkspace};
use emg_kinematics::{
    JointVector, MAX_DOF, PoseTarget, ProjectionConfig, ProjectionError, Robot, project_to_pose,
};
use emg_seeding::{HeuristicConfig, HeuristicObjective, heuristic_seed};

use crate::parse::ParseError;

/// Where the rollout's start configuration comes from (Table 2's rows, plus the CLI's own).
#[derive(Clone, Debug, PartialEq)]
pub enum SeedSource {
    /// The DP seed: diffusion candidates projected onto the start pose, first valid, else
    /// `q0_seed` (Sec. 4.1).
    Dp,
    /// The task's generating configuration `q0_seed`.
    Generating,
    /// The mid-range configuration of the joint limits.
    Home,
    /// A configuration given by the caller (rad), one value per joint of the arm (checked when
    /// the seed is prepared for a robot).
    Given(Vec<f64>),
    /// Directional-manipulability ascent from `q0_seed` (`q_μ`, Sec. 5.1.3).
    QMu,
    /// Joint-centring ascent from `q0_seed` (`q_jl`, Sec. 5.1.3).
    QJl,
}

impl SeedSource {
    /// Name in files and on command lines (`dp`, `generating`, `home`, `given`, `q_mu`,
    /// `q_jl`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Dp => "dp",
            Self::Generating => "generating",
            Self::Home => "home",
            Self::Given(_) => "given",
            Self::QMu => "q_mu",
            Self::QJl => "q_jl",
        }
    }

    /// Name in the paper's tables (`DP`, `q0_seed`, `q_μ`, `q_jl`, `home`, `given`).
    pub fn title(&self) -> &'static str {
        match self {
            Self::Dp => "DP",
            Self::Generating => "q0_seed",
            Self::QMu => "q_μ",
            Self::QJl => "q_jl",
            Self::Home => "home",
            Self::Given(_) => "given",
        }
    }
}

impl FromStr for SeedSource {
    type Err = ParseError;

    /// `dp`, `generating`, `home`, `q_mu`, `q_jl` or `q=v1,...,vN` (radians, one per joint).
    fn from_str(s: &str) -> Result<Self, ParseError> {
        match s {
            "dp" => Ok(Self::Dp),
            "generating" => Ok(Self::Generating),
            "home" => Ok(Self::Home),
            "q_mu" => Ok(Self::QMu),
            "q_jl" => Ok(Self::QJl),
            _ => match s.strip_prefix("q=") {
                Some(values) => Ok(Self::Given(crate::parse::number_list(values, MAX_DOF)?)),
                None => Err(ParseError::Seed(s.to_string())),
            },
        }
    }
}

/// The source of a search's start taken from the reachability scan's configuration at `p0`
/// when the requested seed cannot be put on the start pose.
pub const SCAN_SOURCE: &str = "scan";

/// The source name of a start the long-horizon stage found: the first configuration of a chain
/// of the reachability scan.
pub const CHAIN_SOURCE: &str = "scan-chain";

/// The source name of a start the far-end stage found: where a motion planned back from far
/// along the line reaches `p0`.
pub const FAR_END_SOURCE: &str = "far-end";

/// What a seed's source (its name in output and files) means: the sources of
/// [`SeedSource::name`] and the search's own starts (`ik`, [`CHAIN_SOURCE`],
/// [`FAR_END_SOURCE`], [`SCAN_SOURCE`]).
pub fn seed_source_meaning(name: &str) -> &'static str {
    match name {
        "dp" => "the diffusion seeder's start",
        "generating" => "the configuration the task was generated from",
        "home" => "the mid-range configuration, projected onto the start pose",
        "given" => "the configuration given",
        "q_mu" => "a manipulability ascent from the generating configuration",
        "q_jl" => "a joint-centring ascent from the generating configuration",
        "ik" => "a start the search found by inverse kinematics at p0 within the cone",
        CHAIN_SOURCE => {
            "the reachability scan's chain of configurations from p0, followed by the search"
        }
        FAR_END_SOURCE => {
            "where a motion the search planned back from far along the line reaches p0, \
             followed forwards"
        }
        SCAN_SOURCE => {
            "the reachability scan's configuration at p0 (the requested seed could not be put \
             on the start pose)"
        }
        _ => "a start of the search",
    }
}

/// A seed ready for the rollout.
#[derive(Clone, Debug, PartialEq)]
pub struct Seed {
    /// The configuration the rollout starts from.
    pub q: JointVector,
    /// Where it came from (`dp`, `generating`, `home`, `given`, `q_mu`, `q_jl`, or a search's
    /// own start: [`seed_source_meaning`]); a DP or heuristic seed that fell back to `q0_seed`
    /// reports `generating`.
    pub source: &'static str,
    /// Newton iterations spent projecting it onto `(p0, n)`; `None` when it was already there.
    pub projection_iterations: Option<usize>,
}

/// Why no seed could be prepared.
#[derive(Debug, thiserror::Error)]
pub enum SeedError {
    /// `dp` was requested but no diffusion seeder is loaded.
    #[error("seed 'dp' needs the diffusion seeder's weights, and none are loaded")]
    NoSeeder,
    /// The diffusion seeder failed.
    #[error("seed 'dp'")]
    Dp(#[from] DpSeedError),
    /// The source needs the task's `q0_seed`, which it does not have.
    #[error(
        "seed '{0}' needs the task's generating configuration (q0_seed), which this task does \
         not have; use seed home or q=v1,...,vN (one value per joint)"
    )]
    NoGeneratingConfiguration(&'static str),
    /// A given seed whose number of values is not the arm's number of joints.
    #[error(
        "seed q= gives {given} joint values, and the arm has {joints} joints: give one per joint"
    )]
    GivenJoints {
        /// Values given.
        given: usize,
        /// The arm's joints.
        joints: usize,
    },
    /// The seed cannot be put on the start pose.
    #[error("cannot project the {source_name} seed onto the task's start pose (p0, n)")]
    Projection {
        /// The seed's source.
        source_name: &'static str,
        /// Why the projection failed.
        #[source]
        source: ProjectionError,
    },
}

/// Picks the seed named by `request` (`None`: `dp` when `seeder` is loaded, else `generating`
/// when the task has a `q0_seed`, else `home`) and, unless it already puts the TCP at `p0` with
/// the tool axis within the cone and every joint within its limits, Newton-projects it onto the
/// exact pose `(p0, n)`. The DP seed falls back to `q0_seed` (reported as `generating`); by
/// default, a task whose DP candidates all fail and that has no `q0_seed` starts from `home`.
pub fn prepare_seed(
    robot: &Robot,
    task: &Task,
    request: Option<&SeedSource>,
    constraints: &ConstraintConfig,
    seeder: Option<&DpSeeder>,
) -> Result<Seed, SeedError> {
    let wants_dp =
        matches!(request, Some(SeedSource::Dp)) || (request.is_none() && seeder.is_some());
    if wants_dp {
        let seeder = seeder.ok_or(SeedError::NoSeeder)?;
        match seeder.seed(robot, task, constraints, &mut SeedWorkspace::default()) {
            Ok(seed) => {
                let source = match seed.origin {
                    SeedOrigin::Diffusion => "dp",
                    SeedOrigin::Fallback => "generating",
                };
                return Ok(Seed {
                    q: seed.q,
                    source,
                    projection_iterations: None,
                });
            }
            Err(DpSeedError::NoValidSeed { .. }) if request.is_none() => {}
            Err(error) => return Err(error.into()),
        }
    }
    let generating = |name| {
        task.q0_seed
            .ok_or(SeedError::NoGeneratingConfiguration(name))
    };
    let (q, source) = match request {
        Some(SeedSource::Dp) => unreachable!("handled above"),
        Some(SeedSource::Generating) => (generating("generating")?, "generating"),
        Some(SeedSource::Home) => (robot.mid_range(), "home"),
        Some(SeedSource::Given(values)) if values.len() != robot.dof() => {
            return Err(SeedError::GivenJoints {
                given: values.len(),
                joints: robot.dof(),
            });
        }
        Some(SeedSource::Given(values)) => (robot.joint_vector(values), "given"),
        Some(source @ (SeedSource::QMu | SeedSource::QJl)) => {
            let q0 = generating(source.name())?;
            let objective = if *source == SeedSource::QMu {
                HeuristicObjective::Manipulability
            } else {
                HeuristicObjective::JointCentring
            };
            match heuristic_seed(
                robot,
                task,
                objective,
                &HeuristicConfig::default(),
                &ProjectionConfig::default(),
            ) {
                Ok(seed) => (seed.q, source.name()),
                Err(_) => (q0, "generating"),
            }
        }
        None => match task.q0_seed {
            Some(q) => (q, "generating"),
            None => (robot.mid_range(), "home"),
        },
    };
    if on_start_pose(robot, task, &q, constraints.theta_max_deg) {
        return Ok(Seed {
            q,
            source,
            projection_iterations: None,
        });
    }
    let target = PoseTarget {
        position: task.p0,
        tool_axis: task.n,
        roll_axis: None,
    };
    let (q, iterations) = project_to_pose(robot, &q, &target, &ProjectionConfig::default())
        .map_err(|source_error| SeedError::Projection {
            source_name: source,
            source: source_error,
        })?;
    Ok(Seed {
        q,
        source,
        projection_iterations: Some(iterations),
    })
}

/// Whether `q` is within the joint limits, puts the TCP at `p0` and the tool axis in the cone.
fn on_start_pose(robot: &Robot, task: &Task, q: &JointVector, theta_max_deg: f64) -> bool {
    let kinematics = robot.forward(q);
    robot.limits().first_violation(q, 0.0).is_none()
        && (kinematics.tcp() - task.p0).norm() <= SEED_POSITION_TOLERANCE_M
        && tool_angle_deg(&kinematics.tool_axis(), &task.n) <= theta_max_deg
}
