//! The connect, time and write stages: the planned strokes joined by safe moves (retreat along
//! −n, a free joint-space move, approach along n) into one timed joint trajectory, every segment
//! listed with its time span and what its samples are computed from ([`Motion`]), written as an
//! `emg-job/3` file; the samples evaluated from it ([`JobFile::points`]).

use emg_control::{ConstraintConfig, PathSpec, Task};
use emg_io::{JointTrajectoryPoint, TimeFromStart, TimingLimits};
use emg_kinematics::JointVector;
use emg_planner::MotionTiming;
use emg_timing::{MotionDefinition, TimedSample, time_free_move};
use serde::{Deserialize, Serialize};

use crate::claims::Stretch;
use crate::motion::Motion;
use crate::order::Ordering;
use crate::shortfall::Shortfall;
use crate::spec::JobSettings;

/// The format tag of a job file.
pub const JOB_FILE_FORMAT: &str = "emg-job/3";

/// The longest program a file may hold (s): its sample times fit a joint trajectory's
/// `time_from_start` (2³¹ s).
pub const MAX_PROGRAM_S: f64 = 2e9;

/// What a segment of the program does.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SegmentKind {
    /// Pen down along part `part` of stroke `stroke` (the job's index), whose task is the
    /// stroke's stretch from `from_s` on (back toward its start where `backward`).
    Stroke {
        /// The stroke's index in the job.
        stroke: usize,
        /// The part (0 unless the stroke was resumed).
        part: usize,
        /// Arc length along the stroke as drawn where the part's task starts (m).
        from_s: f64,
        /// Whether the part is drawn from `from_s` back toward the stroke's start: a stroke
        /// left short, finished from its other end. Absent (false) otherwise.
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        backward: bool,
    },
    /// The tool lifted off the surface along −n.
    Retreat,
    /// A free joint-space move between two lifted configurations (or home); a blended pen-up
    /// move (the lift, the move and the set-down in one motion) is one of these.
    Travel,
    /// The tool set down along n.
    Approach,
}

/// One segment of the program and its span.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// What it does.
    #[serde(flatten)]
    pub kind: SegmentKind,
    /// When it starts and ends (s from the program's start).
    pub start_s: f64,
    /// See `start_s`.
    pub end_s: f64,
    /// Vertices of a move's joint-space polyline (2 for a straight move; none for a stroke).
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub vertices: Vec<Vec<f64>>,
    /// A stroke part's task: the stretch of the stroke it follows.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub task: Option<Task>,
    /// What the segment's samples are computed from.
    pub motion: Motion,
}

/// What became of one stroke.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StrokeReport {
    /// Its index in the job.
    pub stroke: usize,
    /// Whether it was drawn from its end.
    pub reversed: bool,
    /// The stroke as drawn (reversed where `reversed`).
    pub path: PathSpec,
    /// Its length (m).
    pub length_m: f64,
    /// The arc length its stroke parts' samples cover (m; [`crate::claims`]).
    pub drawn_m: f64,
    /// The parts it was drawn in.
    pub parts: usize,
    /// Stretches the stroke parts' samples do not cover (arc length along the stroke as
    /// drawn), and where each starts (base frame, m).
    pub unreached: Vec<Stretch>,
    /// See `unreached`.
    pub unreached_at: Vec<[f64; 3]>,
    /// Why each of `unreached` is not drawn, found where it starts (docs/jobs.md, "Why a
    /// stroke stops short").
    pub unreached_causes: Vec<Shortfall>,
    /// Parts planned but left out, each with why: no safe move reached them or they could not
    /// be timed.
    pub parts_left_out: Vec<String>,
    /// Where the stroke's searches (`settings.max_parts`) were spent before its end (arc length
    /// along the stroke as drawn, m): what is unreached past it was not searched, not found out
    /// of reach. Absent where the searches reached the end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unsearched_from_s: Option<f64>,
}

/// The job's totals.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JobSummary {
    /// Strokes drawn whole in one part, whole in several (resumed), and not whole (short).
    pub complete: usize,
    /// See `complete`.
    pub resumed: usize,
    /// See `complete`.
    pub short: usize,
    /// Pen-down length drawn and in all (m).
    pub drawn_m: f64,
    /// See `drawn_m`.
    pub total_m: f64,
    /// Straight-line travel between strokes before and after ordering (m).
    pub travel_given_m: f64,
    /// See `travel_given_m`.
    pub travel_m: f64,
    /// Program duration, and its time pen down and pen up (s).
    pub duration_s: f64,
    /// See `duration_s`.
    pub pen_down_s: f64,
    /// See `duration_s`.
    pub pen_up_s: f64,
    /// Free moves straight in joint space, and those the sampling planner found.
    pub straight_moves: usize,
    /// See `straight_moves`.
    pub sampled_moves: usize,
    /// Searches run over all strokes, and the planning time (s) of the whole job.
    pub searches: usize,
    /// See `searches`.
    pub planning_s: f64,
    /// Whether the program ends at the job's home: false where the job has none, or where no
    /// free move back to it was found.
    pub ends_at_home: bool,
    /// The least time its stroke parts need at the arm's limits (s): each at least its drawn
    /// length at the tool speed and the least time its joints need from its start to its end
    /// (docs/jobs.md, "Cycle time").
    #[serde(default)]
    pub least_pen_down_s: f64,
    /// The least time its pen-up moves need at the arm's limits (s): each at least the least
    /// time its joints need from the configuration where one part ends to where the next
    /// starts, whatever the path.
    #[serde(default)]
    pub least_pen_up_s: f64,
}

/// A job's program as its file holds it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JobFile {
    /// [`JOB_FILE_FORMAT`].
    pub format: String,
    /// The robot file.
    pub robot: String,
    /// The arm's joints, base to tip.
    pub joint_names: Vec<String>,
    /// The constraints every stroke holds.
    pub constraints: ConstraintConfig,
    /// The joint limits every point holds.
    pub limits: TimingLimits,
    /// The job's settings.
    pub settings: JobSettings,
    /// The home configuration the program starts at and, where `summary.ends_at_home`, ends at
    /// (rad, one value per joint); none where the job has no home, and the program starts above
    /// its first stroke.
    pub home: Option<Vec<f64>>,
    /// The drawing order.
    pub ordering: Ordering,
    /// Every stroke's outcome, in drawing order.
    pub strokes: Vec<StrokeReport>,
    /// The totals.
    pub summary: JobSummary,
    /// The part the arm keeps off while drawing and moving: one task per plane of the strokes,
    /// whose work plate covers them all ([`crate::part_surfaces`]).
    pub surfaces: Vec<Task>,
    /// The samples per second of the program's motion.
    pub rate_hz: f64,
    /// The segments in time order.
    pub segments: Vec<Segment>,
}

impl JobFile {
    /// Whether `text` is a job's program of any version: JSON whose `format` starts with
    /// `emg-job/`.
    pub fn is_job(text: &str) -> bool {
        Self::format_of(text).is_some_and(|format| format.starts_with("emg-job/"))
    }

    /// `text` read as a job's program: refused where it is a program of another version than
    /// [`JOB_FILE_FORMAT`] or not a valid one, or where a segment's motion cannot be sampled
    /// ([`Self::check_motion`]).
    pub fn parse(text: &str) -> Result<Self, JobFileError> {
        let file: Self = match Self::format_of(text) {
            Some(format) if format != JOB_FILE_FORMAT => Err(JobFileError::Version(format)),
            _ => serde_json::from_str(text).map_err(JobFileError::Invalid),
        }?;
        file.check_motion()?;
        Ok(file)
    }

    /// Checks that every segment's motion can be sampled at the file's rate and that the
    /// program lasts at most [`MAX_PROGRAM_S`]; else says which segment and field cannot.
    pub fn check_motion(&self) -> Result<(), JobFileError> {
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return Err(JobFileError::Rate(self.rate_hz));
        }
        let mut duration_s = 0.0;
        for (index, segment) in self.segments.iter().enumerate() {
            let definition = self
                .definition(segment)
                .map_err(|why| JobFileError::Motion {
                    segment: index,
                    why,
                })?;
            duration_s += definition.duration_bound_s(self.rate_hz);
        }
        if duration_s > MAX_PROGRAM_S {
            return Err(JobFileError::TooLong(duration_s));
        }
        Ok(())
    }

    /// What `segment`'s samples are computed from, or why they cannot be (naming the field).
    fn definition(&self, segment: &Segment) -> Result<MotionDefinition, String> {
        segment
            .motion
            .definition(&segment.vertices, self.joint_names.len(), self.rate_hz)
    }

    /// The samples of the whole program at [`Self::rate_hz`], from rest to rest: each
    /// segment's motion sampled ([`MotionDefinition::samples`]), every segment after the first
    /// from its second sample on (its first is where the one before ends) and after the one
    /// before's last sample in time. A file [`Self::parse`] accepts or [`crate::plan_job`]
    /// writes gives the samples its motion was timed with.
    ///
    /// # Panics
    ///
    /// If a segment's motion cannot be sampled or the program lasts longer than
    /// [`MAX_PROGRAM_S`] ([`Self::check_motion`]).
    pub fn points(&self) -> Vec<JointTrajectoryPoint> {
        let dof = self.joint_names.len();
        let mut points = Vec::new();
        let mut offset_ns = 0;
        for segment in &self.segments {
            let samples = self.segment_samples(segment);
            let skip = usize::from(!points.is_empty());
            points.extend(samples.iter().skip(skip).map(|sample| {
                JointTrajectoryPoint {
                    positions: sample.q.as_slice()[..dof].to_vec(),
                    velocities: sample.qd.as_slice()[..dof].to_vec(),
                    accelerations: sample.qdd.as_slice()[..dof].to_vec(),
                    time_from_start: TimeFromStart::from_nanoseconds(sample.time_ns + offset_ns)
                        .expect("a program's duration is checked when it is read or planned"),
                }
            }));
            offset_ns += samples.last().map_or(0, |last| last.time_ns);
        }
        points
    }

    /// The samples of `segment` (one of [`Self::segments`]) at [`Self::rate_hz`], times from
    /// the segment's start.
    ///
    /// # Panics
    ///
    /// If the segment's motion cannot be sampled ([`Self::check_motion`]).
    pub fn segment_samples(&self, segment: &Segment) -> Vec<TimedSample> {
        self.definition(segment)
            .expect("a program's motion is checked when it is read or planned")
            .samples(self.rate_hz)
    }

    /// How far each joint turns over `segment`'s samples in all (rad): per joint, the sum of
    /// `|Δq|` between consecutive samples, so a joint that turns and turns back counts both.
    ///
    /// # Panics
    ///
    /// If the segment's motion cannot be sampled ([`Self::check_motion`]).
    pub fn joint_travel_rad(&self, segment: &Segment) -> Vec<f64> {
        let samples = self.segment_samples(segment);
        (0..self.joint_names.len())
            .map(|joint| {
                samples
                    .windows(2)
                    .map(|pair| (pair[1].q[joint] - pair[0].q[joint]).abs())
                    .sum()
            })
            .collect()
    }

    /// The `format` of a JSON text, if it has one.
    fn format_of(text: &str) -> Option<String> {
        #[derive(Deserialize)]
        struct Format {
            format: Option<String>,
        }
        if !text.trim_start().starts_with('{') {
            return None;
        }
        serde_json::from_str::<Format>(text).ok()?.format
    }

    /// The samples `points` (the program's: [`Self::points`]) as an export reads them
    /// ([`emg_io::export`]), with the tool's switching `tool` (its switches:
    /// [`Self::tool_switches`]).
    pub fn timed_points<'a>(
        &'a self,
        points: &'a [JointTrajectoryPoint],
        tool: emg_io::ToolSwitching<'a>,
    ) -> emg_io::TimedPoints<'a> {
        emg_io::TimedPoints {
            joint_names: &self.joint_names,
            limits: &self.limits,
            points,
            home: self.home.as_deref(),
            tool: Some(tool),
        }
    }

    /// Where the tool is switched on and off: on where each stroke part starts, off where it
    /// ends (a stroke segment is where the tool is on; `settings.tool_output` names its output).
    pub fn tool_switches(&self) -> Vec<emg_io::ToolSwitch> {
        self.segments
            .iter()
            .filter(|segment| matches!(segment.kind, SegmentKind::Stroke { .. }))
            .flat_map(|segment| {
                [
                    emg_io::ToolSwitch {
                        time_s: segment.start_s,
                        on: true,
                    },
                    emg_io::ToolSwitch {
                        time_s: segment.end_s,
                        on: false,
                    },
                ]
            })
            .collect()
    }
}

/// Why a job's program cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum JobFileError {
    /// A program of another version.
    #[error(
        "is an {0} program, which this emg does not read: plan the job again, which writes \
         {JOB_FILE_FORMAT}"
    )]
    Version(String),
    /// Not a valid program.
    #[error("is not a valid {JOB_FILE_FORMAT} file: {0}")]
    Invalid(serde_json::Error),
    /// A rate that is not a positive number.
    #[error("is not a valid {JOB_FILE_FORMAT} file: rate_hz must be positive, got {0}")]
    Rate(f64),
    /// A segment whose motion cannot be sampled.
    #[error("is not a valid {JOB_FILE_FORMAT} file: segments[{segment}].{why}")]
    Motion {
        /// The segment's index.
        segment: usize,
        /// Why, naming the field.
        why: String,
    },
    /// A program too long for a joint trajectory's times.
    #[error(
        "is not a valid {JOB_FILE_FORMAT} file: its motion lasts {0:.0} s, more than \
         {MAX_PROGRAM_S:.0} s"
    )]
    TooLong(f64),
}

/// The program being assembled: its segments on one time line.
#[derive(Default)]
pub struct Program {
    segments: Vec<Segment>,
    /// The last sample so far, on the program's time line.
    last: Option<TimedSample>,
}

impl Program {
    /// The configuration the program ends at, if it has begun.
    pub fn last(&self) -> Option<JointVector> {
        self.last.map(|sample| sample.q)
    }

    /// Appends the rest-to-rest motion `definition` from the program's last configuration (its
    /// samples `samples`, times from 0) as a segment of `kind` (a stroke part with its `task`);
    /// a move's vertices are its definition's.
    pub fn append(
        &mut self,
        kind: SegmentKind,
        definition: &MotionDefinition,
        samples: &[TimedSample],
        task: Option<&Task>,
        dof: usize,
    ) {
        let offset_ns = self.last.map_or(0, |last| last.time_ns);
        let end = samples.last().map(|last| TimedSample {
            time_ns: last.time_ns + offset_ns,
            ..*last
        });
        self.last = end.or(self.last);
        let vertices = match definition {
            MotionDefinition::Splines { .. } => &[][..],
            MotionDefinition::Polyline { vertices, .. }
            | MotionDefinition::Blended { vertices, .. } => vertices,
        };
        self.segments.push(Segment {
            kind,
            start_s: offset_ns as f64 * 1e-9,
            end_s: self.last.map_or(0.0, |last| last.time_s()),
            vertices: vertices
                .iter()
                .map(|q| q.as_slice()[..dof].to_vec())
                .collect(),
            task: task.cloned(),
            motion: Motion::of(definition, dof),
        });
    }

    /// A free move through `vertices` timed rest to rest (a segment of `kind`).
    pub fn append_move(
        &mut self,
        kind: SegmentKind,
        vertices: &[JointVector],
        timing: &MotionTiming,
        dof: usize,
    ) {
        let timed = time_free_move(vertices, timing.request());
        self.append(kind, &timed.definition, &timed.samples, None, dof);
    }

    /// The segments so far.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The program's end (s).
    pub fn duration_s(&self) -> f64 {
        self.last.map_or(0.0, |last| last.time_s())
    }
}
