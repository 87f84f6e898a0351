//! The plan-strokes stage: each stroke planned by the search to the limit; where the arm cannot
//! finish it in one motion, the rest is planned again from where it stopped (the tool set down
//! a little behind, after a reconfiguration in free space), as often as that gains length.

use emg_control::{ARRIVAL_M, Path, Task, Termination, Trajectory};
use emg_planner::{PlanRequest, Planner};
use serde::{Deserialize, Serialize};

use crate::spec::JobSettings;

/// One motion along a stretch of a stroke.
#[derive(Clone, Debug)]
pub struct StrokePart {
    /// Arc length of the stroke where the part's stretch starts (m).
    pub from_s: f64,
    /// The task of the stretch, as planned.
    pub task: Task,
    /// The planned motion along it.
    pub trajectory: Trajectory,
}

impl StrokePart {
    /// Arc length of the stroke the part reaches (m).
    pub fn reached_s(&self) -> f64 {
        self.from_s + self.trajectory.path_length_m
    }
}

/// A stretch of a stroke no motion reached (m of arc length).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Unreached {
    /// Where it starts.
    pub from_s: f64,
    /// Where it ends.
    pub to_s: f64,
}

/// A stroke planned in one or more parts.
#[derive(Clone, Debug)]
pub struct StrokePlan {
    /// The stroke as drawn (reversed where the order says so).
    pub path: Path,
    /// The parts, in order along the stroke.
    pub parts: Vec<StrokePart>,
    /// The stretches no part reached.
    pub unreached: Vec<Unreached>,
    /// Searches run (parts planned, those that gained nothing included).
    pub searches: usize,
}

impl StrokePlan {
    /// Arc length drawn: the union of the parts' stretches (m).
    pub fn drawn_m(&self) -> f64 {
        let mut drawn = 0.0;
        let mut covered = 0.0_f64;
        for part in &self.parts {
            let from = part.from_s.max(covered);
            drawn += (part.reached_s() - from).max(0.0);
            covered = covered.max(part.reached_s());
        }
        drawn
    }

    /// Whether the whole stroke was drawn.
    pub fn complete(&self) -> bool {
        self.unreached.is_empty()
            && self
                .parts
                .last()
                .is_some_and(|part| part.reached_s() >= self.path.length_m() - 2.0 * ARRIVAL_M)
    }
}

/// Plans `path` with `planner` as `request` asks (the search): from its start, then from where each part stopped
/// (`settings.overlap_m` back), while a part gains at least `settings.min_gain_m`; a stretch
/// where no motion starts or gains is skipped by `settings.min_gain_m` and reported, up to
/// `settings.max_parts` searches.
pub fn plan_stroke(
    planner: &Planner,
    request: &PlanRequest,
    path: &Path,
    settings: &JobSettings,
) -> StrokePlan {
    let length = path.length_m();
    let mut plan = StrokePlan {
        path: path.clone(),
        parts: Vec::new(),
        unreached: Vec::new(),
        searches: 0,
    };
    // How far the stroke is drawn or given up.
    let mut done = 0.0;
    while done < length - 2.0 * ARRIVAL_M && plan.searches < settings.max_parts {
        plan.searches += 1;
        let from_s = if plan.parts.is_empty() || done <= 0.0 {
            done
        } else {
            (done - settings.overlap_m).max(0.0)
        };
        let part = path
            .stretch(from_s, length)
            .and_then(|stretch| Task::on_path(planner.robot(), stretch, None).ok())
            .and_then(|task| {
                let planned = planner.plan(&task, request).ok()?;
                Some(StrokePart {
                    from_s,
                    task,
                    trajectory: planned.trajectory,
                })
            });
        let gained = part
            .as_ref()
            .filter(|part| {
                !matches!(
                    part.trajectory.termination,
                    Termination::InvalidStart { .. }
                )
            })
            .map_or(0.0, |part| part.reached_s() - done);
        match part {
            Some(part) if gained >= settings.min_gain_m || completes(&part, length) => {
                done = part.reached_s();
                plan.parts.push(part);
            }
            _ => {
                let to_s = (done + settings.min_gain_m).min(length);
                push_unreached(&mut plan.unreached, done, to_s);
                done = to_s;
            }
        }
    }
    if done < length - 2.0 * ARRIVAL_M {
        push_unreached(&mut plan.unreached, done, length);
    }
    plan
}

/// Whether a part ends at the stroke's end.
fn completes(part: &StrokePart, length: f64) -> bool {
    part.trajectory.termination == Termination::Completed
        || part.reached_s() >= length - 2.0 * ARRIVAL_M
}

/// Adds `[from, to]`, merged with the last stretch where they touch.
fn push_unreached(unreached: &mut Vec<Unreached>, from_s: f64, to_s: f64) {
    match unreached.last_mut() {
        Some(last) if (last.to_s - from_s).abs() < 1e-12 => last.to_s = to_s,
        _ => unreached.push(Unreached { from_s, to_s }),
    }
}
