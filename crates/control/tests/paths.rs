//! Paths: their geometry, the errors that name a malformed field, and rollouts that follow them.
//!
//! - Arc length parameterises every path: each piece starts where the one before it ends, the
//!   tangent is the derivative of the point by finite differences, blends join their two
//!   segments tangentially, and every form of arc lands where its spec says.
//! - A TCP is located along the path near where it was last, so a full circle's end is never
//!   taken for its start.
//! - A malformed path is refused with an error naming the field.
//! - The classical controller follows a rectangle and a circle, stops at corners exactly, ends
//!   with `Completed` where it gets round, and the independent checker accepts every rollout;
//!   a one-segment path is followed as the line it lies on.

mod common;

use emg_control::{
    CheckRollout, Path, PathError, PathSpec, RolloutConfig, SegmentSpec, Task, Termination,
};
use emg_kinematics::Vec3;

use common::{checker, classical, robot, tasks};

fn spec(start: Vec3, normal: Vec3, blend: f64, segments: Vec<SegmentSpec>) -> PathSpec {
    PathSpec {
        version: 1,
        start: start.into(),
        normal: normal.into(),
        blend_radius_m: blend,
        segments,
    }
}

fn line(to: Vec3) -> SegmentSpec {
    SegmentSpec::Line { to: to.into() }
}

fn arc(
    centre: Option<Vec3>,
    through: Option<Vec3>,
    to: Option<Vec3>,
    sweep: Option<f64>,
) -> SegmentSpec {
    SegmentSpec::Arc {
        centre: centre.map(Into::into),
        through: through.map(Into::into),
        to: to.map(Into::into),
        sweep_deg: sweep,
    }
}

/// A rectangle `a × b` from `p` along `d` then `n × d`, back to `p`.
fn rectangle(p: Vec3, d: Vec3, n: Vec3, a: f64, b: f64, blend: f64) -> PathSpec {
    let e = n.cross(&d);
    spec(
        p,
        n,
        blend,
        vec![
            line(p + d * a),
            line(p + d * a + e * b),
            line(p + e * b),
            line(p),
        ],
    )
}

fn assert_close(a: Vec3, b: Vec3, tolerance: f64, what: &str) {
    assert!((a - b).norm() <= tolerance, "{what}: {a:?} vs {b:?}");
}

/// Continuity of points, tangents by finite differences, unit tangents.
fn assert_parameterised(path: &Path) {
    let h = 1e-6;
    for piece in path.pieces() {
        let (start, end, _) = piece.outline();
        assert_close(path.point_at(piece.start_s), start, 1e-12, "piece start");
        assert_close(
            path.point_at(piece.start_s + piece.length_m),
            end,
            1e-9,
            "piece end",
        );
        for k in 1..10 {
            let s = piece.start_s + piece.length_m * k as f64 / 10.0;
            let derivative = (path.point_at(s + h) - path.point_at(s - h)) / (2.0 * h);
            assert_close(derivative, path.tangent_at(s), 1e-6, "tangent");
            assert!((path.tangent_at(s).norm() - 1.0).abs() < 1e-12);
            assert!(
                (path.point_at(s) - path.point_at(0.0))
                    .dot(&path.normal())
                    .abs()
                    < 1e-12
            );
        }
    }
    for pair in path.pieces().windows(2) {
        let (_, end, _) = pair[0].outline();
        let (start, _, _) = pair[1].outline();
        assert_close(end, start, 1e-9, "pieces join");
        assert!((pair[0].start_s + pair[0].length_m - pair[1].start_s).abs() < 1e-12);
    }
}

#[test]
fn a_rectangle_has_four_corners_and_its_perimeter_for_length() {
    let (p, d, n) = (Vec3::new(0.4, 0.0, 0.3), Vec3::y(), Vec3::z());
    let path = Path::new(rectangle(p, d, n, 0.2, 0.1, 0.0)).unwrap();
    assert!((path.length_m() - 0.6).abs() < 1e-12);
    assert_eq!(path.corners_m().collect::<Vec<_>>().len(), 3);
    assert_eq!(path.next_corner_m(0.0), Some(0.2));
    assert_eq!(path.next_corner_m(0.25), Some(0.3));
    assert_close(path.point_at(0.6), p, 1e-12, "closed");
    assert_parameterised(&path);
}

#[test]
fn blends_round_the_corners_tangentially_and_shorten_the_path() {
    let (p, d, n) = (Vec3::new(0.4, 0.0, 0.3), Vec3::y(), Vec3::z());
    let radius = 0.02;
    let path = Path::new(rectangle(p, d, n, 0.2, 0.1, radius)).unwrap();
    // Each right-angle corner trades 2r of straight for a quarter circle.
    let expected = 0.6 - 3.0 * (2.0 * radius - std::f64::consts::FRAC_PI_2 * radius);
    assert!(
        (path.length_m() - expected).abs() < 1e-12,
        "{}",
        path.length_m()
    );
    assert_eq!(path.corners_m().count(), 0);
    assert_eq!(path.pieces().len(), 7);
    assert_tangent_continuous(&path, "blended path");
    assert_parameterised(&path);
}

#[test]
fn corners_with_arcs_blend_tangentially_on_either_side() {
    let (p, n) = (Vec3::new(0.4, 0.0, 0.3), Vec3::z());
    let corner = p + Vec3::x() * 0.1;
    let shapes = [
        // A line into an arc turning away from the corner's turn (the blend outside the circle).
        vec![
            line(corner),
            arc(Some(corner + Vec3::x() * 0.05), None, None, Some(90.0)),
        ],
        // A line into an arc leaving 45° to the right and turning right on (the blend inside
        // the circle).
        vec![
            line(corner),
            arc(
                Some(corner - Vec3::new(1.0, 1.0, 0.0).normalize() * 0.05),
                None,
                None,
                Some(-120.0),
            ),
        ],
        // An arc into a line, and two arcs meeting at an angle.
        vec![
            arc(Some(p + Vec3::y() * 0.05), None, None, Some(90.0)),
            line(p + Vec3::new(0.05, 0.05, 0.0) + Vec3::new(-0.1, 0.0, 0.0)),
        ],
        vec![
            arc(Some(p + Vec3::y() * 0.05), None, None, Some(90.0)),
            arc(
                Some(p + Vec3::new(0.05, 0.05, 0.0) + Vec3::new(0.0, -0.06, 0.0)),
                None,
                None,
                Some(-150.0),
            ),
        ],
    ];
    for (index, segments) in shapes.into_iter().enumerate() {
        let plain = Path::new(spec(p, n, 0.0, segments.clone())).unwrap();
        let path = Path::new(spec(p, n, 0.01, segments)).unwrap();
        assert_eq!(plain.corners_m().count(), 1, "case {index} has a corner");
        assert_eq!(
            path.corners_m().count(),
            0,
            "case {index}: the blend leaves no corner"
        );
        assert_eq!(path.pieces().len(), 3, "case {index}");
        assert!(
            path.length_m() < plain.length_m(),
            "case {index}: a blend cuts the corner"
        );
        assert_tangent_continuous(&path, &format!("case {index}"));
        assert_parameterised(&path);
        // The blend stays within its radius's reach of the corner it rounds.
        let blend = &path.pieces()[1];
        let (start, end, Some(_)) = blend.outline() else {
            panic!("case {index}: the blend is an arc");
        };
        let join = plain.point_at(plain.corners_m().next().unwrap());
        for point in [start, end] {
            assert!(
                (point - join).norm() < 0.1,
                "case {index}: {point:?} far from {join:?}"
            );
        }
    }
}

#[test]
fn every_arc_form_lands_where_its_spec_says() {
    let (p, n) = (Vec3::new(0.5, 0.1, 0.2), Vec3::new(0.0, 0.0, 1.0));
    let centre = p + Vec3::new(0.0, 0.05, 0.0);
    let top = centre + Vec3::new(0.05, 0.0, 0.0);
    let opposite = centre + Vec3::new(0.0, 0.05, 0.0);
    // Centre and end: the shorter way round, a quarter circle.
    let quarter = Path::new(spec(
        p,
        n,
        0.0,
        vec![arc(Some(centre), None, Some(top), None)],
    ))
    .unwrap();
    assert!((quarter.length_m() - 0.05 * std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert_close(
        quarter.point_at(quarter.length_m()),
        top,
        1e-12,
        "quarter end",
    );
    // Through a point: the long way round the same circle (three quarters) via the opposite side.
    let long = Path::new(spec(
        p,
        n,
        0.0,
        vec![arc(None, Some(opposite), Some(top), None)],
    ))
    .unwrap();
    assert!((long.length_m() - 0.05 * 1.5 * std::f64::consts::PI).abs() < 1e-9);
    assert_close(long.point_at(long.length_m()), top, 1e-9, "through end");
    assert_close(
        long.point_at(long.length_m() * 2.0 / 3.0),
        opposite,
        1e-9,
        "passes through",
    );
    // A full circle by sweep, clockwise about n.
    let circle = Path::new(spec(
        p,
        n,
        0.0,
        vec![arc(Some(centre), None, None, Some(-360.0))],
    ))
    .unwrap();
    assert!((circle.length_m() - 0.1 * std::f64::consts::PI).abs() < 1e-12);
    assert_close(
        circle.point_at(circle.length_m()),
        p,
        1e-12,
        "closed circle",
    );
    let ahead = circle.tangent_at(0.0);
    assert_close(
        ahead,
        -Vec3::x(),
        1e-12,
        "clockwise about +z from -y of the centre",
    );
    for path in [&quarter, &long, &circle] {
        assert_parameterised(path);
    }
}

/// A full circle of radius 5 cm counter-clockwise about +z from `p`, its centre 5 cm along +y.
fn unit_circle() -> (Vec3, Vec3, Path) {
    let (p, n) = (Vec3::new(0.5, 0.1, 0.2), Vec3::z());
    let centre = p + Vec3::new(0.0, 0.05, 0.0);
    let circle = spec(p, n, 0.0, vec![arc(Some(centre), None, None, Some(360.0))]);
    (p, n, Path::new(circle).unwrap())
}

/// A closed path started elsewhere is the same curve from there round to there; an open one
/// has no other start.
#[test]
fn a_closed_path_may_start_anywhere_on_it() {
    let (p, n, circle) = unit_circle();
    assert!(circle.is_closed());
    let length = circle.length_m();
    let third = length / 3.0;
    let started = circle.started_at(third).expect("a closed path restarts");
    assert!((started.length_m() - length).abs() < 1e-9);
    for k in 0..=30 {
        let s = length * k as f64 / 30.0;
        let original = circle.point_at((s + third) % length);
        assert_close(started.point_at(s), original, 1e-9, "restarted point");
    }
    let open = Path::new(spec(p, n, 0.0, vec![line(p + Vec3::new(0.1, 0.0, 0.0))])).unwrap();
    assert!(!open.is_closed());
    assert!(open.started_at(0.05).is_none());
}

/// A whole circle's stretch, its reverse and its rigid motions are paths again, of its length,
/// whatever its radius (the sweep recomputed from the arc length may round past 360°).
#[test]
fn whole_circles_stretch_reverse_and_move_as_paths() {
    let motion = nalgebra::Isometry3::new(Vec3::new(0.1, -0.2, 0.05), Vec3::new(0.3, -0.2, 0.7));
    for k in 0..200 {
        let radius = 0.005 + 0.0013 * k as f64;
        let (p, n) = (Vec3::new(0.45, 0.0, 0.25), -Vec3::z());
        let centre = p - Vec3::new(radius, 0.0, 0.0);
        let circle = Path::new(spec(
            p,
            n,
            0.0,
            vec![arc(Some(centre), None, None, Some(360.0))],
        ))
        .unwrap();
        let length = circle.length_m();
        let whole = circle
            .stretch(0.0, length)
            .unwrap_or_else(|| panic!("radius {radius}: the whole circle is a stretch"));
        assert!((whole.length_m() - length).abs() < 1e-12, "radius {radius}");
        let back = circle.reversed().unwrap();
        assert!((back.length_m() - length).abs() < 1e-12, "radius {radius}");
        let moved = Path::new(circle.spec().moved(&motion)).unwrap();
        assert!((moved.length_m() - length).abs() < 1e-12, "radius {radius}");
        for s in [0.0, 0.3 * length, length] {
            assert_close(
                moved.point_at(s),
                (motion * nalgebra::Point3::from(circle.point_at(s))).coords,
                1e-12,
                "a moved point",
            );
        }
    }
}

/// Two paths joined are one path of both lengths: the first as it was, the second moved by the
/// gap between them (blends kept as arcs of their own); paths of other normals do not join.
#[test]
fn paths_join_end_to_start_moved_by_the_gap_between_them() {
    let (p, n) = (Vec3::new(0.4, 0.0, 0.3), Vec3::z());
    let first = Path::new(rectangle(p, Vec3::y(), n, 0.02, 0.01, 0.002)).unwrap();
    let gap = Vec3::new(3e-4, -2e-4, 0.0);
    let begin = first.point_at(first.length_m()) + gap;
    let second = Path::new(spec(
        begin,
        n,
        0.0,
        vec![
            arc(
                Some(begin + Vec3::new(0.0, 0.01, 0.0)),
                None,
                None,
                Some(90.0),
            ),
            line(begin + Vec3::new(0.03, 0.01, 0.0)),
        ],
    ))
    .unwrap();
    assert_close(
        second.point_at(0.0) - first.point_at(first.length_m()),
        gap,
        1e-12,
        "gap",
    );
    let joined = first.joined(&second).unwrap();
    assert_parameterised(&joined);
    assert!((joined.length_m() - first.length_m() - second.length_m()).abs() < 1e-12);
    for k in 0..=50 {
        let s = first.length_m() * k as f64 / 50.0;
        assert_close(
            joined.point_at(s),
            first.point_at(s),
            1e-12,
            "the first path",
        );
        let t = second.length_m() * k as f64 / 50.0;
        assert_close(
            joined.point_at(first.length_m() + t),
            second.point_at(t) - gap,
            1e-12,
            "the second path moved",
        );
    }
    let tilted = Path::straight(
        second.point_at(0.0),
        Vec3::x(),
        Vec3::new(0.0, 0.1, 1.0).normalize(),
        0.01,
    )
    .unwrap();
    assert!(first.joined(&tilted).is_none(), "another normal");
}

#[test]
fn a_tcp_is_located_near_where_it_was_last() {
    let (p, _, circle) = unit_circle();
    let length = circle.length_m();
    let near_start = p + Vec3::new(0.0, 0.001, 0.0);
    assert!(circle.locate(&near_start, 0.0, 0.05).s < 1e-12);
    assert!((circle.locate(&near_start, length - 0.01, 0.05).s - length).abs() < 1e-12);
    let quarter = circle.point_at(length / 4.0) + Vec3::new(0.003, 0.0, 0.0);
    let located = circle.locate(&quarter, length / 4.0 - 0.01, 0.05);
    assert!((located.s - length / 4.0).abs() < 1e-9, "{}", located.s);
    assert_close(
        located.point,
        circle.point_at(length / 4.0),
        1e-9,
        "nearest point",
    );
}

#[test]
fn a_tcp_on_a_path_of_many_pieces_is_located_at_the_least_cost_in_the_window() {
    use rand::{RngExt, SeedableRng};
    // A spiral of 2,000 short lines, 0.35 mm apart, each joint rounded by a blend arc.
    let (centre, n) = (Vec3::new(0.45, 0.0, 0.25), Vec3::z());
    let at = |i: usize| {
        let (turn, radius) = (i as f64 * 0.02, 0.01 + 1e-5 * i as f64);
        centre + Vec3::new(radius * libm::cos(turn), radius * libm::sin(turn), 0.0)
    };
    let segments = (1..2000).map(|i| line(at(i))).collect();
    let path = Path::new(spec(at(0), n, 1e-3, segments)).unwrap();
    let window = emg_control::TRACKING_WINDOW_M;
    let cost = |p: &Vec3, hint: f64, s: f64| {
        (path.point_at(s) - p).norm() + emg_control::PROGRESS_CONTINUITY * (s - hint).abs()
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    for _ in 0..100 {
        let hint = rng.random_range(0.0..path.length_m());
        let near = hint + rng.random_range(-0.02..0.02);
        let offset = Vec3::new(
            rng.random_range(-2e-3..2e-3),
            rng.random_range(-2e-3..2e-3),
            rng.random_range(-1e-3..1e-3),
        );
        let p = path.point_at(near) + offset;
        let located = path.locate(&p, hint, window);
        let found = cost(&p, hint, located.s);
        // The progress never goes back: no point of the window, from the hint on, sampled
        // every 10 µm, costs less (each piece offers its point nearest `p` and its ends, which
        // miss the least cost by about PROGRESS_CONTINUITY² / 2 of the distance).
        assert!(
            located.s >= hint,
            "located {} behind the hint {hint}",
            located.s
        );
        let (low, high) = (hint, (hint + window).min(path.length_m()));
        let samples = ((high - low) / 1e-5) as usize;
        for k in 0..=samples {
            let s = low + (high - low) * k as f64 / samples as f64;
            assert!(
                found <= cost(&p, hint, s) + 1e-4 * found + 1e-12,
                "located {} (cost {found}) but {s} costs {}",
                located.s,
                cost(&p, hint, s)
            );
        }
    }
}

#[test]
fn a_malformed_path_is_refused_naming_its_field() {
    let (p, n) = (Vec3::new(0.4, 0.0, 0.3), Vec3::z());
    let refused = |spec: PathSpec| match Path::new(spec) {
        Err(PathError::Field { field, problem }) => format!("{field}: {problem}"),
        other => panic!("expected a field error, got {other:?}"),
    };
    let message = refused(spec(
        p,
        n,
        0.0,
        vec![line(p + Vec3::x() * 0.1), line(p + Vec3::x() * 0.1)],
    ));
    assert!(
        message.starts_with("segments[1].line.to: makes a segment"),
        "{message}"
    );
    let message = refused(spec(p, n, 0.0, vec![line(p + Vec3::new(0.1, 0.0, 0.01))]));
    assert!(
        message.starts_with("segments[0].line.to: lies"),
        "{message}"
    );
    let message = refused(spec(p, n, 0.0, vec![]));
    assert!(message.starts_with("segments: is empty"), "{message}");
    let centre = p + Vec3::y() * 0.05;
    let message = refused(spec(
        p,
        n,
        0.0,
        vec![arc(
            Some(centre),
            None,
            Some(centre + Vec3::y() * 0.05),
            None,
        )],
    ));
    assert!(message.contains("ambiguous"), "{message}");
    let message = refused(spec(
        p,
        n,
        0.0,
        vec![arc(Some(centre), None, Some(p + Vec3::x()), None)],
    ));
    assert!(message.starts_with("segments[0].arc.to: lies"), "{message}");
    let message = refused(spec(p, n, 0.0, vec![arc(Some(centre), None, None, None)]));
    assert!(
        message.starts_with("segments[0].arc: an arc takes"),
        "{message}"
    );
    let message = refused(spec(
        p,
        n,
        0.0,
        vec![arc(
            None,
            Some(p + Vec3::x() * 0.1),
            Some(p + Vec3::x() * 0.2),
            None,
        )],
    ));
    assert!(message.contains("no circle passes"), "{message}");
    let message = refused(rectangle(p, Vec3::y(), n, 0.2, 0.1, 0.06));
    assert!(
        message.starts_with("blend_radius_m: is too large for segment 1"),
        "{message}"
    );
    let message = refused(spec(
        p,
        n,
        0.2,
        vec![
            line(p + Vec3::x() * 0.1),
            arc(Some(p + Vec3::new(0.15, 0.0, 0.0)), None, None, Some(90.0)),
        ],
    ));
    assert!(
        message.starts_with(
            "blend_radius_m: cannot round the corner between segments 0 and 1: the radius is too large"
        ),
        "{message}"
    );
    let mut wrong_version = spec(p, n, 0.0, vec![line(p + Vec3::x() * 0.1)]);
    wrong_version.version = 2;
    assert_eq!(
        Path::new(wrong_version),
        Err(PathError::Version { found: 2 })
    );
    let text = r#"{"version": 1, "start": [0.4, 0, 0.3], "normal": [0, 0, 1], "segments": [{"spline": {}}]}"#;
    assert!(serde_json::from_str::<Path>(text).is_err());
}

#[test]
fn a_path_round_trips_through_json() {
    let path = Path::new(rectangle(
        Vec3::new(0.4, 0.0, 0.3),
        Vec3::y(),
        Vec3::z(),
        0.2,
        0.1,
        0.01,
    ))
    .unwrap();
    let text = serde_json::to_string(&path).unwrap();
    assert_eq!(serde_json::from_str::<Path>(&text).unwrap(), path);
}

/// A sampled task's start and seed, with the rollout settings of the paper.
fn start() -> (emg_kinematics::Robot, Task) {
    let robot = robot();
    let (_, task) = tasks(&robot, 1).remove(0);
    (robot, task)
}

#[test]
fn a_one_segment_path_is_followed_as_its_line() {
    let (robot, task) = start();
    let config = RolloutConfig::default();
    let line_rollout = classical(&robot, &task, &config);
    let length = line_rollout.path_length_m.max(0.05) + 0.2;
    let path = Path::straight(task.p0, task.d, task.n, length).unwrap();
    let on_path = Task::on_path(&robot, path, task.q0_seed).unwrap();
    let path_rollout = classical(&robot, &on_path, &config);
    assert_eq!(path_rollout.steps.len(), line_rollout.steps.len());
    for (a, b) in path_rollout.steps.iter().zip(&line_rollout.steps) {
        assert!((a.q - b.q).amax() < 1e-9, "{:?} vs {:?}", a.q, b.q);
    }
    assert!((path_rollout.path_length_m - line_rollout.path_length_m).abs() < 1e-9);
    checker()
        .check(&on_path, &path_rollout, &config.constraints)
        .unwrap();
}

#[test]
fn the_classical_controller_follows_a_rectangle_and_a_circle_checked_independently() {
    let (robot, task) = start();
    let config = RolloutConfig::default();
    let (p, d, n) = (task.p0, task.d, task.n);
    let e = n.cross(&d);
    let shapes = [
        rectangle(p, d, n, 0.06, 0.04, 0.0),
        rectangle(p, d, n, 0.06, 0.04, 0.01),
        spec(
            p,
            n,
            0.0,
            vec![arc(Some(p + e * 0.03), None, None, Some(360.0))],
        ),
    ];
    for shape in shapes {
        let path = Path::new(shape).unwrap();
        let corners: Vec<f64> = path.corners_m().collect();
        let length = path.length_m();
        let path_task = Task::on_path(&robot, path, task.q0_seed).unwrap();
        let trajectory = classical(&robot, &path_task, &config);
        checker()
            .check(&path_task, &trajectory, &config.constraints)
            .unwrap();
        assert_eq!(
            trajectory.termination,
            Termination::Completed,
            "{length} m path"
        );
        assert!((trajectory.path_length_m - length).abs() < 2e-4);
        // The tool comes to each corner and turns there.
        for corner in corners {
            let point = path_task.path.as_ref().unwrap().point_at(corner);
            let nearest = trajectory
                .steps
                .iter()
                .map(|step| (step.tcp - point).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest < 1e-3,
                "corner at {corner} m passed {nearest} m away"
            );
        }
    }
}

#[test]
fn the_checker_refuses_a_path_rollout_checked_against_another_path_or_a_false_ending() {
    let (robot, task) = start();
    let config = RolloutConfig::default();
    let (p, d, n) = (task.p0, task.d, task.n);
    let path_task = Task::on_path(
        &robot,
        Path::new(rectangle(p, d, n, 0.06, 0.04, 0.0)).unwrap(),
        task.q0_seed,
    )
    .unwrap();
    let trajectory = classical(&robot, &path_task, &config);
    checker()
        .check(&path_task, &trajectory, &config.constraints)
        .unwrap();
    // The same motion against the rectangle drawn the other way from the same start leaves it.
    let mirrored = Task::on_path(
        &robot,
        Path::new(rectangle(p, -d, n, 0.06, 0.04, 0.0)).unwrap(),
        task.q0_seed,
    )
    .unwrap();
    let failure = checker()
        .check(&mirrored, &trajectory, &config.constraints)
        .unwrap_err();
    assert!(format!("{failure}").contains("off the line"), "{failure}");
    // Claiming the end of the path after only part of it.
    let mut short = trajectory.clone();
    short.steps.truncate(10);
    let located: f64 = {
        let mut s = 0.0;
        for step in &short.steps {
            s = path_task.along(&step.tcp, s).s_m;
        }
        s
    };
    short.path_length_m = located;
    let failure = checker()
        .check(&path_task, &short, &config.constraints)
        .unwrap_err();
    assert!(
        format!("{failure}").contains("claims the end of the path"),
        "{failure}"
    );
}

#[test]
fn a_work_plate_covers_a_path_with_its_margins_and_no_more() {
    use emg_kinematics::{Plate, WorkSurface};
    let (robot, task) = start();
    let plate = WorkSurface::Plate(Plate::default());
    let WorkSurface::Plate(on_line) = task.work_surface(&plate) else {
        panic!("a plate stays a plate");
    };
    assert_eq!(
        Plate {
            ahead_m: Plate::default().ahead_m,
            ..on_line
        },
        Plate::default(),
        "on a line only the plate's reach ahead may change"
    );
    let (p, d, n) = (task.p0, task.d, task.n);
    let path = Path::new(rectangle(p, d, n, 0.3, 0.15, 0.0)).unwrap();
    let extent = path.extent();
    assert!((extent.ahead_m - 0.3).abs() < 1e-12 && extent.behind_m.abs() < 1e-12);
    assert!((extent.across_m - 0.15).abs() < 1e-12);
    let on_path = Task::on_path(&robot, path, None).unwrap();
    let WorkSurface::Plate(grown) = on_path.work_surface(&plate) else {
        panic!("a plate stays a plate");
    };
    let default = Plate::default();
    assert!((grown.half_width_m - (default.half_width_m + 0.15)).abs() < 1e-12);
    assert!((grown.behind_m - default.behind_m).abs() < 1e-12);
    assert!(
        (grown.ahead_m - (0.3 + default.behind_m)).abs() < 1e-12,
        "the plate ends its margin beyond the path, not a line's reach beyond: {grown:?}"
    );
    // A circle of radius 0.1 m whose start tangent is across `d`: it reaches 0.1 m behind its
    // start and 0.2 m to one side, in the frame of that tangent.
    let circle = spec(
        p,
        n,
        0.0,
        vec![arc(Some(p - d * 0.1), None, None, Some(360.0))],
    );
    let on_circle = Task::on_path(&robot, Path::new(circle).unwrap(), None).unwrap();
    let WorkSurface::Plate(grown) = on_circle.work_surface(&plate) else {
        panic!("a plate stays a plate");
    };
    assert!(
        (grown.behind_m - (default.behind_m + 0.1)).abs() < 1e-12,
        "{grown:?}"
    );
    assert!(
        (grown.half_width_m - (default.half_width_m + 0.2)).abs() < 1e-12,
        "{grown:?}"
    );
    assert!(
        (grown.ahead_m - (0.1 + default.behind_m)).abs() < 1e-12,
        "{grown:?}"
    );
}

#[test]
fn the_path_population_takes_each_shape_in_turn_from_its_anchors_start_along_d() {
    use emg_control::{PathShape, path_tasks};
    let robot = robot();
    let anchors: Vec<Task> = tasks(&robot, 8).into_iter().map(|(_, task)| task).collect();
    let population = path_tasks(&robot, &anchors, 7).unwrap();
    assert_eq!(
        population,
        path_tasks(&robot, &anchors, 7).unwrap(),
        "deterministic"
    );
    assert_ne!(
        population,
        path_tasks(&robot, &anchors, 8).unwrap(),
        "seeded"
    );
    for (index, ((shape, task), anchor)) in population.iter().zip(&anchors).enumerate() {
        assert_eq!(*shape, PathShape::ALL[index % 4]);
        let path = task.path.as_ref().unwrap();
        assert_close(path.point_at(0.0), anchor.p0, 1e-12, "starts at the anchor");
        assert_close(path.tangent_at(0.0), anchor.d, 1e-9, "leaves along d");
        assert_eq!(task.q0_seed, anchor.q0_seed);
        assert_parameterised(path);
        let ends_at_start = (path.point_at(path.length_m()) - anchor.p0).norm() < 1e-9;
        match shape {
            PathShape::Rectangle => {
                assert_eq!(path.corners_m().count(), 3);
                assert!(ends_at_start);
            }
            PathShape::Circle => {
                assert!(ends_at_start);
                assert!(path.length_m() > 2.0 * std::f64::consts::PI * 0.03 - 1e-9);
            }
            PathShape::Arc | PathShape::SCurve => {
                assert_eq!(path.corners_m().count(), 0, "smooth");
                assert!(!ends_at_start);
            }
        }
    }
}

#[test]
fn a_point_just_before_a_full_circles_start_is_located_at_its_start_and_checked_so() {
    let (p, n, circle) = unit_circle();
    // Counter-clockwise about +z from -y of the centre the circle leaves along +x: a point a
    // hair towards -x lies at an angle just below zero.
    let before = p - Vec3::x() * 1e-9;
    let located = circle.locate(&before, 0.0, 0.05);
    assert!(located.s < 1e-6, "{}", located.s);
    let line = emg_verify::Line {
        p0: p,
        d: circle.tangent_at(0.0),
        n,
        path: vec![emg_verify::PathPiece::Arc {
            centre: p + Vec3::new(0.0, 0.05, 0.0),
            start: p,
            axis: n,
            sweep_rad: 2.0 * std::f64::consts::PI,
        }],
    };
    assert!(line.reached([before]) < 1e-6);
    assert!(line.distance(&before) < 1e-8);
}

/// The tangent of `path` is continuous where each piece meets the next.
fn assert_tangent_continuous(path: &Path, what: &str) {
    for pair in path.pieces().windows(2) {
        let s = pair[1].start_s;
        assert_close(
            path.tangent_at(s - 1e-9),
            path.tangent_at(s),
            1e-6,
            &format!("{what}: tangent continuity"),
        );
    }
}

/// The start and the end of a closed stroke shorter than the tracking window are the same
/// point: a TCP standing there (to rounding, or a little off the path) is located near the start
/// before it moves and near the end once it has come round, never the other way.
#[test]
fn the_ends_of_a_short_closed_stroke_are_told_apart_by_where_the_tcp_came_from() {
    let (p, n) = (Vec3::new(0.45, 0.25, 0.25), -Vec3::z());
    let radius = 0.0075;
    let circle = spec(
        p,
        n,
        0.0,
        vec![arc(Some(p + Vec3::x() * radius), None, None, Some(360.0))],
    );
    let square = rectangle(p, Vec3::y(), n, 0.012, 0.01, 0.0);
    for spec in [circle, square] {
        let forward = Path::new(spec).unwrap();
        for path in [forward.reversed().unwrap(), forward] {
            let length = path.length_m();
            assert!(length < emg_control::TRACKING_WINDOW_M, "{length}");
            let start = path.point_at(0.0);
            let normal = path.normal();
            let across = normal.cross(&path.tangent_at(0.0));
            for offset in [
                Vec3::zeros(),
                Vec3::new(1e-13, -1e-13, 1e-13),
                Vec3::new(-1e-12, 1e-12, 0.0),
                across * 3e-4,
                -across * 3e-4,
                normal * 2e-4,
            ] {
                let tcp = start + offset;
                let at_start = path.locate(&tcp, 0.0, emg_control::TRACKING_WINDOW_M);
                assert!(at_start.s < 1e-3, "{offset:?}: {} of {length}", at_start.s);
                let came_round = path.locate(&tcp, length - 0.002, emg_control::TRACKING_WINDOW_M);
                assert!(
                    came_round.s > length - 1e-3,
                    "{offset:?}: {} of {length}",
                    came_round.s
                );
            }
        }
    }
}

#[test]
fn the_nearest_point_of_a_long_path_is_the_nearest_of_all_its_points() {
    // A zigzag of 600 lines with blended corners and arcs, doubling back near itself.
    let n = Vec3::new(0.0, 0.0, -1.0);
    let mut segments = Vec::new();
    for k in 1..=600 {
        let x = 0.002 * k as f64;
        let y = if k % 2 == 0 { 0.0 } else { 0.01 };
        segments.push(if k % 7 == 0 {
            arc(
                None,
                Some(Vec3::new(x - 0.001, y + 0.002, 0.0)),
                Some(Vec3::new(x, y, 0.0)),
                None,
            )
        } else {
            line(Vec3::new(x, y, 0.0))
        });
    }
    let path = Path::new(spec(Vec3::zeros(), n, 0.0005, segments)).expect("a zigzag");
    // Its points every 20 µm of arc length, and its end.
    let samples: Vec<Vec3> = (0..=(path.length_m() / 2e-5) as usize)
        .map(|k| path.point_at(k as f64 * 2e-5))
        .chain([path.point_at(path.length_m())])
        .collect();
    for k in 0..300 {
        let p = Vec3::new(
            ((k as f64 * 0.618_034).fract() - 0.1) * 1.5,
            ((k as f64 * 0.754_878).fract() - 0.5) * 0.05,
            ((k as f64 * 0.569_840).fract() - 0.5) * 0.02,
        );
        let nearest = path.nearest_point(&p);
        let found = (nearest.point - p).norm();
        let least = samples
            .iter()
            .map(|q| (q - p).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(
            found <= least + 1e-12 && found >= least - 1e-5,
            "{p:?}: found {found}, the samples come within {least}"
        );
        assert_close(
            nearest.point,
            path.point_at(nearest.s),
            1e-12,
            "the point at its s",
        );
    }
}
