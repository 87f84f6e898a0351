//! Capsule self-collision: `segment_distance` against known answers and dense-grid brute force
//! (random, parallel, anti-parallel, collinear, crossing and degenerate segments); the shipped
//! capsules and the checked pairs (exactly the pairs ≥ 3 chain links apart on different
//! segments); home is collision-free; a folded colliding configuration whose clearance agrees
//! with an independent computation; and `first_collision`/`min_clearance` against an
//! exhaustive independent check on random configurations (which exercises the bounding-sphere
//! shortcut and the clearance floors), also beyond the joint limits, where the floors do not
//! hold, and on an arm whose only capsule on one body is a point (a sphere of radius 0).

mod common;

use common::{home, random_point, random_q, random_unit, rng, robot};
use emg_kinematics::{Capsule, Kinematics, Robot, Vec3, segment_distance};
use rand::RngExt;

/// Minimum over a (n+1)×(n+1) grid of points on both segments.
fn brute_force_distance(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3, n: usize) -> f64 {
    let mut best = f64::INFINITY;
    let qs: Vec<Vec3> = (0..=n)
        .map(|j| q0 + (q1 - q0) * (j as f64 / n as f64))
        .collect();
    for i in 0..=n {
        let p = p0 + (p1 - p0) * (i as f64 / n as f64);
        for q in &qs {
            best = best.min((p - q).norm_squared());
        }
    }
    best.sqrt()
}

#[test]
fn segment_distance_known_answers() {
    let v = Vec3::new;
    let cases = [
        // Skew perpendicular segments, closest points interior.
        (
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(0.5, -1.0, 1.0),
            v(0.5, 1.0, 1.0),
            1.0,
        ),
        // Parallel, offset and not overlapping along their direction.
        (
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(2.0, 1.0, 0.0),
            v(3.0, 1.0, 0.0),
            2.0f64.sqrt(),
        ),
        // Parallel and overlapping.
        (
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(0.5, 0.3, 0.0),
            v(1.5, 0.3, 0.0),
            0.3,
        ),
        // Anti-parallel and overlapping.
        (
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(1.5, 0.0, 0.4),
            v(0.2, 0.0, 0.4),
            0.4,
        ),
        // Collinear with a gap.
        (
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(1.25, 0.0, 0.0),
            v(2.0, 0.0, 0.0),
            0.25,
        ),
        // Crossing.
        (
            v(-1.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(0.0, -1.0, 0.0),
            v(0.0, 1.0, 0.0),
            0.0,
        ),
        // Point to point, point to segment (both orders), end point to end point.
        (
            v(0.0, 0.0, 0.0),
            v(0.0, 0.0, 0.0),
            v(3.0, 4.0, 0.0),
            v(3.0, 4.0, 0.0),
            5.0,
        ),
        (
            v(0.5, 2.0, 0.0),
            v(0.5, 2.0, 0.0),
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            2.0,
        ),
        (
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(-3.0, 4.0, 0.0),
            v(-3.0, 4.0, 0.0),
            5.0,
        ),
        (
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(1.0, 1.0, 1.0),
            v(1.0, 5.0, 5.0),
            2.0f64.sqrt(),
        ),
    ];
    for (p0, p1, q0, q1, expected) in cases {
        for (a0, a1, b0, b1) in [(p0, p1, q0, q1), (q0, q1, p0, p1), (p1, p0, q1, q0)] {
            let d = segment_distance(&a0, &a1, &b0, &b1);
            assert!(
                (d - expected).abs() < 1e-12,
                "{a0:?}-{a1:?} vs {b0:?}-{b1:?}: {d} != {expected}"
            );
        }
    }
}

#[test]
fn segment_distance_matches_brute_force() {
    let mut rng = rng(50);
    let grid = 500;
    let (mut worst, mut worst_below) = (0.0f64, 0.0f64);
    for case in 0..300 {
        // Segments of length ≤ 0.5, so the grid spacing is ≤ 1e-3.
        let p0 = random_point(&mut rng, 0.5);
        let dir_p = random_unit(&mut rng) * rng.random_range(0.0..0.5);
        let (q0, dir_q) = match case % 6 {
            // General position.
            0 | 1 => (
                random_point(&mut rng, 0.5),
                random_unit(&mut rng) * rng.random_range(0.0..0.5),
            ),
            // Parallel / anti-parallel (exactly), random offset.
            2 => (
                p0 + random_point(&mut rng, 0.3),
                dir_p * rng.random_range(-1.0..1.0),
            ),
            // Nearly parallel.
            3 => (
                p0 + random_point(&mut rng, 0.3),
                dir_p * 0.8 + random_point(&mut rng, 1e-6),
            ),
            // Degenerate second segment (a point).
            4 => (random_point(&mut rng, 0.5), Vec3::zeros()),
            // Collinear, possibly overlapping.
            _ => (
                p0 + dir_p * rng.random_range(-1.5..1.5),
                dir_p * rng.random_range(-1.0..1.0),
            ),
        };
        let (p1, q1) = (p0 + dir_p, q0 + dir_q);
        // Also the first segment degenerate every so often.
        let p1 = if case % 10 == 9 { p0 } else { p1 };
        let exact = segment_distance(&p0, &p1, &q0, &q1);
        let brute = brute_force_distance(&p0, &p1, &q0, &q1, grid);
        worst = worst.max((exact - brute).abs());
        // The grid can only overestimate the true minimum.
        worst_below = worst_below.max(exact - brute);
        let swapped = segment_distance(&q0, &q1, &p0, &p1);
        assert!(
            (swapped - exact).abs() < 1e-12,
            "distance must be symmetric"
        );
    }
    println!(
        "segment_distance vs {grid}-point grid: worst |difference| {worst:.3e}, worst excess over grid {worst_below:.3e}"
    );
    assert!(
        worst_below < 1e-12,
        "segment_distance exceeds a sampled distance by {worst_below:e}"
    );
    assert!(
        worst < 1e-3,
        "segment_distance differs from brute force by {worst:e}"
    );
}

#[test]
fn shipped_capsules_and_checked_pairs() {
    let robot = robot();
    let capsules = robot.capsules();
    // 12 capsules of the official description plus the pen.
    assert_eq!(capsules.len(), 13);
    let count = |link: &str| capsules.iter().filter(|c| c.link == link).count();
    for (link, n) in [
        ("link0", 1),
        ("link1", 1),
        ("link5", 2),
        ("link7", 2),
        ("hand", 2),
        ("pen_tip", 1),
    ] {
        assert_eq!(count(link), n, "capsules on {link}");
    }
    // Bodies after the last joint (flange, hand, pen) move with segment 7.
    for c in capsules {
        let expected_segment = c.chain_index.min(7);
        assert_eq!(
            c.segment, expected_segment,
            "segment of a {} capsule",
            c.link
        );
        assert!(c.radius > 0.0);
    }
    let pairs = robot.collision_pairs();
    assert!(!pairs.is_empty());
    for pair in pairs {
        assert!(pair.first < pair.second);
        let (a, b) = (&capsules[pair.first], &capsules[pair.second]);
        assert!(
            a.chain_index.abs_diff(b.chain_index) >= 3,
            "{} vs {} are too close in the chain",
            a.link,
            b.link
        );
        assert_ne!(
            a.segment, b.segment,
            "{} and {} move together",
            a.link, b.link
        );
    }
    // ... and every such pair is checked.
    for i in 0..capsules.len() {
        for j in i + 1..capsules.len() {
            let (a, b) = (&capsules[i], &capsules[j]);
            if a.chain_index.abs_diff(b.chain_index) >= 3 && a.segment != b.segment {
                assert!(
                    pairs.iter().any(|p| p.first == i && p.second == j),
                    "missing pair {} / {}",
                    a.link,
                    b.link
                );
            }
        }
    }
    // The pen capsule ends at the TCP and runs 0.1 m back along the tool axis.
    let kin = robot.forward(&home());
    let pen = capsules
        .iter()
        .find(|c| c.link == "pen_tip")
        .expect("pen capsule");
    let ends = world_ends(&kin, pen);
    let (tip, back) = if (ends[0] - kin.tcp()).norm() < (ends[1] - kin.tcp()).norm() {
        (ends[0], ends[1])
    } else {
        (ends[1], ends[0])
    };
    assert!((tip - kin.tcp()).norm() < 1e-12);
    assert!((back - (kin.tcp() - kin.tool_axis() * 0.1)).norm() < 1e-12);
}

/// World end points of a capsule via the segment's isometry (not `segment_point`).
fn world_ends(kin: &Kinematics, c: &Capsule) -> [Vec3; 2] {
    let frame = kin.segment_frame(c.segment);
    [
        (frame * nalgebra::Point3::from(c.start)).coords,
        (frame * nalgebra::Point3::from(c.end)).coords,
    ]
}

/// Independent clearance of every checked pair, in pair order.
fn all_clearances(robot: &Robot, kin: &Kinematics) -> Vec<f64> {
    robot
        .collision_pairs()
        .iter()
        .map(|p| {
            let (a, b) = (&robot.capsules()[p.first], &robot.capsules()[p.second]);
            let (ea, eb) = (world_ends(kin, a), world_ends(kin, b));
            segment_distance(&ea[0], &ea[1], &eb[0], &eb[1]) - a.radius - b.radius
        })
        .collect()
}

#[test]
fn home_is_collision_free() {
    let robot = robot();
    let kin = robot.forward(&home());
    assert!(robot.first_collision(&kin, 0.0).is_none());
    let min = robot.min_clearance(&kin).expect("pairs exist");
    let independent = all_clearances(&robot, &kin)
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    println!("home: minimum clearance {:.4} m", min.clearance);
    assert!(min.clearance > 0.0);
    assert!((min.clearance - independent).abs() < 1e-12);
}

#[test]
fn folded_configuration_collides_with_the_right_clearance() {
    let robot = robot();
    let mut rng = rng(51);
    let mut found = None;
    for _ in 0..100_000 {
        let q = random_q(&mut rng, &robot);
        let kin = robot.forward(&q);
        if let Some(hit) = robot.first_collision(&kin, 0.0) {
            found = Some((q, kin, hit));
            break;
        }
    }
    let (q, kin, hit) = found.expect("some random configuration self-collides");
    let (a, b) = (
        &robot.capsules()[hit.pair.first],
        &robot.capsules()[hit.pair.second],
    );
    let (ea, eb) = (world_ends(&kin, a), world_ends(&kin, b));
    let independent = segment_distance(&ea[0], &ea[1], &eb[0], &eb[1]) - a.radius - b.radius;
    println!(
        "folded q = {:?}: {} vs {} clearance {:.4} m (independent {:.4})",
        q.as_slice(),
        a.link,
        b.link,
        hit.clearance,
        independent
    );
    assert!(hit.clearance < 0.0, "a collision has negative clearance");
    assert!((hit.clearance - independent).abs() < 1e-12);
    // Every pair before the reported one is clear.
    let clearances = all_clearances(&robot, &kin);
    let index = robot
        .collision_pairs()
        .iter()
        .position(|p| *p == hit.pair)
        .expect("pair is checked");
    assert!(clearances[..index].iter().all(|&c| c >= 0.0));
}

#[test]
fn first_collision_and_min_clearance_match_an_exhaustive_check() {
    let robot = robot();
    let mut rng = rng(52);
    let (mut colliding, mut worst) = (0, 0.0f64);
    for case in 0..2000 {
        let q = random_q(&mut rng, &robot);
        let kin = robot.forward(&q);
        let clearances = all_clearances(&robot, &kin);
        let margin = [0.0, 0.02, 0.1][case % 3];
        let expected = clearances.iter().position(|&c| c < margin);
        let hit = robot.first_collision(&kin, margin);
        assert_eq!(
            hit.map(|h| h.pair),
            expected.map(|i| robot.collision_pairs()[i]),
            "margin {margin}, q {q:?}"
        );
        if let (Some(hit), Some(i)) = (hit, expected) {
            worst = worst.max((hit.clearance - clearances[i]).abs());
            if margin == 0.0 {
                colliding += 1;
            }
        }
        let min = robot.min_clearance(&kin).expect("pairs exist");
        let independent = clearances.iter().copied().fold(f64::INFINITY, f64::min);
        worst = worst.max((min.clearance - independent).abs());
    }
    println!(
        "exhaustive check: {colliding} colliding configs at margin 0, worst clearance difference {worst:.3e}"
    );
    assert!(colliding > 0);
    assert!(worst < 1e-12);
}

#[test]
fn pairs_certified_clear_within_the_limits_are_still_checked_beyond_them() {
    // The hand's clearance floor against link5 holds within the limits of joints 6 and 7;
    // with joint 6 below its lower limit the two can touch, and the check must find it.
    let robot = robot();
    let mut rng = rng(54);
    let lower = robot.limits().lower[5];
    let mut hand_on_link5 = 0;
    for _ in 0..2000 {
        let mut q = random_q(&mut rng, &robot);
        q[5] = rng.random_range(lower - 3.0..lower);
        q[6] = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        let kin = robot.forward(&q);
        let expected = all_clearances(&robot, &kin)
            .iter()
            .position(|&c| c < 0.0)
            .map(|i| robot.collision_pairs()[i]);
        let hit = robot.first_collision(&kin, 0.0).map(|h| h.pair);
        assert_eq!(hit, expected, "q {q:?}");
        let capsules = robot.capsules();
        hand_on_link5 += usize::from(hit.is_some_and(|pair| {
            (capsules[pair.first].segment, capsules[pair.second].segment) == (5, 7)
        }));
    }
    println!("link5 touched the hand or the pen in {hand_on_link5} of 2000 configurations");
    assert!(
        hand_on_link5 > 0,
        "the test must reach the pairs the floor skips"
    );
}

#[test]
fn a_body_whose_only_capsule_is_a_point_is_still_checked() {
    // link6 carries only a point; only its pairs with the hand are checked, so a pair the
    // broad phase wrongly skips cannot hide behind an earlier pair.
    let text = common::robot_text();
    let start = text.find("<link name=\"link6\">").expect("link6");
    let end = start + text[start..].find("</link>").expect("end of link6");
    let point = "<link name=\"link6\">\n    <collision>\n      <origin xyz=\"0 0 -0.03\"/>\n      \
                 <geometry><sphere radius=\"0\"/></geometry>\n    </collision>\n  ";
    let text = format!("{}{point}{}", &text[..start], &text[end..]);
    let links: Vec<String> = robot().capsules().iter().map(|c| c.link.clone()).collect();
    let mut disabled = Vec::new();
    for (i, a) in links.iter().enumerate() {
        for b in &links[i + 1..] {
            if a != b && !(a == "link6" && b == "hand") {
                disabled.push((a.clone(), b.clone()));
            }
        }
    }
    let rule = emg_kinematics::PairRule::AllExcept(disabled);
    let robot = Robot::from_urdf_str_with_rule(&text, "link0", "pen_tip", rule)
        .expect("edited robot loads");
    let point = robot
        .capsules()
        .iter()
        .position(|c| c.link == "link6")
        .expect("link6 keeps its point");
    assert_eq!(robot.capsules()[point].radius, 0.0);
    let pairs = robot.collision_pairs();
    assert_eq!(pairs.len(), 2, "the point against the hand's two capsules");
    assert!(pairs.iter().all(|p| p.first == point));
    let mut rng = rng(53);
    let configurations: Vec<_> = (0..2000).map(|_| random_q(&mut rng, &robot)).collect();
    let nearest = |q| {
        let kin = robot.forward(q);
        all_clearances(&robot, &kin)
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    };
    // Joint 7 alone moves the hand about link6, so the clearance spans a narrow band: the
    // margin lies between its two middle values, so that both verdicts occur and no
    // clearance sits on it.
    let mut clearances: Vec<f64> = configurations.iter().map(nearest).collect();
    clearances.sort_by(f64::total_cmp);
    let middle = clearances.len() / 2;
    let margin = 0.5 * (clearances[middle - 1] + clearances[middle]);
    let mut hits = 0;
    for q in &configurations {
        let kin = robot.forward(q);
        let expected = all_clearances(&robot, &kin)
            .iter()
            .position(|&c| c < margin);
        let hit = robot.first_collision(&kin, margin);
        assert_eq!(
            hit.map(|h| h.pair),
            expected.map(|i| robot.collision_pairs()[i]),
            "q {q:?}"
        );
        hits += usize::from(hit.is_some());
    }
    println!("the point came within {margin:.3} m of the hand in {hits} of 2000 configurations");
    assert!(hits > 0 && hits < 2000, "the test must see both verdicts");
}
