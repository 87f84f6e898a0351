//! The order stage at scale and its merging:
//!
//! - random short strokes (the large jobs' drawing) are ordered with work, counted, that grows
//!   near-linearly with the strokes, every stroke drawn once and the travel a fraction of the
//!   given order's;
//! - strokes that meet end to end within the tolerance, listed out of order and either way
//!   round, are merged into strokes that draw the same geometry: every point of the job's
//!   strokes within the tolerance of the stroke drawn, the lengths summed.

mod common;

use emg_control::{PATH_FORMAT_VERSION, Path, PathSpec, SegmentSpec};
use emg_job::order::{Ordering, merge_and_order, order_strokes_counted};
use emg_job::{JOB_TOLERANCE_M, Job, JobSettings, Order, verify_job};
use emg_kinematics::Vec3;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The plane the strokes lie on: its height (m) and normal.
const Z_M: f64 = 0.2;
const NORMAL: [f64; 3] = [0.0, 0.0, -1.0];

/// The straight stroke from `from` to `to`.
fn line(from: Vec3, to: Vec3) -> Path {
    Path::new(PathSpec {
        version: PATH_FORMAT_VERSION,
        start: from.into(),
        normal: NORMAL,
        blend_radius_m: 0.0,
        segments: vec![SegmentSpec::Line { to: to.into() }],
    })
    .expect("a straight stroke")
}

/// `count` straight strokes 3–12 mm long in random directions, starting at random in a 0.2 m
/// square (x from 0.3 m, y from −0.1 m) on the plane z = 0.2 m, from `seed`: the drawing of the
/// large jobs (issue 65).
pub fn random_strokes(count: usize, seed: u64) -> Vec<Path> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            let from = Vec3::new(
                0.3 + 0.2 * rng.random::<f64>(),
                -0.1 + 0.2 * rng.random::<f64>(),
                Z_M,
            );
            let length = 0.003 + 0.009 * rng.random::<f64>();
            let angle = std::f64::consts::TAU * rng.random::<f64>();
            line(
                from,
                from + Vec3::new(libm::cos(angle), libm::sin(angle), 0.0) * length,
            )
        })
        .collect()
}

/// Each drawn stroke once in the sequence.
fn assert_each_drawn_once(ordering: &Ordering) {
    let mut seen = vec![false; ordering.drawn.len()];
    for oriented in &ordering.sequence {
        assert!(!seen[oriented.stroke], "stroke {} twice", oriented.stroke);
        seen[oriented.stroke] = true;
    }
    assert!(
        seen.iter().all(|&s| s),
        "every drawn stroke in the sequence"
    );
}

#[test]
fn ordering_work_grows_near_linearly_with_the_strokes() {
    let mut before: Option<(usize, usize)> = None;
    for count in [500, 2000, 8000] {
        let strokes = random_strokes(count, 65);
        let (ordering, work) =
            order_strokes_counted(&strokes, Order::Shortest, Some(JOB_TOLERANCE_M));
        assert_each_drawn_once(&ordering);
        // The given order travels about a third of the square per stroke; the chosen one a few
        // millimetres.
        assert!(
            ordering.travel_m < ordering.travel_given_m / 20.0,
            "{count} strokes: {} m of {} m",
            ordering.travel_m,
            ordering.travel_given_m
        );
        println!(
            "{count} strokes: work {work} ({:.0} a stroke), travel {:.3} m of {:.3} m given, \
             {} drawn",
            work as f64 / count as f64,
            ordering.travel_m,
            ordering.travel_given_m,
            ordering.drawn.len()
        );
        if let Some((fewer, work_before)) = before {
            let strokes_ratio = count as f64 / fewer as f64;
            let work_ratio = work as f64 / work_before as f64;
            assert!(
                work_ratio < 1.5 * strokes_ratio,
                "{fewer} → {count} strokes: the work grows {work_ratio:.2}×"
            );
        }
        before = Some((count, work));
    }
}

/// Zigzag polylines, far apart, each cut into straight strokes that meet end to end or leave
/// gaps of up to a quarter of the tolerance, some turned round; with the strokes of each.
fn cut_polylines(rng: &mut ChaCha8Rng) -> (Vec<Path>, Vec<Vec<usize>>) {
    let mut strokes = Vec::new();
    let mut polylines = Vec::new();
    for row in 0..6 {
        for column in 0..6 {
            let origin = Vec3::new(0.3 + 0.03 * column as f64, -0.1 + 0.03 * row as f64, Z_M);
            let pieces = rng.random_range(1..=5);
            let mut members = Vec::new();
            let mut at = origin;
            for k in 0..pieces {
                let to = origin
                    + Vec3::new(
                        0.004 * (k + 1) as f64,
                        if k % 2 == 0 { 0.003 } else { 0.0 },
                        0.0,
                    );
                let stroke = if rng.random_bool(0.3) {
                    line(to, at)
                } else {
                    line(at, to)
                };
                members.push(strokes.len());
                strokes.push(stroke);
                let gap = if rng.random_bool(0.5) {
                    0.0
                } else {
                    0.25 * JOB_TOLERANCE_M * rng.random::<f64>()
                };
                at = to + Vec3::new(0.0, gap, 0.0);
            }
            polylines.push(members);
        }
    }
    (strokes, polylines)
}

/// Every point of `stroke` lies within `tolerance_m` of `drawn`.
fn assert_on(stroke: &Path, drawn: &Path, tolerance_m: f64) {
    for k in 0..=20 {
        let p = stroke.point_at(stroke.length_m() * k as f64 / 20.0);
        let off = (drawn.nearest_point(&p).point - p).norm();
        assert!(off <= tolerance_m + 1e-12, "a point {off:.2e} m off");
    }
}

#[test]
fn strokes_that_meet_end_to_end_are_merged_into_strokes_that_draw_the_same() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let (strokes, polylines) = cut_polylines(&mut rng);
    // Listed out of order.
    let mut shuffle: Vec<usize> = (0..strokes.len()).collect();
    shuffle.shuffle(&mut rng);
    let listed: Vec<Path> = shuffle.iter().map(|&i| strokes[i].clone()).collect();
    let ordering = merge_and_order(&listed, Order::Shortest, JOB_TOLERANCE_M);
    assert_each_drawn_once(&ordering);
    // Each polyline drawn as one stroke.
    assert_eq!(ordering.drawn.len(), polylines.len());
    let several = polylines.iter().filter(|p| p.len() > 1).count();
    let in_several: usize = polylines.iter().filter(|p| p.len() > 1).map(Vec::len).sum();
    assert_eq!(ordering.merged(), (in_several, several));
    let drawn = ordering.drawn_paths(&listed);
    let mut used = vec![false; listed.len()];
    for (chain, path) in ordering.drawn.iter().zip(&drawn) {
        let length: f64 = chain.0.iter().map(|o| listed[o.stroke].length_m()).sum();
        assert!((path.length_m() - length).abs() < 1e-9);
        for oriented in &chain.0 {
            assert!(
                !used[oriented.stroke],
                "stroke {} merged twice",
                oriented.stroke
            );
            used[oriented.stroke] = true;
            assert_on(&listed[oriented.stroke], path, JOB_TOLERANCE_M);
        }
    }
    assert!(used.iter().all(|&u| u), "every stroke drawn");
    // Drawn one after another, the polylines' strokes need no travel between them.
    let alone = order_strokes_counted(&listed, Order::Shortest, None).0;
    assert!(ordering.travel_m < alone.travel_m);
}

#[test]
fn strokes_that_merge_with_none_keep_their_direction() {
    // A closed square (its end on its start) and a line apart: neither merges, and neither is
    // turned round (a stroke's direction decides how far the arm draws it).
    let corner = |x: f64, y: f64| Vec3::new(0.45 + x, y, 0.25);
    let square = [
        (0.0, 0.0),
        (0.03, 0.0),
        (0.03, 0.03),
        (0.0, 0.03),
        (0.0, 0.0),
    ];
    let closed = Path::new(PathSpec {
        version: PATH_FORMAT_VERSION,
        start: corner(0.0, 0.0).into(),
        normal: NORMAL,
        blend_radius_m: 0.0,
        segments: square[1..]
            .iter()
            .map(|&(x, y)| SegmentSpec::Line {
                to: corner(x, y).into(),
            })
            .collect(),
    })
    .expect("a valid square");
    let strokes = vec![closed, line(corner(0.0, 0.1), corner(0.03, 0.1))];
    let ordering = merge_and_order(&strokes, Order::Shortest, JOB_TOLERANCE_M);
    assert_eq!(ordering.merged(), (0, 0));
    for chain in &ordering.drawn {
        assert!(chain.0.iter().all(|o| !o.reversed), "{:?}", ordering.drawn);
    }
}

#[test]
fn in_the_given_order_a_stroke_merges_only_with_the_one_listed_before_it() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let (strokes, _) = cut_polylines(&mut rng);
    let ordering = merge_and_order(&strokes, Order::Given, JOB_TOLERANCE_M);
    assert_each_drawn_once(&ordering);
    let drawn = ordering.drawn_paths(&strokes);
    let mut next = 0;
    for (index, (chain, path)) in ordering.drawn.iter().zip(&drawn).enumerate() {
        assert_eq!(ordering.sequence[index].stroke, index, "as listed");
        for oriented in &chain.0 {
            assert_eq!(oriented.stroke, next, "listed order, each once");
            assert!(!oriented.reversed, "each in its own direction");
            next += 1;
            assert_on(&strokes[oriented.stroke], path, JOB_TOLERANCE_M);
        }
        for pair in chain.0.windows(2) {
            let (before, after) = (&strokes[pair[0].stroke], &strokes[pair[1].stroke]);
            let gap = (after.point_at(0.0) - before.point_at(before.length_m())).norm();
            assert!(gap <= JOB_TOLERANCE_M);
        }
    }
    assert_eq!(next, strokes.len());
    assert!(ordering.drawn.len() < strokes.len(), "some strokes merged");
}

#[test]
fn a_job_of_strokes_that_merge_is_planned_as_the_merged_strokes_and_checks() {
    let (planner, timing, checker, file) = common::setup("fr3");
    // A 3 cm square drawn as four strokes, two of them turned round, the last a tenth of the
    // tolerance short of the first's start; and a stroke apart.
    let corner = |x: f64, y: f64| Vec3::new(0.45 + x, y, 0.25);
    let gap = Vec3::new(0.0, 0.1 * JOB_TOLERANCE_M, 0.0);
    let strokes = vec![
        line(corner(0.0, 0.0), corner(0.03, 0.0)),
        line(corner(0.03, 0.03), corner(0.03, 0.0)),
        line(corner(0.03, 0.03), corner(0.0, 0.03)),
        line(corner(0.0, 0.0) + gap, corner(0.0, 0.03)),
        line(corner(0.0, 0.05), corner(0.03, 0.05)),
    ];
    let total_m: f64 = strokes.iter().map(Path::length_m).sum();
    let job = Job {
        strokes,
        settings: JobSettings::default(),
        home: None,
    };
    let program = common::plan(&planner, &timing, &file, &job);
    assert_eq!(program.ordering.merged(), (4, 1));
    assert_eq!(program.strokes.len(), 2);
    let check = verify_job(&program, &checker, planner.robot().joint_names())
        .unwrap_or_else(|e| panic!("{e}"));
    assert!((check.drawn_m - program.summary.drawn_m).abs() < 1e-6);
    assert!((program.summary.total_m - total_m).abs() < 1e-9);
    assert!(
        program.summary.drawn_m > total_m - 1e-3,
        "{:?}",
        program.summary
    );
}
