//! The independent check of a job's program (`emg check` on an `emg-job/1` file): every segment
//! replayed by the checker (`emg_verify`, which shares no kinematics with the planners), each
//! from rest to rest within the joint velocity, acceleration and jerk limits; a stroke part's
//! samples on its stretch of the stroke within the tolerance and the cone, clear of the arm's
//! own links, its work plate, the part the file's `surfaces` make and the scene; a move's
//! samples clear of the arm's own links, the part and the scene.

use emg_control::{ConstraintConfig, task_bounds};
use emg_verify::{JointSamples, Joints, ReferenceModel, ReplayError, check_replay};

use crate::free_space::with_part;
use crate::program::{JobFile, SegmentKind};

/// What the check verified.
#[derive(Clone, Debug, PartialEq)]
pub struct JobCheck {
    /// Segments verified: stroke parts and moves.
    pub stroke_parts: usize,
    /// See `stroke_parts`.
    pub moves: usize,
    /// Samples verified.
    pub points: usize,
}

/// Where a job's program fails the check.
#[derive(Debug, thiserror::Error)]
pub enum JobCheckError {
    /// The file names other joints than the robot's.
    #[error("the job's joints {found:?} are not the robot's {expected:?}")]
    Joints {
        /// The file's.
        found: Vec<String>,
        /// The robot's.
        expected: Vec<String>,
    },
    /// A stroke segment carries no task.
    #[error("segment {0} is a stroke without its task")]
    NoTask(usize),
    /// A segment breaks a constraint.
    #[error("segment {segment} ({kind}, {start_s:.3} s to {end_s:.3} s): {error}")]
    Segment {
        /// Its index.
        segment: usize,
        /// What it does.
        kind: String,
        /// Its span (s).
        start_s: f64,
        /// See `start_s`.
        end_s: f64,
        /// What the checker found.
        error: ReplayError,
    },
}

/// Checks every segment of `file` with the checker `model` of its robot (joint names
/// `joint_names`).
pub fn verify_job(
    file: &JobFile,
    model: &ReferenceModel,
    joint_names: &[String],
) -> Result<JobCheck, JobCheckError> {
    if file.joint_names != joint_names {
        return Err(JobCheckError::Joints {
            found: file.joint_names.clone(),
            expected: joint_names.to_vec(),
        });
    }
    let dynamics = file.limits.dynamics();
    let on_part = with_part(&file.constraints, &file.surfaces);
    // Between strokes the tool leaves the line and turns freely: only the arm's clearances hold.
    let free = ConstraintConfig {
        line_tolerance_m: f64::INFINITY,
        theta_max_deg: 180.0,
        ..on_part.clone()
    };
    let times: Vec<f64> = file
        .points
        .iter()
        .map(|p| p.time_from_start.seconds())
        .collect();
    let mut check = JobCheck {
        stroke_parts: 0,
        moves: 0,
        points: file.points.len(),
    };
    for (index, segment) in file.segments.iter().enumerate() {
        let first = times.partition_point(|t| *t < segment.start_s - 1e-9);
        let last = times.partition_point(|t| *t <= segment.end_s + 1e-9);
        let points = &file.points[first..last];
        let samples = JointSamples {
            time_s: times[first..last].to_vec(),
            q: points.iter().map(|p| joints(&p.positions)).collect(),
            qd: Some(points.iter().map(|p| joints(&p.velocities)).collect()),
            qdd: Some(points.iter().map(|p| joints(&p.accelerations)).collect()),
        };
        let fail = |error| JobCheckError::Segment {
            segment: index,
            kind: match segment.kind {
                SegmentKind::Stroke { stroke, part } => format!("stroke {stroke} part {part}"),
                SegmentKind::Retreat => "retreat".to_string(),
                SegmentKind::Travel => "travel".to_string(),
                SegmentKind::Approach => "approach".to_string(),
            },
            start_s: segment.start_s,
            end_s: segment.end_s,
            error,
        };
        match segment.kind {
            SegmentKind::Stroke { .. } => {
                let task = segment.task.as_ref().ok_or(JobCheckError::NoTask(index))?;
                check_replay(
                    model,
                    &task.into(),
                    &task_bounds(task, &on_part),
                    &samples,
                    None,
                    Some(&dynamics),
                )
                .map_err(fail)?;
                check.stroke_parts += 1;
            }
            _ => {
                // The whole part is in `free`'s scene: one surface's task frames the replay.
                if let Some(task) = file.surfaces.first() {
                    check_replay(
                        model,
                        &task.into(),
                        &task_bounds(task, &free),
                        &samples,
                        None,
                        Some(&dynamics),
                    )
                    .map_err(fail)?;
                }
                check.moves += 1;
            }
        }
    }
    Ok(check)
}

/// A checker's joint vector from a file's values.
fn joints(values: &[f64]) -> Joints {
    let mut q = Joints::zeros();
    for (i, v) in values.iter().enumerate() {
        q[i] = *v;
    }
    q
}
