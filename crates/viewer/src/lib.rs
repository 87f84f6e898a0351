//! A self-contained HTML motion viewer: one page that animates a planned motion along a line or
//! a path ([`render_html`]), or a whole job's program ([`render_job_html`]); and the placement
//! map of `emg place` ([`placement_map_svg`]).
//!
//! [`render_html`] turns a robot, its task, the rollout and the constraints it was planned under
//! into a single HTML document with inline CSS, inline JavaScript and the motion as an inline
//! JSON blob; it references nothing outside itself, so it opens from disk without a network.
//! The page draws on a Canvas 2D (no WebGL) with its own perspective projection:
//!
//! * the arm as its collision capsules, the joint origins and the pen highlighted;
//! * the work surface around the line (when it is a constraint) and the obstacles of the cell;
//! * the task line `p0 + s·d` with its start and its lateral tolerance, the tool cone of
//!   half-angle `θ_max` around `n` at the TCP, the current tool axis and the TCP trace so far;
//! * a timeline coloured by the controller that acted at each step, play/pause, scrubbing,
//!   playback speed, mouse-drag orbit and wheel zoom; time, path progress, tool angle and `ρ`
//!   as text. Playback follows the recorded (possibly non-uniform) timestamps in real time.
//!
//! Forward kinematics runs here, once per recorded step; the page only interpolates the world
//! points between steps by time. Once its first frame is drawn the page sets
//! `document.body.dataset.status = "rendered"`; an uncaught error or rejection sets it to
//! `"error: <message>"` instead.
//!
//! ```
//! use emg_control::{ClassicalController, RolloutConfig, Task, rollout};
//! use emg_kinematics::{Robot, Vec3};
//! use emg_viewer::{ViewerInput, render_html};
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
//! let robot = Robot::from_urdf_file(path, "link0", "pen_tip")?;
//! let seed = robot.mid_range();
//! let kin = robot.forward(&seed);
//! let task = Task::new(&robot, kin.tcp(), Vec3::y(), kin.tool_axis(), Some(seed))?;
//! let config = RolloutConfig { max_steps: 20, ..RolloutConfig::default() };
//! let trajectory = rollout(&robot, &task, &seed, &mut ClassicalController::default(), &config);
//! let page = render_html(&ViewerInput {
//!     robot: &robot,
//!     task: &task,
//!     trajectory: &trajectory,
//!     constraints: &config.constraints,
//!     title: "demo line",
//! });
//! assert!(page.starts_with("<!DOCTYPE html>"));
//! assert!(page.contains("<title>demo line</title>"));
//! assert!(page.contains(r#""theta_max_deg":30.0"#));
//! assert_eq!(page.matches(r#""controller":"classical""#).count(), 20);
//! assert!(!page.contains("http://") && !page.contains("https://"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`render_job_html`] draws a job's program ([`JobViewerInput`]: plain paths, tasks and
//! configurations, so that this crate does not depend on the job's file format): the arm
//! animated through the whole program at its timing, every stroke on the part (the stretches
//! drawn solid, the rest faint, [`drawn_stretches`]), the ink laid so far, the TCP's pen-up
//! moves (retreat, travel, approach) dashed, the segment under way named (`stroke 3 part 0`,
//! `travel`), the work plates and the obstacles; a timeline coloured by segment kind. Both
//! pages run on one core script (projection, painter's order, the arm, the cell, the controls)
//! and one template.

mod input;
mod job;
mod page;
mod placement_map;
mod scene;

pub use input::ViewerInput;
pub use job::{
    JOB_PAGE_RATE_HZ, JobSample, JobSegment, JobSegmentKind, JobViewerInput, MIN_UNREACHED_M,
    MOVE_POINT_SPACING_M, drawn_stretches,
};
pub use page::{render_html, render_job_html};
pub use placement_map::{MapCell, MapMark, placement_map_svg};
