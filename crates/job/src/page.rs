//! A job's program as the viewer draws it (`emg_viewer::render_job_html`): what `emg job --html`
//! and the README's picture show.

use emg_control::Path;
use emg_kinematics::Robot;

use crate::program::{JobFile, SegmentKind};
use crate::spec::Job;

/// The viewer page of `file`, the program of `job` on `robot`, titled after `name`.
pub fn viewer_page(file: &JobFile, job: &Job, robot: &Robot, name: &str) -> String {
    // Every stroke as drawn: reversed where the order draws it from its end.
    let mut strokes: Vec<Path> = job.strokes.clone();
    for oriented in &file.ordering.sequence {
        strokes[oriented.stroke] = oriented.path(&job.strokes);
    }
    let segments: Vec<emg_viewer::JobSegment<'_>> = file
        .segments
        .iter()
        .map(|segment| emg_viewer::JobSegment {
            kind: match segment.kind {
                SegmentKind::Stroke { stroke, part } => {
                    emg_viewer::JobSegmentKind::Stroke { stroke, part }
                }
                SegmentKind::Retreat => emg_viewer::JobSegmentKind::Retreat,
                SegmentKind::Travel => emg_viewer::JobSegmentKind::Travel,
                SegmentKind::Approach => emg_viewer::JobSegmentKind::Approach,
            },
            start_s: segment.start_s,
            end_s: segment.end_s,
            task: segment.task.as_ref(),
        })
        .collect();
    let samples: Vec<emg_viewer::JobSample> = file
        .points
        .iter()
        .map(|point| emg_viewer::JobSample {
            time_s: point.time_from_start.seconds(),
            q: robot.joint_vector(&point.positions),
        })
        .collect();
    let reached = emg_viewer::drawn_stretches(robot, &strokes, &segments, &samples);
    let s = &file.summary;
    emg_viewer::render_job_html(&emg_viewer::JobViewerInput {
        robot,
        strokes: &strokes,
        reached: &reached,
        segments: &segments,
        samples: &samples,
        surfaces: &file.surfaces,
        constraints: &file.constraints,
        title: &format!(
            "{name}: {} strokes, {:.1} % drawn, {:.2} s",
            file.strokes.len(),
            100.0 * s.drawn_m / s.total_m.max(f64::MIN_POSITIVE),
            s.duration_s
        ),
    })
}
