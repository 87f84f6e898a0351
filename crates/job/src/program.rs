//! The connect, time and write stages: the planned strokes joined by safe moves (retreat along
//! −n, a free joint-space move, approach along n) into one timed joint trajectory, every segment
//! listed with its time span, written as an `emg-job/2` file.

use emg_control::{ConstraintConfig, PathSpec, Task};
use emg_io::{JointTrajectoryPoint, TimeFromStart, TimingLimits};
use emg_kinematics::JointVector;
use emg_planner::MotionTiming;
use emg_timing::{TimedSample, time_free_move};
use serde::{Deserialize, Serialize};

use crate::claims::Stretch;
use crate::order::Ordering;
use crate::spec::JobSettings;

/// The format tag of a job file.
pub const JOB_FILE_FORMAT: &str = "emg-job/2";

/// What a segment of the program does.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SegmentKind {
    /// Pen down along part `part` of stroke `stroke` (the job's index), whose task is the
    /// stroke's stretch from `from_s` on.
    Stroke {
        /// The stroke's index in the job.
        stroke: usize,
        /// The part (0 unless the stroke was resumed).
        part: usize,
        /// Arc length along the stroke as drawn where the part's task starts (m).
        from_s: f64,
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
    /// Parts planned but left out, each with why: no safe move reached them or they could not
    /// be timed.
    pub parts_left_out: Vec<String>,
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
    /// The segments in time order.
    pub segments: Vec<Segment>,
    /// The samples of the whole program, from rest to rest.
    pub points: Vec<JointTrajectoryPoint>,
}

impl JobFile {
    /// Whether `text` is a job's program of any version: JSON whose `format` starts with
    /// `emg-job/`.
    pub fn is_job(text: &str) -> bool {
        Self::format_of(text).is_some_and(|format| format.starts_with("emg-job/"))
    }

    /// `text` read as a job's program: refused where it is a program of another version than
    /// [`JOB_FILE_FORMAT`] (an `emg-job/2` program's claims cannot be checked) or not a valid
    /// one.
    pub fn parse(text: &str) -> Result<Self, JobFileError> {
        match Self::format_of(text) {
            Some(format) if format != JOB_FILE_FORMAT => Err(JobFileError::Version(format)),
            _ => serde_json::from_str(text).map_err(JobFileError::Invalid),
        }
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

    /// The samples as an export reads them ([`emg_io::export`]).
    pub fn timed_points(&self) -> emg_io::TimedPoints<'_> {
        emg_io::TimedPoints {
            joint_names: &self.joint_names,
            limits: &self.limits,
            points: &self.points,
            home: self.home.as_deref(),
        }
    }
}

/// Why a job's program cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum JobFileError {
    /// A program of another version.
    #[error(
        "is an {0} program, which this emg does not read (its claims cannot be checked): plan \
         the job again, which writes {JOB_FILE_FORMAT}"
    )]
    Version(String),
    /// Not a valid program.
    #[error("is not a valid {JOB_FILE_FORMAT} file: {0}")]
    Invalid(serde_json::Error),
}

/// The program being assembled: samples on one time line and the segments they make.
#[derive(Default)]
pub struct Program {
    samples: Vec<TimedSample>,
    segments: Vec<Segment>,
}

impl Program {
    /// The configuration the program ends at, if it has begun.
    pub fn last(&self) -> Option<JointVector> {
        self.samples.last().map(|sample| sample.q)
    }

    /// Appends `samples` (a rest-to-rest motion from the program's last configuration, its times
    /// from 0) as a segment of `kind` (a stroke part with its `task`).
    pub fn append(
        &mut self,
        kind: SegmentKind,
        samples: &[TimedSample],
        vertices: &[JointVector],
        task: Option<&Task>,
        dof: usize,
    ) {
        let offset_ns = self.samples.last().map_or(0, |last| last.time_ns);
        let skip = usize::from(!self.samples.is_empty());
        let start_s = offset_ns as f64 * 1e-9;
        self.samples
            .extend(samples.iter().skip(skip).map(|sample| TimedSample {
                time_ns: sample.time_ns + offset_ns,
                ..*sample
            }));
        let end_s = self
            .samples
            .last()
            .map_or(0.0, |last| last.time_ns as f64 * 1e-9);
        self.segments.push(Segment {
            kind,
            start_s,
            end_s,
            vertices: vertices
                .iter()
                .map(|q| q.as_slice()[..dof].to_vec())
                .collect(),
            task: task.cloned(),
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
        let samples = time_free_move(vertices, timing.request());
        self.append(kind, &samples, vertices, None, dof);
    }

    /// The segments so far.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The samples as joint trajectory points (the arm's `dof` joints); `None` where a time is
    /// past what the format holds.
    pub fn points(&self, dof: usize) -> Option<Vec<JointTrajectoryPoint>> {
        self.samples
            .iter()
            .map(|sample| {
                Some(JointTrajectoryPoint {
                    positions: sample.q.as_slice()[..dof].to_vec(),
                    velocities: sample.qd.as_slice()[..dof].to_vec(),
                    accelerations: sample.qdd.as_slice()[..dof].to_vec(),
                    time_from_start: TimeFromStart::from_nanoseconds(sample.time_ns)?,
                })
            })
            .collect()
    }

    /// The samples.
    pub fn samples(&self) -> &[TimedSample] {
        &self.samples
    }
}
