//! The data a job page gets: every stroke's points, the stretches drawn and not drawn, the
//! pen-up moves' TCP polylines, the segments' names and spans, the samples kept and where the
//! pen is down, read back from the page's own JSON blob.

mod support;

use emg_kinematics::Vec3;
use emg_viewer::{JOB_PAGE_RATE_HZ, JobSegmentKind, MOVE_POINT_SPACING_M};
use serde_json::Value;

use support::job::{SyntheticJob, synthetic_job};

/// The page's data blob.
fn data_of(page: &str) -> Value {
    let open = r#"<script type="application/json" id="motion-data">"#;
    let start = page.find(open).expect("the page holds its data") + open.len();
    let end = start + page[start..].find("</script>").expect("the data ends");
    serde_json::from_str(&page[start..end]).expect("the data is JSON")
}

fn vec3(value: &Value) -> Vec3 {
    let v: Vec<f64> = serde_json::from_value(value.clone()).expect("a point");
    Vec3::new(v[0], v[1], v[2])
}

fn numbers(value: &Value) -> Vec<f64> {
    serde_json::from_value(value.clone()).expect("numbers")
}

/// Points are written to 10 µm.
const ROUNDING_M: f64 = 1e-5;

/// The job and its page's data.
fn job_and_data() -> (SyntheticJob, Value) {
    let job = synthetic_job();
    let data = data_of(&job.page("two strokes"));
    (job, data)
}

#[test]
fn every_stroke_is_sampled_on_its_path() {
    let (job, data) = job_and_data();
    let strokes = data["strokes"].as_array().expect("strokes");
    assert_eq!(strokes.len(), job.strokes.len());
    for (index, (stroke, path)) in strokes.iter().zip(&job.strokes).enumerate() {
        assert_eq!(stroke["stroke"], index);
        let sampled = &stroke["path"];
        let s = numbers(&sampled["s"]);
        let points = sampled["points"].as_array().expect("points");
        assert_eq!(s.len(), points.len());
        assert_eq!(s.len(), sampled["sides"].as_array().expect("sides").len());
        assert_eq!(s[0], 0.0);
        assert!(
            (s[s.len() - 1] - path.length_m()).abs() <= ROUNDING_M,
            "to its end"
        );
        assert!(s.windows(2).all(|w| w[1] > w[0]), "ascending arc length");
        for (s, p) in s.iter().zip(points) {
            let error = (vec3(p) - path.point_at(*s)).norm();
            assert!(
                error <= 2.0 * ROUNDING_M,
                "stroke {index} at {s} m: {error} m off"
            );
        }
        // A line needs only its ends; an arc a sample every 5 mm or 5° at most.
        let longest = s.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        if index == 0 {
            assert_eq!(s.len(), 2, "a line is its two ends");
        } else {
            assert!(
                longest <= 0.05 * 5f64.to_radians() + ROUNDING_M,
                "{longest} m between samples"
            );
        }
    }
}

#[test]
fn stretches_drawn_and_not_drawn_split_each_stroke() {
    let (job, data) = job_and_data();
    let reached = job.reached();
    // Stroke 0 is drawn whole in one part; stroke 1 in two, the gap between them not drawn.
    assert_eq!(reached[0].len(), 1, "{reached:?}");
    assert!(reached[0][0].start < 1e-4 && reached[0][0].end > job.strokes[0].length_m() - 1e-4);
    assert_eq!(reached[1].len(), 2, "{reached:?}");
    assert!(reached[1][0].start < 1e-4);
    assert!(
        (reached[1][0].end - job.gap.start).abs() < 1e-4,
        "{reached:?} {:?}",
        job.gap
    );
    assert!(
        (reached[1][1].start - job.gap.end).abs() < 1e-4,
        "{reached:?} {:?}",
        job.gap
    );
    assert!(reached[1][1].end > job.strokes[1].length_m() - 1e-4);

    let strokes = data["strokes"].as_array().expect("strokes");
    for (index, stroke) in strokes.iter().enumerate() {
        let page_reached: Vec<[f64; 2]> =
            serde_json::from_value(stroke["reached"].clone()).unwrap();
        assert_eq!(page_reached.len(), reached[index].len());
        for (page, given) in page_reached.iter().zip(&reached[index]) {
            assert!((page[0] - given.start).abs() <= ROUNDING_M);
            assert!((page[1] - given.end).abs() <= ROUNDING_M);
        }
    }
    let unreached = |index: usize| -> Vec<[f64; 2]> {
        serde_json::from_value(strokes[index]["unreached"].clone()).unwrap()
    };
    assert!(
        unreached(0).is_empty(),
        "stroke 0 is drawn whole: {:?}",
        unreached(0)
    );
    let gap = unreached(1);
    assert_eq!(gap.len(), 1, "{gap:?}");
    assert!((gap[0][0] - reached[1][0].end).abs() <= ROUNDING_M);
    assert!((gap[0][1] - reached[1][1].start).abs() <= ROUNDING_M);
    let drawn: f64 = reached.iter().flatten().map(|r| r.end - r.start).sum();
    assert!((data["drawn_m"].as_f64().unwrap() - drawn).abs() <= ROUNDING_M);
    let total: f64 = job.strokes.iter().map(|p| p.length_m()).sum();
    assert!((data["length_m"].as_f64().unwrap() - total).abs() <= ROUNDING_M);
}

#[test]
fn segments_are_named_and_moves_carry_the_tcp_polyline() {
    let (job, data) = job_and_data();
    let segments = data["segments"].as_array().expect("segments");
    let names: Vec<&str> = segments
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "approach",
            "stroke 0 part 0",
            "retreat",
            "travel",
            "approach",
            "stroke 1 part 0",
            "retreat",
            "travel",
            "approach",
            "stroke 1 part 1",
            "retreat"
        ]
    );
    for (segment, span) in segments.iter().zip(&job.spans) {
        assert_eq!(segment["kind"], span.kind.tag());
        assert!((segment["start_s"].as_f64().unwrap() - span.start_s).abs() < 1e-6);
        assert!((segment["end_s"].as_f64().unwrap() - span.end_s).abs() < 1e-6);
        let samples: Vec<_> = job
            .samples
            .iter()
            .filter(|s| s.time_s >= span.start_s - 1e-9 && s.time_s <= span.end_s + 1e-9)
            .collect();
        let tcp = |q| job.robot.forward(q).tcp();
        match span.kind {
            JobSegmentKind::Stroke { stroke, part } => {
                assert_eq!(segment["stroke"], stroke);
                assert_eq!(segment["part"], part);
                assert!(
                    segment.get("tcp").is_none(),
                    "a stroke's ink comes from the steps"
                );
                let n = vec3(&segment["n"]);
                assert!((n - job.tasks[span.task.unwrap()].n).norm() < 2.0 * ROUNDING_M);
            }
            _ => {
                assert!(segment.get("stroke").is_none() && segment.get("n").is_none());
                let line: Vec<Vec3> = segment["tcp"]
                    .as_array()
                    .expect("a move's TCP polyline")
                    .iter()
                    .map(vec3)
                    .collect();
                let first = tcp(&samples[0].q);
                let last = tcp(&samples[samples.len() - 1].q);
                assert!(
                    (line[0] - first).norm() < 2.0 * ROUNDING_M,
                    "starts where the move does"
                );
                assert!(
                    (line[line.len() - 1] - last).norm() < 2.0 * ROUNDING_M,
                    "ends where it does"
                );
                for pair in line[..line.len() - 1].windows(2) {
                    assert!((pair[1] - pair[0]).norm() >= MOVE_POINT_SPACING_M - 2.0 * ROUNDING_M);
                }
                // Every sample of the move lies within the spacing of the polyline's points.
                for sample in &samples {
                    let p = tcp(&sample.q);
                    let nearest = line
                        .iter()
                        .map(|q| (q - p).norm())
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        nearest <= MOVE_POINT_SPACING_M + 2.0 * ROUNDING_M,
                        "{nearest} m"
                    );
                }
                assert!(line.len() > 3, "a real move: {} points", line.len());
            }
        }
    }
}

#[test]
fn samples_are_kept_at_the_page_rate_with_every_segment_end() {
    let (job, data) = job_and_data();
    let steps = data["steps"].as_array().expect("steps");
    let times: Vec<f64> = steps.iter().map(|s| s["t"].as_f64().unwrap()).collect();
    assert!(times.windows(2).all(|w| w[1] > w[0]), "in time order");
    let duration = job.samples.last().unwrap().time_s;
    assert_eq!(times[0], 0.0);
    assert!(
        (times[times.len() - 1] - duration).abs() < 1e-6,
        "to the program's end"
    );
    // At the page's rate between segment ends (the rollout's steps are 10 ms apart or more).
    let period = 1.0 / JOB_PAGE_RATE_HZ;
    let largest_gap = job
        .samples
        .windows(2)
        .map(|w| w[1].time_s - w[0].time_s)
        .fold(0.0, f64::max);
    for w in times.windows(2) {
        assert!(
            w[1] - w[0] <= period + largest_gap + 1e-6,
            "{} s apart",
            w[1] - w[0]
        );
    }
    assert!(
        (times.len() as f64) < duration * JOB_PAGE_RATE_HZ + 2.0 * job.spans.len() as f64 + 2.0,
        "{} steps for {duration} s",
        times.len()
    );
    for span in &job.spans {
        for end in [span.start_s, span.end_s] {
            assert!(
                times.iter().any(|t| (t - end).abs() < 1e-6),
                "a step at {end} s, where {} starts or ends",
                span.kind
            );
        }
    }
    // Pen down (within a stroke part) a step knows where along the stroke it is; pen up not.
    for (step, t) in steps.iter().zip(&times) {
        let stroke = job
            .spans
            .iter()
            .find(|s| s.task.is_some() && *t >= s.start_s - 1e-6 && *t <= s.end_s + 1e-6);
        assert_eq!(step.get("s").is_some(), stroke.is_some(), "at {t} s");
        assert_eq!(
            step.get("tool_angle_deg").is_some(),
            stroke.is_some(),
            "at {t} s"
        );
        let joints = step["joints"].as_array().unwrap();
        assert_eq!(joints.len(), job.robot.dof() + 2, "base, joints and TCP");
    }
}

#[test]
fn the_cell_and_the_page_stay_self_contained() {
    let job = synthetic_job();
    let page = job.page("two <strokes>");
    assert!(page.starts_with("<!DOCTYPE html>"));
    assert!(page.contains("<title>two &lt;strokes&gt;</title>"));
    assert!(!page.contains("http://") && !page.contains("https://"));
    let data = data_of(&page);
    let obstacles = data["obstacles"].as_array().unwrap();
    assert_eq!(obstacles.len(), 1, "the plate under stroke 0");
    assert_eq!(obstacles[0]["name"], emg_control::WORK_SURFACE);
    assert_eq!(obstacles[0]["surface"], true);
    assert_eq!(obstacles[0]["kind"], "box");
    // The job page's own read-out, on the shared template and core script.
    for id in [
        "r-time",
        "r-segment",
        "r-stroke",
        "r-lateral",
        "r-angle",
        "r-step",
    ] {
        assert!(page.contains(&format!(r#"id="{id}""#)), "{id}");
    }
    assert!(
        page.contains("const emg = (function () {"),
        "the core script"
    );
    assert!(page.contains("// The job page:"), "the job script");
    assert!(
        !page.contains("// The motion page:"),
        "not the motion page's script"
    );
}
