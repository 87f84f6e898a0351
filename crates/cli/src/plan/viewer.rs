//! `emg plan --html`: the self-contained page that animates a planned task's motion in 3D.

use std::path::Path;

use anyhow::Result;
use emg_control::{Task, Trajectory};
use emg_planner::Planner;

use crate::output::write_text;

/// `trajectory` with each step at the time the timed motion passes it: the viewer plays the
/// motion the robot executes, at rest where it starts and ends.
pub fn played_as_timed(trajectory: &Trajectory, step_times_s: &[f64]) -> Trajectory {
    let mut played = trajectory.clone();
    for (step, time_s) in played.steps.iter_mut().zip(step_times_s) {
        step.time_s = *time_s;
    }
    played
}

/// Writes the `--html` viewer page of one planned task to `path`; returns the line to print.
pub fn write_viewer(
    planner: &Planner,
    task: &Task,
    trajectory: &Trajectory,
    path: &Path,
) -> Result<String> {
    let name = path
        .file_stem()
        .unwrap_or(path.as_os_str())
        .to_string_lossy();
    let acted: Vec<&str> = trajectory
        .acting_controllers()
        .into_iter()
        .map(emg_control::ActingController::name)
        .collect();
    let title = match acted.as_slice() {
        [] => format!("{name}: no step taken"),
        [one] => format!("{name}: steps by the {one} controller"),
        [first @ .., last] => format!(
            "{name}: steps by the {} and {last} controllers",
            first.join(", ")
        ),
    };
    let page = emg_viewer::render_html(&emg_viewer::ViewerInput {
        robot: planner.robot(),
        task,
        trajectory,
        constraints: &planner.config().rollout.constraints,
        title: &title,
    });
    write_text(path, &page)?;
    Ok(format!("\n  wrote {}", path.display()))
}
