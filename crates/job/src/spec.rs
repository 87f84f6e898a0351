//! The read stage: a job file (`emg-job` input, version 1), a path file (a job of one stroke) or
//! a drawing's strokes, validated into a [`Job`].

use crate::setting::InvalidSetting;
use crate::tool_output::ToolOutput;
use emg_control::{Path, PathError, PathSpec};
pub use emg_kinematics::Transform;
use emg_kinematics::{JointVector, Robot};
use nalgebra::Isometry3;
use serde::{Deserialize, Serialize};

/// The job file version this build reads.
pub const JOB_FORMAT_VERSION: u32 = 1;

/// A job file: strokes, shared settings, an optional home configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JobSpec {
    /// [`JOB_FORMAT_VERSION`].
    pub version: u32,
    /// The strokes, each a path as in a path file (docs/paths.md).
    pub strokes: Vec<PathSpec>,
    /// Settings shared by every stroke and move.
    #[serde(default)]
    pub settings: JobSettings,
    /// Where the arm starts and ends, one value per joint (rad); without it the job starts
    /// above its first stroke and ends above its last.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub home: Option<Vec<f64>>,
    /// A rigid motion applied to every stroke (the place `emg place --export` writes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<Transform>,
}

/// The order the strokes are drawn in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Order {
    /// As listed, each in its own direction.
    Given,
    /// The order and directions that shorten the pen-up travel (nearest neighbour, then 2-opt
    /// with reversals).
    #[default]
    Shortest,
}

/// The tool a job draws, seals or welds with: what it needs between strokes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Tool {
    /// A pen: lifts [`Tool::PEN_LIFT_M`] off the paper between strokes.
    #[default]
    Pen,
    /// A dispensing or sealing nozzle: lifts [`Tool::DISPENSER_LIFT_M`], clear of its bead.
    Dispenser,
    /// A welding torch: lifts [`Tool::TORCH_LIFT_M`], clear of the seam's edges and spatter.
    Torch,
}

impl Tool {
    /// A pen's lift between strokes (m): enough that the tip leaves no mark.
    pub const PEN_LIFT_M: f64 = 0.002;
    /// A dispenser's lift between strokes (m).
    pub const DISPENSER_LIFT_M: f64 = 0.01;
    /// A torch's lift between strokes (m).
    pub const TORCH_LIFT_M: f64 = 0.03;

    /// How far the tool lifts off the surface between strokes unless the job says (m).
    pub fn lift_m(self) -> f64 {
        match self {
            Self::Pen => Self::PEN_LIFT_M,
            Self::Dispenser => Self::DISPENSER_LIFT_M,
            Self::Torch => Self::TORCH_LIFT_M,
        }
    }
}

/// Settings shared by every stroke and move of a job.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct JobSettings {
    /// The tool, whose lift between strokes is the default of `lift_m`.
    pub tool: Tool,
    /// How far the tool lifts off the surface (along −n) between strokes (m); unset, the
    /// tool's ([`Tool::lift_m`]). A program's settings have it set.
    pub lift_m: Option<f64>,
    /// The order of the strokes.
    pub order: Order,
    /// Where a stroke is resumed after a reconfiguration, the tool sets down this far back
    /// along it (m).
    pub overlap_m: f64,
    /// A stroke is resumed while a part gains at least this much (m); where a part gains
    /// less, the stretch is skipped by this much, doubled for each search in a row before it
    /// that gained nothing, and reported out of reach.
    pub min_gain_m: f64,
    /// Parts stopping short of the stroke's end a stroke is planned with at most; a part that
    /// stopped only at the rollout's step cap (the arm still able to go on) is not counted,
    /// nor a search that gained nothing (it skips ahead, `min_gain_m`).
    pub max_parts: usize,
    /// Seed of the sampling planner of the free moves.
    pub seed: u64,
    /// Samples the sampling planner draws at most per move.
    pub rrt_max_samples: usize,
    /// The output that switches the tool on along each stroke.
    pub tool_output: ToolOutput,
    /// How far (m) the strokes' corners were rounded from the drawing's, out of the line
    /// tolerance (docs/jobs.md, "Corner rounding"): the strokes are followed within the line
    /// tolerance less it, so that the pen stays within the line tolerance of the drawing; 0
    /// (the default) for strokes taken as they are.
    pub corner_tolerance_m: f64,
}

impl Default for JobSettings {
    fn default() -> Self {
        Self {
            tool: Tool::Pen,
            lift_m: None,
            order: Order::Shortest,
            overlap_m: 0.002,
            min_gain_m: 0.005,
            max_parts: 6,
            seed: 20_261_127,
            rrt_max_samples: 4000,
            tool_output: ToolOutput::default(),
            corner_tolerance_m: 0.0,
        }
    }
}

/// A validated job.
#[derive(Clone, Debug)]
pub struct Job {
    /// The strokes, in the file's order.
    pub strokes: Vec<Path>,
    /// The settings.
    pub settings: JobSettings,
    /// The home configuration, if given.
    pub home: Option<JointVector>,
}

/// Why a job cannot be planned; each names the field.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// The text is not a job file.
    #[error("{origin}: not a job file: {message}")]
    Parse {
        /// The file.
        origin: String,
        /// The parser's message.
        message: String,
    },
    /// Another version.
    #[error("job field 'version' is {found}; this build reads version {JOB_FORMAT_VERSION}")]
    Version {
        /// The version found.
        found: u32,
    },
    /// Nothing to draw.
    #[error("job field 'strokes' is empty: a job needs at least one stroke")]
    NoStrokes,
    /// A stroke is not a valid path.
    #[error("job field 'strokes[{index}]': {source}")]
    Stroke {
        /// Its index.
        index: usize,
        /// What is wrong.
        source: PathError,
    },
    /// A setting is out of range.
    #[error(transparent)]
    Setting(#[from] InvalidSetting),
    /// The home configuration does not fit the arm.
    #[error("job field 'home': {0}")]
    Home(String),
    /// A drawing's corner tolerance does not fit within its line tolerance.
    #[error(
        "the corner tolerance is {} mm; it must be at least 0 and less than the line tolerance, {} mm",
        corner_m * 1e3,
        line_m * 1e3
    )]
    CornerTolerance {
        /// The corner tolerance asked for (m).
        corner_m: f64,
        /// The line tolerance (m).
        line_m: f64,
    },
}

impl JobSettings {
    /// How far the tool lifts off the surface between strokes (m): `lift_m`, else the tool's.
    pub fn lift(&self) -> f64 {
        self.lift_m.unwrap_or(self.tool.lift_m())
    }

    /// The settings with the lift set: the tool's where `lift_m` is unset (as a program
    /// records them).
    pub fn resolved(self) -> Self {
        Self {
            lift_m: Some(self.lift()),
            ..self
        }
    }

    /// Checks every setting.
    pub fn validate(&self) -> Result<(), JobError> {
        let require = |field, value: f64, allowed, ok: bool| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(JobError::Setting(InvalidSetting {
                    field,
                    value,
                    allowed,
                }))
            }
        };
        let lift = self.lift();
        require("lift_m", lift, "in (0, 0.5] m", lift > 0.0 && lift <= 0.5)?;
        require(
            "overlap_m",
            self.overlap_m,
            "in [0, 0.05] m",
            (0.0..=0.05).contains(&self.overlap_m),
        )?;
        require(
            "min_gain_m",
            self.min_gain_m,
            "in (0, 0.5] m",
            self.min_gain_m > 0.0 && self.min_gain_m <= 0.5,
        )?;
        require(
            "max_parts",
            self.max_parts as f64,
            "in [1, 100]",
            (1..=100).contains(&self.max_parts),
        )?;
        require(
            "corner_tolerance_m",
            self.corner_tolerance_m,
            "0 or more (m)",
            self.corner_tolerance_m >= 0.0,
        )?;
        require(
            "rrt_max_samples",
            self.rrt_max_samples as f64,
            "in [1, 1000000]",
            (1..=1_000_000).contains(&self.rrt_max_samples),
        )?;
        Ok(self.tool_output.validate()?)
    }
}

impl Job {
    /// The job of `spec` for `robot`: every stroke a valid path, the settings in range, the
    /// home within the joint limits.
    pub fn from_spec(spec: JobSpec, robot: &Robot) -> Result<Self, JobError> {
        if spec.version != JOB_FORMAT_VERSION {
            return Err(JobError::Version {
                found: spec.version,
            });
        }
        if spec.strokes.is_empty() {
            return Err(JobError::NoStrokes);
        }
        spec.settings.validate()?;
        let motion = spec.transform.map(|t| t.isometry());
        let strokes = spec
            .strokes
            .into_iter()
            .enumerate()
            .map(|(index, stroke)| {
                let stroke = match &motion {
                    Some(motion) => stroke.moved(motion),
                    None => stroke,
                };
                Path::new(stroke).map_err(|source| JobError::Stroke { index, source })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let home = spec.home.map(|values| home(robot, &values)).transpose()?;
        Ok(Self {
            strokes,
            settings: spec.settings,
            home,
        })
    }

    /// The job of `strokes` (a drawing's) with the default settings and no home.
    pub fn from_strokes(strokes: Vec<PathSpec>, robot: &Robot) -> Result<Self, JobError> {
        Self::from_spec(
            JobSpec {
                version: JOB_FORMAT_VERSION,
                strokes,
                settings: JobSettings::default(),
                home: None,
                transform: None,
            },
            robot,
        )
    }

    /// The job with its home at `values` (rad, one per joint, within the limits).
    pub fn with_home(self, values: &[f64], robot: &Robot) -> Result<Self, JobError> {
        Ok(Self {
            home: Some(home(robot, values)?),
            ..self
        })
    }

    /// The job with the home its program starts and ends at, as every front end sets it:
    /// `given` where given, else the job's own, else `default` (a shipped arm's); the job as it
    /// is where none is.
    pub fn homed(
        self,
        given: Option<&[f64]>,
        default: Option<&[f64]>,
        robot: &Robot,
    ) -> Result<Self, JobError> {
        match (given, default) {
            (Some(values), _) => self.with_home(values, robot),
            (None, Some(values)) if self.home.is_none() => self.with_home(values, robot),
            _ => Ok(self),
        }
    }

    /// The job with every stroke moved rigidly by `motion`.
    pub fn moved(&self, motion: &Isometry3<f64>) -> Result<Self, JobError> {
        let strokes = self
            .strokes
            .iter()
            .enumerate()
            .map(|(index, stroke)| {
                Path::new(stroke.spec().moved(motion))
                    .map_err(|source| JobError::Stroke { index, source })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            strokes,
            ..self.clone()
        })
    }

    /// Reads a job file's text, or a path file's (docs/paths.md: a job of one stroke, with the
    /// default settings); `origin` names it in errors.
    pub fn from_json(origin: &str, text: &str, robot: &Robot) -> Result<Self, JobError> {
        let parse_error = |what: &str, e: serde_json::Error| JobError::Parse {
            origin: origin.to_string(),
            message: format!("{what}{e}"),
        };
        if is_path_file(text) {
            let stroke: PathSpec = serde_json::from_str(text)
                .map_err(|e| parse_error("read as a path file (docs/paths.md): ", e))?;
            return Self::from_strokes(vec![stroke], robot);
        }
        let spec: JobSpec = serde_json::from_str(text).map_err(|e| parse_error("", e))?;
        Self::from_spec(spec, robot)
    }
}

/// Whether `text` is a path file: a JSON object with `segments` and no `strokes`.
fn is_path_file(text: &str) -> bool {
    /// The members that tell a path file from a job file.
    #[derive(Deserialize)]
    struct Members {
        strokes: Option<serde::de::IgnoredAny>,
        segments: Option<serde::de::IgnoredAny>,
    }
    serde_json::from_str::<Members>(text)
        .is_ok_and(|members| members.segments.is_some() && members.strokes.is_none())
}

/// The home configuration of `values`: one finite value per joint, within the limits.
fn home(robot: &Robot, values: &[f64]) -> Result<JointVector, JobError> {
    if values.len() != robot.dof() {
        return Err(JobError::Home(format!(
            "has {} values; {} has {} joints",
            values.len(),
            robot.name(),
            robot.dof()
        )));
    }
    if values.iter().any(|v| !v.is_finite()) {
        return Err(JobError::Home(format!("{values:?} is not finite")));
    }
    let q = robot.joint_vector(values);
    if let Some(joint) = robot.limits().first_violation(&q, 0.0) {
        return Err(JobError::Home(format!(
            "joint {} ({} rad) is outside its limits",
            joint + 1,
            values[joint]
        )));
    }
    Ok(q)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fr3() -> Robot {
        let file =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
        Robot::from_chain_file(&file).unwrap()
    }

    #[test]
    fn a_path_file_is_a_job_of_one_stroke() {
        let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
        let text = std::fs::read_to_string(examples.join("slot.json")).unwrap();
        let job = Job::from_json("slot.json", &text, &fr3()).unwrap();
        let spec: PathSpec = serde_json::from_str(&text).unwrap();
        assert_eq!(job.strokes.len(), 1);
        assert_eq!(job.strokes[0].spec(), &spec);
        assert_eq!(job.settings, JobSettings::default());
        // A path file's own errors name it as such.
        let broken = text.replacen("\"segments\"", "\"segments\": 3, \"x\"", 1);
        let error = Job::from_json("slot.json", &broken, &fr3()).unwrap_err();
        assert!(error.to_string().contains("path file"), "{error}");
        // A job file is still read as one.
        let seams = std::fs::read_to_string(examples.join("seams.json")).unwrap();
        assert!(
            Job::from_json("seams.json", &seams, &fr3())
                .unwrap()
                .strokes
                .len()
                > 1
        );
    }
}
