//! Timed joint positions as a trajectory file holds them.

use crate::model::{ReferenceModel, angle_deg};
use crate::record::{Ending, Joints, Line, RecordedStep, Recording};

/// Timed joint positions read from a trajectory file, with the velocities it declares.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSamples {
    /// Time of each point since the start (s).
    pub time_s: Vec<f64>,
    /// Joint positions of each point (rad).
    pub q: Vec<Joints>,
    /// Velocities the file declares at each point (rad/s), if it declares any.
    pub qd: Option<Vec<Joints>>,
    /// Accelerations the file declares at each point (rad/s²), if it declares any.
    pub qdd: Option<Vec<Joints>>,
}

impl JointSamples {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.q.len()
    }

    /// Whether there is no point at all.
    pub fn is_empty(&self) -> bool {
        self.q.is_empty()
    }

    /// The points as a [`Recording`] of `line`: TCP and tool angle from the checker's own
    /// forward kinematics, the path length from the last point's TCP (along a path, followed
    /// point by point), and [`Ending::Stopped`].
    ///
    /// A file of points says nothing about why the motion ended, so the check of such a
    /// recording verifies every point but no reason for the end. Since the TCP and tool angles
    /// are recomputed here, the check compares them with themselves; what it verifies are the
    /// constraints at each point.
    pub fn to_recording(&self, model: &ReferenceModel, line: &Line) -> Recording {
        let steps: Vec<RecordedStep> = self
            .time_s
            .iter()
            .zip(&self.q)
            .map(|(time_s, q)| {
                let (tcp, axis) = model.tcp_pose(q);
                RecordedStep {
                    time_s: *time_s,
                    q: *q,
                    tcp,
                    tool_angle_deg: angle_deg(&axis, &line.n),
                }
            })
            .collect();
        let path_length_m = line.reached(steps.iter().map(|step| step.tcp));
        Recording {
            steps,
            ending: Ending::Stopped,
            path_length_m,
        }
    }
}
