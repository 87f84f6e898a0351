//! A job's program as the viewer draws it (`emg_viewer::render_job_html`): what `emg job --html`
//! and the README's picture show; and the heat map of a job's places
//! (`emg_viewer::placement_map_svg`).

use emg_control::Path;
use emg_kinematics::Robot;

use emg_viewer::{MapCell, MapMark, placement_map_svg};

use crate::place::{Placement, Score};
use crate::program::{JobFile, SegmentKind};
use crate::spec::Job;

/// The viewer page of `file`, the program of `job` on `robot`, titled after `name`.
pub fn viewer_page(file: &JobFile, job: &Job, robot: &Robot, name: &str) -> String {
    // Every stroke as drawn: merged where the order merged it, reversed where it draws it from
    // its end.
    let drawn = file.ordering.drawn_paths(&job.strokes);
    let mut strokes: Vec<Path> = drawn.clone();
    for oriented in &file.ordering.sequence {
        strokes[oriented.stroke] = oriented.path(&drawn);
    }
    let segments: Vec<emg_viewer::JobSegment<'_>> = file
        .segments
        .iter()
        .map(|segment| emg_viewer::JobSegment {
            kind: match segment.kind {
                SegmentKind::Stroke { stroke, part, .. } => {
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
        .points()
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

/// The heat map of `placement`'s screened places ([`placement_map_svg`]): per position the
/// best `score` over the heights and turns, the certified places ranked: what `emg place
/// --map` writes.
pub fn placement_map(placement: &Placement, score: Score) -> String {
    let mut cells: Vec<MapCell> = Vec::new();
    for scored in &placement.screened {
        let p = &scored.place;
        match cells.iter_mut().find(|c| c.x_m == p.x_m && c.y_m == p.y_m) {
            Some(cell) if cell.score >= scored.score => {}
            Some(cell) => {
                cell.score = scored.score;
                cell.rotation_deg = p.rotation_deg;
            }
            None => cells.push(MapCell {
                x_m: p.x_m,
                y_m: p.y_m,
                score: scored.score,
                rotation_deg: p.rotation_deg,
            }),
        }
    }
    let mut marks: Vec<MapMark> = Vec::new();
    for (rank, c) in placement.certified.iter().enumerate() {
        let (x_m, y_m) = (c.scored.place.x_m, c.scored.place.y_m);
        match marks.iter_mut().find(|m| m.x_m == x_m && m.y_m == y_m) {
            Some(mark) => mark.ranks.push_str(&format!(", {}", rank + 1)),
            None => marks.push(MapMark {
                x_m,
                y_m,
                ranks: (rank + 1).to_string(),
            }),
        }
    }
    let what = match score {
        Score::Bound => "Σ min(bound, length) / Σ length",
        Score::PointIk => "share of stroke points with an IK solution",
    };
    placement_map_svg(
        &cells,
        &marks,
        &format!(
            "best screened score per position ({what}); the turn below it; planned places ranked"
        ),
    )
}
