//! The least time a program needs at the arm's limits, summed as its parts are placed.

use emg_kinematics::JointVector;
use emg_timing::{TimingRequest, least_move_s};

/// The least time a program needs at the arm's limits, summed as its parts are placed
/// (docs/jobs.md, "Cycle time"): each stroke part at least its drawn length at the tool speed,
/// and at least the least time its joints need from its start to its end ([`least_move_s`]);
/// each pen-up move at least the least time from the configuration where the last part ended
/// (or the program starts) to where the next one starts, whatever path it takes. No program
/// that draws the same parts from the same configurations within the limits is shorter.
pub(super) struct LeastDuration<'a> {
    request: &'a TimingRequest,
    /// Where the arm is when the next pen-up move starts: the last part's end, or the home
    /// before the first (none where the program starts above its first stroke).
    pen_up_from: Option<JointVector>,
    /// The sum over stroke parts (s).
    pub(super) pen_down_s: f64,
    /// The sum over pen-up moves (s).
    pub(super) pen_up_s: f64,
}

impl<'a> LeastDuration<'a> {
    pub(super) fn new(request: &'a TimingRequest, home: Option<JointVector>) -> Self {
        Self {
            request,
            pen_up_from: home,
            pen_down_s: 0.0,
            pen_up_s: 0.0,
        }
    }

    /// Adds the stroke part from `start` to `end` drawing `drawn_m`, and the move to it (from
    /// `above_start` where it is the program's first).
    pub(super) fn add_stroke(
        &mut self,
        above_start: JointVector,
        start: JointVector,
        end: JointVector,
        drawn_m: f64,
    ) {
        let limits = &self.request.limits;
        let from = self.pen_up_from.unwrap_or(above_start);
        self.pen_up_s += least_move_s(&from, &start, limits);
        self.pen_down_s +=
            (drawn_m / self.request.tool_speed_m_per_s).max(least_move_s(&start, &end, limits));
        self.pen_up_from = Some(end);
    }

    /// Adds the move from the last part's end to `last`, the program's last configuration.
    pub(super) fn end_at(&mut self, last: Option<JointVector>) {
        if let Some((from, last)) = self.pen_up_from.zip(last) {
            self.pen_up_s += least_move_s(&from, &last, &self.request.limits);
        }
    }
}
