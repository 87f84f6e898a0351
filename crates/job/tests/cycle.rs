//! Cycle time: short strokes close together on the FR3, drawn with a pen's lift and hopped
//! between, against the same job with a torch's lift; every program no shorter than the least
//! time the arm's limits allow, and the pen clear of the paper between strokes; seams on two
//! faces drawn in the order of least pen-up time, not of least travel.

mod common;

use emg_control::PathSpec;
use emg_job::{Job, JobFile, Order, SegmentKind, Tool, order_strokes, valley_seams, verify_job};
use emg_kinematics::{JointVector, Vec3};

/// Twelve 6 mm strokes in a 4 × 3 grid 8 mm apart, on the plate in front of the arm.
fn short_strokes() -> Vec<PathSpec> {
    (0..12)
        .map(|k| {
            let (x, y) = (0.45 + 0.008 * (k % 4) as f64, 0.008 * (k / 4) as f64);
            serde_json::from_str(&format!(
                r#"{{"version": 1, "start": [{x}, {y}, 0.25], "normal": [0, 0, -1],
                    "segments": [{{"line": {{"to": [{}, {}, 0.25]}}}}]}}"#,
                x + 0.004,
                y + 0.0045
            ))
            .expect("a path")
        })
        .collect()
}

/// The job of `strokes` with `tool` and the FR3's home, planned and checked.
fn planned(strokes: Vec<PathSpec>, tool: Tool) -> (JobFile, emg_kinematics::Robot) {
    let (planner, timing, checker, file) = common::setup("fr3");
    let mut job = Job::from_strokes(strokes, planner.robot()).expect("a valid job");
    job.settings.tool = tool;
    let job = job
        .with_home(
            &[0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785],
            planner.robot(),
        )
        .expect("home");
    let program = common::plan(&planner, &timing, &file, &job);
    verify_job(&program, &checker, planner.robot().joint_names())
        .expect("the program passes the checker");
    (program, planner.robot().clone())
}

#[test]
fn a_pen_hops_between_close_strokes_within_the_least_time_the_limits_allow() {
    let (pen, robot) = planned(short_strokes(), Tool::Pen);
    let (torch, _) = planned(short_strokes(), Tool::Torch);
    for program in [&pen, &torch] {
        let s = &program.summary;
        assert_eq!(s.complete, 12, "{s:?}");
        assert!(s.least_pen_down_s > 0.0 && s.least_pen_up_s > 0.0, "{s:?}");
        assert!(s.pen_down_s >= s.least_pen_down_s, "{s:?}");
        assert!(s.pen_up_s >= s.least_pen_up_s, "{s:?}");
    }
    assert_eq!(pen.settings.lift_m, Some(Tool::PEN_LIFT_M));
    assert_eq!(torch.settings.lift_m, Some(Tool::TORCH_LIFT_M));
    // The pen's moves between strokes: hops (up and over, straight down), the pen-up time
    // under half the torch's.
    let between: Vec<_> = pen
        .segments
        .windows(3)
        .filter(|w| {
            matches!(w[0].kind, SegmentKind::Stroke { .. })
                && matches!(w[2].kind, SegmentKind::Stroke { .. })
        })
        .map(|w| &w[1])
        .collect();
    assert_eq!(between.len(), 11);
    assert!(between.iter().all(|s| s.vertices.len() == 3), "hops");
    assert!(
        pen.summary.pen_up_s < 0.5 * torch.summary.pen_up_s,
        "pen {:?}, torch {:?}",
        pen.summary,
        torch.summary
    );
    // Between strokes the pen tip stays off the paper (z = 0.25, the tool pointing down)
    // except within 0.3 mm across the paper of where it leaves and meets it.
    let points = pen.points();
    let time = |k: usize| points[k].time_from_start.seconds();
    let tcp = |k: usize| {
        let mut q = JointVector::zeros();
        q.as_mut_slice()[..points[k].positions.len()].copy_from_slice(&points[k].positions);
        robot.forward(&q).tcp()
    };
    for segment in between {
        let first = (0..points.len())
            .find(|&k| time(k) >= segment.start_s - 1e-9)
            .expect("a point");
        let last = (first..points.len())
            .take_while(|&k| time(k) <= segment.end_s + 1e-9)
            .last()
            .expect("a point");
        let (leaves, meets) = (tcp(first), tcp(last));
        for k in first..=last {
            let at = tcp(k);
            let across = |end: &Vec3| (at - end).xy().norm();
            if across(&leaves).min(across(&meets)) > 3e-4 {
                assert!(at.z > 0.25 + 1e-4, "the pen touches the paper at {at:?}");
            }
        }
    }
}

#[test]
fn seams_on_two_faces_are_drawn_one_face_then_the_other() {
    // Listed (and, by the shortest travel, ordered) back and forth across the edge: even
    // strokes on the level face, odd ones on the rising face.
    let (program, robot) = planned(valley_seams(), Tool::Pen);
    let s = &program.summary;
    assert_eq!(s.complete, 12, "{s:?}");
    let faces: Vec<usize> = program
        .ordering
        .sequence
        .iter()
        .map(|oriented| oriented.stroke % 2)
        .collect();
    let changes = faces.windows(2).filter(|pair| pair[0] != pair[1]).count();
    assert_eq!(changes, 1, "the tool turns over {changes} times: {faces:?}");
    // The order of least travel crosses the edge at every other move: the order drawn travels
    // further.
    let job = Job::from_strokes(valley_seams(), &robot).expect("a valid job");
    let shortest = order_strokes(&job.strokes, Order::Shortest);
    assert!(
        s.travel_m > shortest.travel_m + 0.05,
        "{s:?} against {shortest:?}"
    );
    assert!(s.pen_up_s >= s.least_pen_up_s, "{s:?}");
}
