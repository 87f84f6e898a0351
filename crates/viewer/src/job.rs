//! A job's program as the job page draws it: every stroke on the part (the stretches drawn and
//! those not), the TCP's pen-up moves, the segments named on one time line, and the arm at the
//! program's samples (decimated to [`JOB_PAGE_RATE_HZ`], every segment's ends kept).
//!
//! The inputs are plain (paths, tasks, configurations): this crate does not know the job's file
//! format; `emg job --html` converts a program into them.

use std::fmt;
use std::ops::Range;

use emg_control::{ARRIVAL_M, ConstraintConfig, Path, Task};
use emg_kinematics::{JointVector, Robot, Vec3};
use serde::Serialize;

use crate::scene::{
    SceneCapsule, SceneConstraints, SceneObstacle, ScenePath, ScenePose, capsules, cell, length,
    point, time, value,
};

/// The rate (Hz) the job page samples the program at: the arm is drawn at every `1/50` s of
/// the program (and at every segment's ends), and interpolated in between.
pub const JOB_PAGE_RATE_HZ: f64 = 50.0;

/// Distance (m) between the points of a pen-up move's TCP polyline: the program's samples of
/// the move, thinned to points at least this far apart (the move's ends always kept).
pub const MOVE_POINT_SPACING_M: f64 = 0.002;

/// Gaps between a stroke's drawn stretches shorter than this (m) are not drawn as unreached: a
/// stroke counts as drawn to its end within `2 ×` [`ARRIVAL_M`], as a job counts it.
pub const MIN_UNREACHED_M: f64 = 2.0 * ARRIVAL_M;

/// Samples and segment ends this close in time (s) are the same instant.
const SAME_TIME_S: f64 = 1e-7;

/// What a segment of a job's program does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JobSegmentKind {
    /// Pen down along part `part` of stroke `stroke` (the job's index).
    Stroke {
        /// The stroke's index in the job (into [`JobViewerInput::strokes`]).
        stroke: usize,
        /// The part (0 unless the stroke was resumed).
        part: usize,
    },
    /// The tool lifted off the surface.
    Retreat,
    /// A free move between two lifted configurations (or home), or a whole pen-up move blended
    /// from one stroke part to the next.
    Travel,
    /// The tool set down on the surface.
    Approach,
}

impl JobSegmentKind {
    /// The kind's tag as a job file writes it: `stroke`, `retreat`, `travel` or `approach`.
    pub fn tag(self) -> &'static str {
        match self {
            Self::Stroke { .. } => "stroke",
            Self::Retreat => "retreat",
            Self::Travel => "travel",
            Self::Approach => "approach",
        }
    }
}

/// The segment's name as the page shows it: `stroke 3 part 0`, `retreat`, `travel`,
/// `approach`.
impl fmt::Display for JobSegmentKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Stroke { stroke, part } => write!(f, "stroke {stroke} part {part}"),
            other => f.write_str(other.tag()),
        }
    }
}

/// One segment of a job's program and its span.
#[derive(Clone, Copy, Debug)]
pub struct JobSegment<'a> {
    /// What it does.
    pub kind: JobSegmentKind,
    /// When it starts (s from the program's start).
    pub start_s: f64,
    /// When it ends (s from the program's start).
    pub end_s: f64,
    /// A stroke part's task: the stretch of the stroke from where the part starts to the
    /// stroke's end (as a job plans it); `None` for a move.
    pub task: Option<&'a Task>,
}

/// One sample of a job's program.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JobSample {
    /// Its time (s from the program's start).
    pub time_s: f64,
    /// The arm's configuration.
    pub q: JointVector,
}

/// Everything a job page shows: the arm, every stroke and what was drawn of it, the program's
/// segments and samples, and the cell.
#[derive(Clone, Copy, Debug)]
pub struct JobViewerInput<'a> {
    /// The arm that moves (its capsules are drawn).
    pub robot: &'a Robot,
    /// Every stroke of the job, by the job's index, each as drawn (reversed where the job draws
    /// it from its end).
    pub strokes: &'a [Path],
    /// Per stroke (as `strokes`), the stretches of arc length along it the program draws
    /// (drawn solid; the rest faint): [`drawn_stretches`] finds them in the program.
    pub reached: &'a [Vec<Range<f64>>],
    /// The program's segments in time order.
    pub segments: &'a [JobSegment<'a>],
    /// The program's samples in time order (a job's at 1 kHz; the page keeps
    /// [`JOB_PAGE_RATE_HZ`] of them, at their times).
    pub samples: &'a [JobSample],
    /// The tasks whose work surfaces are drawn (for a job, `emg_job::part_surfaces` of its
    /// strokes: the part, one plate per plane the strokes lie on).
    pub surfaces: &'a [Task],
    /// The constraints the job was planned under (tool cone, work surface, obstacles).
    pub constraints: &'a ConstraintConfig,
    /// Page title and heading (plain text; escaped as needed).
    pub title: &'a str,
}

/// Where the TCP stands along its stroke at one sample of a stroke part.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Progress {
    /// Arc length along the stroke (m).
    s_m: f64,
    /// Distance from the stroke (m).
    lateral_m: f64,
    /// Angle of the tool axis from the surface normal (degrees).
    tool_angle_deg: f64,
}

/// The indices of `samples` within `segment`'s span, its ends included.
fn segment_samples(samples: &[JobSample], segment: &JobSegment<'_>) -> Range<usize> {
    let first = samples.partition_point(|s| s.time_s < segment.start_s - SAME_TIME_S);
    let last = samples.partition_point(|s| s.time_s <= segment.end_s + SAME_TIME_S);
    first..last.max(first)
}

/// The stroke `segment` draws on and its task, if it is a stroke part; panics naming the
/// segment where it names no stroke of `strokes` or has no task.
fn stroke_of<'s, 't>(
    strokes: &'s [Path],
    segment: &JobSegment<'t>,
) -> Option<(usize, &'s Path, &'t Task)> {
    let JobSegmentKind::Stroke { stroke, .. } = segment.kind else {
        return None;
    };
    let path = strokes.get(stroke).unwrap_or_else(|| {
        panic!(
            "segment '{}' names stroke {stroke}, but the input holds {} strokes",
            segment.kind,
            strokes.len()
        )
    });
    let task = segment
        .task
        .unwrap_or_else(|| panic!("segment '{}' has no task", segment.kind));
    Some((stroke, path, task))
}

/// Where the TCP stands along `stroke` at each of `samples` of a part planned on `task` (the
/// stroke's stretch from the part's start to its end): followed along the task from its start,
/// offset by where the stretch starts on the stroke.
fn stroke_progress(
    robot: &Robot,
    stroke: &Path,
    task: &Task,
    samples: &[JobSample],
) -> Vec<Progress> {
    let from_s = task
        .length_m()
        .map_or(0.0, |stretch| (stroke.length_m() - stretch).max(0.0));
    let mut hint = 0.0;
    samples
        .iter()
        .map(|sample| {
            let kin = robot.forward(&sample.q);
            let along = task.along(&kin.tcp(), hint);
            hint = along.s_m;
            Progress {
                s_m: from_s + along.s_m,
                lateral_m: along.lateral.norm(),
                tool_angle_deg: emg_control::tool_angle_deg(&kin.tool_axis(), &task.n),
            }
        })
        .collect()
}

/// Per stroke of `strokes` (the job's, each as drawn), the stretches of arc length the program
/// of `segments` and `samples` draws: each stroke part's from where its samples start along
/// the stroke to the farthest they reach, overlapping stretches merged, in order along the
/// stroke.
///
/// # Panics
///
/// Where a stroke segment names a stroke `strokes` lacks, or has no task.
pub fn drawn_stretches(
    robot: &Robot,
    strokes: &[Path],
    segments: &[JobSegment<'_>],
    samples: &[JobSample],
) -> Vec<Vec<Range<f64>>> {
    let mut reached = vec![Vec::new(); strokes.len()];
    for segment in segments {
        let Some((index, stroke, task)) = stroke_of(strokes, segment) else {
            continue;
        };
        let progress = stroke_progress(
            robot,
            stroke,
            task,
            &samples[segment_samples(samples, segment)],
        );
        let (low, high) = progress
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(low, high), p| {
                (low.min(p.s_m), high.max(p.s_m))
            });
        if low <= high {
            reached[index].push(low..high);
        }
    }
    reached.into_iter().map(merged).collect()
}

/// `stretches` sorted, those that overlap or touch merged.
fn merged(mut stretches: Vec<Range<f64>>) -> Vec<Range<f64>> {
    stretches.sort_by(|a, b| a.start.total_cmp(&b.start));
    let mut out: Vec<Range<f64>> = Vec::with_capacity(stretches.len());
    for stretch in stretches {
        match out.last_mut() {
            Some(last) if stretch.start <= last.end => last.end = last.end.max(stretch.end),
            _ => out.push(stretch),
        }
    }
    out
}

/// The stretches of `[0, length_m]` outside `reached` (sorted, disjoint), those shorter than
/// [`MIN_UNREACHED_M`] left out.
fn unreached(reached: &[Range<f64>], length_m: f64) -> Vec<Range<f64>> {
    let mut gaps = Vec::new();
    let mut from = 0.0_f64;
    for stretch in reached {
        gaps.push(from..stretch.start.min(length_m));
        from = from.max(stretch.end);
    }
    gaps.push(from..length_m);
    gaps.retain(|gap| gap.end - gap.start >= MIN_UNREACHED_M);
    gaps
}

/// The indices of the samples the page keeps: the first and the last, every one at a segment's
/// start or end, and otherwise one at least `1 / rate_hz` after the one kept before it.
fn page_samples(samples: &[JobSample], segments: &[JobSegment<'_>], rate_hz: f64) -> Vec<usize> {
    let period = 1.0 / rate_hz;
    let mut ends: Vec<f64> = segments.iter().flat_map(|s| [s.start_s, s.end_s]).collect();
    ends.sort_by(f64::total_cmp);
    let at_end = |t: f64| {
        let next = ends.partition_point(|end| *end < t - SAME_TIME_S);
        ends.get(next).is_some_and(|end| *end <= t + SAME_TIME_S)
    };
    let mut kept: Vec<usize> = Vec::new();
    for (index, sample) in samples.iter().enumerate() {
        let due = kept
            .last()
            .is_none_or(|&k| sample.time_s - samples[k].time_s >= period - SAME_TIME_S);
        if due || index + 1 == samples.len() || at_end(sample.time_s) {
            kept.push(index);
        }
    }
    kept
}

/// The TCP's polyline through `samples` (a move's): thinned to points at least
/// [`MOVE_POINT_SPACING_M`] apart, the first and the last sample's always kept.
fn move_polyline(robot: &Robot, samples: &[JobSample]) -> Vec<Vec3> {
    let tcp: Vec<Vec3> = samples.iter().map(|s| robot.forward(&s.q).tcp()).collect();
    let mut line: Vec<Vec3> = Vec::new();
    for (index, p) in tcp.iter().enumerate() {
        let far = line
            .last()
            .is_none_or(|last| (p - last).norm() >= MOVE_POINT_SPACING_M);
        if far || index + 1 == tcp.len() {
            line.push(*p);
        }
    }
    line
}

/// The job page's whole input, serialised as JSON.
#[derive(Debug, Serialize)]
pub(crate) struct JobScene<'a> {
    title: &'a str,
    robot: &'a str,
    constraints: SceneConstraints,
    obstacles: Vec<SceneObstacle<'a>>,
    capsules: Vec<SceneCapsule<'a>>,
    strokes: Vec<SceneStroke>,
    segments: Vec<SceneSegment>,
    /// The strokes' length and the length the program draws of them (m).
    length_m: f64,
    drawn_m: f64,
    steps: Vec<JobStep>,
}

/// One stroke: where it lies and what of it is drawn.
#[derive(Debug, Serialize)]
struct SceneStroke {
    /// The job's index.
    stroke: usize,
    path: ScenePath,
    /// The surface normal `n` the pen points along (the surface faces `−n`).
    normal: [f64; 3],
    /// Stretches `[from, to]` of arc length the program draws.
    reached: Vec<[f64; 2]>,
    /// The rest of the stroke (stretches shorter than [`MIN_UNREACHED_M`] left out).
    unreached: Vec<[f64; 2]>,
}

/// One segment of the program.
#[derive(Debug, Serialize)]
struct SceneSegment {
    /// `stroke`, `retreat`, `travel` or `approach`.
    kind: &'static str,
    /// As the page shows it ([`JobSegmentKind`]'s display).
    name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    stroke: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    part: Option<usize>,
    start_s: f64,
    end_s: f64,
    /// A stroke part's surface normal (the tool cone's axis).
    #[serde(skip_serializing_if = "Option::is_none")]
    n: Option<[f64; 3]>,
    /// A move's TCP polyline ([`move_polyline`]), drawn dashed.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    tcp: Vec<[f64; 3]>,
}

/// One kept sample in world coordinates.
#[derive(Debug, Serialize)]
struct JobStep {
    t: f64,
    /// Arc length along the stroke being drawn (m); absent pen up.
    #[serde(skip_serializing_if = "Option::is_none")]
    s: Option<f64>,
    /// Distance of the TCP from that stroke (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    lateral: Option<f64>,
    /// Angle of the tool axis from that stroke's surface normal (degrees).
    #[serde(skip_serializing_if = "Option::is_none")]
    tool_angle_deg: Option<f64>,
    #[serde(flatten)]
    pose: ScenePose,
}

impl<'a> JobScene<'a> {
    /// Runs forward kinematics on the kept samples and on every stroke part's samples, and
    /// samples every stroke; panics where the inputs disagree (a segment naming a stroke the
    /// input lacks, a stroke segment without a task, `reached` not one entry per stroke).
    pub(crate) fn new(input: &JobViewerInput<'a>) -> Self {
        let JobViewerInput {
            robot,
            strokes,
            reached,
            segments,
            samples,
            surfaces,
            constraints,
            title,
        } = *input;
        assert_eq!(
            reached.len(),
            strokes.len(),
            "one list of stretches reached per stroke"
        );
        let mut progress: Vec<Option<Progress>> = vec![None; samples.len()];
        for segment in segments {
            if let Some((_, stroke, task)) = stroke_of(strokes, segment) {
                let range = segment_samples(samples, segment);
                let along = stroke_progress(robot, stroke, task, &samples[range.clone()]);
                for (slot, p) in progress[range].iter_mut().zip(along) {
                    *slot = Some(p);
                }
            }
        }
        let steps = page_samples(samples, segments, JOB_PAGE_RATE_HZ)
            .into_iter()
            .map(|index| {
                let sample = &samples[index];
                let at = progress[index];
                JobStep {
                    t: time(sample.time_s),
                    s: at.map(|p| length(p.s_m)),
                    lateral: at.map(|p| length(p.lateral_m)),
                    tool_angle_deg: at.map(|p| value(p.tool_angle_deg)),
                    pose: ScenePose::at(robot, &sample.q),
                }
            })
            .collect();
        let scene_strokes = strokes
            .iter()
            .zip(reached)
            .enumerate()
            .map(|(index, (path, reached))| SceneStroke {
                stroke: index,
                path: ScenePath::new(path),
                normal: point(&path.normal()),
                reached: reached
                    .iter()
                    .map(|r| [length(r.start), length(r.end)])
                    .collect(),
                unreached: unreached(reached, path.length_m())
                    .iter()
                    .map(|r| [length(r.start), length(r.end)])
                    .collect(),
            })
            .collect();
        let scene_segments = segments
            .iter()
            .map(|segment| {
                let (stroke, part) = match segment.kind {
                    JobSegmentKind::Stroke { stroke, part } => (Some(stroke), Some(part)),
                    _ => (None, None),
                };
                let tcp = match segment.kind {
                    JobSegmentKind::Stroke { .. } => Vec::new(),
                    _ => move_polyline(robot, &samples[segment_samples(samples, segment)])
                        .iter()
                        .map(point)
                        .collect(),
                };
                SceneSegment {
                    kind: segment.kind.tag(),
                    name: segment.kind.to_string(),
                    stroke,
                    part,
                    start_s: time(segment.start_s),
                    end_s: time(segment.end_s),
                    n: segment
                        .task
                        .filter(|_| stroke.is_some())
                        .map(|task| point(&task.n)),
                    tcp,
                }
            })
            .collect();
        let plates = surfaces.iter().filter_map(|task| {
            task.work_surface(&constraints.work_surface)
                .shape(&task.p0, &task.d, &task.n)
        });
        Self {
            title,
            robot: robot.name(),
            constraints: SceneConstraints {
                line_tolerance_m: constraints.line_tolerance_m,
                theta_max_deg: constraints.theta_max_deg,
                // Every surface, a half-space too, is an obstacle of its own here.
                work_surface: false,
            },
            obstacles: cell(plates, &constraints.scene),
            capsules: capsules(robot),
            strokes: scene_strokes,
            segments: scene_segments,
            length_m: length(strokes.iter().map(Path::length_m).sum()),
            drawn_m: length(
                reached
                    .iter()
                    .flatten()
                    .map(|r| (r.end - r.start).max(0.0))
                    .sum(),
            ),
            steps,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_are_named_as_the_job_names_them() {
        let names: Vec<String> = [
            JobSegmentKind::Stroke { stroke: 3, part: 0 },
            JobSegmentKind::Retreat,
            JobSegmentKind::Travel,
            JobSegmentKind::Approach,
        ]
        .iter()
        .map(ToString::to_string)
        .collect();
        assert_eq!(names, ["stroke 3 part 0", "retreat", "travel", "approach"]);
        assert_eq!(
            JobSegmentKind::Stroke { stroke: 1, part: 2 }.tag(),
            "stroke"
        );
    }

    #[test]
    fn overlapping_stretches_merge_and_the_rest_is_unreached() {
        let reached = merged(vec![0.3..0.5, 0.0..0.1, 0.09..0.2]);
        assert_eq!(reached, [0.0..0.2, 0.3..0.5]);
        assert_eq!(unreached(&reached, 0.6), [0.2..0.3, 0.5..0.6]);
        assert_eq!(unreached(&[], 0.25), [0.0..0.25]);
        assert_eq!(unreached(&[0.05..0.25], 0.25), [0.0..0.05]);
        // Slivers a job counts as drawn are not drawn faint.
        let almost = [0.0..0.1, 0.10005..0.29995];
        assert!(unreached(&almost, 0.3).is_empty());
    }

    #[test]
    fn the_page_keeps_its_rate_and_every_segment_end() {
        let samples: Vec<JobSample> = (0..=1000)
            .map(|k| JobSample {
                time_s: k as f64 * 1e-3,
                q: JointVector::zeros(),
            })
            .collect();
        let segment = |start_s, end_s| JobSegment {
            kind: JobSegmentKind::Travel,
            start_s,
            end_s,
            task: None,
        };
        let segments = [
            segment(0.0, 0.333),
            segment(0.333, 0.999),
            segment(0.999, 1.0),
        ];
        let kept = page_samples(&samples, &segments, JOB_PAGE_RATE_HZ);
        for end in [0, 333, 999, 1000] {
            assert!(kept.contains(&end), "sample {end} is kept: {kept:?}");
        }
        assert!(kept.windows(2).all(|w| w[1] - w[0] <= 20), "{kept:?}");
        assert_eq!(kept.len(), 53, "{kept:?}");
        assert_eq!(
            segment_samples(&samples, &segments[1]),
            333..1000,
            "a segment's samples, both ends included"
        );
        assert!(page_samples(&[], &segments, JOB_PAGE_RATE_HZ).is_empty());
    }
}
