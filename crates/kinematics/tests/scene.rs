//! Obstacles of the cell: the signed distance of a segment from each shape against a dense
//! sampling of the shape's own point distance (apart, touching and entering, boxes turned at
//! random); the tool's capsules are the pen's; the work surface spares them and nothing else;
//! `first_contact` against an exhaustive check of every capsule; scene files read, write back and
//! refuse bad input naming the obstacle and the field.

mod common;

use common::{home, random_point, random_q, random_unit, rng, robot};
use emg_kinematics::{
    Obstacle, Scene, Shape, ToolContact, Vec3, rotation_about, rotation_from_rpy,
};
use nalgebra::Rotation3;
use rand::RngExt;

/// Signed distance of a point from `shape`, straight from each solid's definition.
fn point_signed_distance(shape: &Shape, p: &Vec3) -> f64 {
    match shape {
        Shape::HalfSpace { point, normal } => (p - point).dot(normal),
        Shape::Sphere { centre, radius } => (p - centre).norm() - radius,
        Shape::Capsule { start, end, radius } => {
            let axis = end - start;
            let t = ((p - start).dot(&axis) / axis.norm_squared()).clamp(0.0, 1.0);
            (p - (start + axis * t)).norm() - radius
        }
        Shape::Cuboid {
            centre,
            rotation,
            half_extents,
        } => {
            let local = rotation.transpose() * (p - centre);
            let mut outside = 0.0_f64;
            let mut inside = f64::NEG_INFINITY;
            for i in 0..3 {
                let excess = local[i].abs() - half_extents[i];
                outside += excess.max(0.0).powi(2);
                inside = inside.max(excess);
            }
            outside.sqrt() + inside.min(0.0)
        }
    }
}

/// Minimum of the point distance over `n + 1` evenly spaced points of the segment.
fn sampled_distance(shape: &Shape, a: &Vec3, b: &Vec3, n: usize) -> f64 {
    (0..=n)
        .map(|i| point_signed_distance(shape, &(a + (b - a) * (i as f64 / n as f64))))
        .fold(f64::INFINITY, f64::min)
}

fn random_shape(rng: &mut rand_chacha::ChaCha8Rng, kind: usize) -> Shape {
    match kind {
        0 => Shape::HalfSpace {
            point: random_point(rng, 0.2),
            normal: random_unit(rng),
        },
        1 => Shape::Cuboid {
            centre: random_point(rng, 0.2),
            rotation: rotation_about(&random_unit(rng), rng.random_range(0.0..3.0)),
            half_extents: Vec3::new(
                rng.random_range(0.0..0.3),
                rng.random_range(0.01..0.3),
                rng.random_range(0.01..0.3),
            ),
        },
        2 => Shape::Sphere {
            centre: random_point(rng, 0.2),
            radius: rng.random_range(0.0..0.3),
        },
        _ => Shape::Capsule {
            start: random_point(rng, 0.3),
            end: random_point(rng, 0.3),
            radius: rng.random_range(0.0..0.2),
        },
    }
}

#[test]
fn segment_distance_matches_a_dense_sampling_of_every_shape() {
    let mut rng = rng(11);
    let samples = 20_000;
    let (mut apart, mut entering) = (0, 0);
    for case in 0..4_000 {
        let shape = random_shape(&mut rng, case % 4);
        let a = random_point(&mut rng, 0.5);
        // Some segments degenerate to a point.
        let b = if case % 17 == 0 {
            a
        } else {
            random_point(&mut rng, 0.5)
        };
        let exact = shape.segment_distance(&a, &b);
        let sampled = sampled_distance(&shape, &a, &b, samples);
        // The sampled minimum is never below the exact one and exceeds it by at most what the
        // sampling spacing can miss (each point distance is 1-Lipschitz).
        let spacing = (b - a).norm() / samples as f64;
        assert!(
            sampled >= exact - 1e-12 && sampled <= exact + spacing + 1e-12,
            "case {case}: {shape:?} from {a} to {b}: exact {exact}, sampled {sampled}"
        );
        if exact > 0.0 {
            apart += 1;
        } else {
            entering += 1;
        }
    }
    assert!(
        apart > 1_000 && entering > 1_000,
        "{apart} apart, {entering} entering"
    );
}

/// A rigid motion moves a segment and every shape together: their distance is unchanged; a scene
/// file's `transform` moves its obstacles as `Scene::moved` does.
#[test]
fn moved_shapes_keep_their_distances_and_scene_files_move_theirs() {
    let mut rng = rng(12);
    for case in 0..2_000 {
        let shape = random_shape(&mut rng, case % 4);
        let (a, b) = (random_point(&mut rng, 0.5), random_point(&mut rng, 0.5));
        let motion = nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::from(random_point(&mut rng, 0.5)),
            nalgebra::UnitQuaternion::from_rotation_matrix(&rotation_about(
                &random_unit(&mut rng),
                rng.random_range(-3.0..3.0),
            )),
        );
        let moved = |p: &Vec3| (motion * nalgebra::Point3::from(*p)).coords;
        let before = shape.segment_distance(&a, &b);
        let after = shape
            .moved(&motion)
            .segment_distance(&moved(&a), &moved(&b));
        assert!(
            (before - after).abs() < 1e-9,
            "case {case}: {before} vs {after}"
        );
    }
    let text = r#"{"transform": {"translation_m": [0.1, -0.2, 0.3], "rpy": [0, 0, 1.5707963267948966]},
        "obstacles": [{"sphere": {"centre": [0.5, 0, 0], "radius": 0.05}}]}"#;
    let scene: Scene = serde_json::from_str(text).unwrap();
    let Shape::Sphere { centre, .. } = &scene.obstacles[0].shape else {
        panic!("a sphere")
    };
    assert!(
        (centre - Vec3::new(0.1, 0.3, 0.3)).norm() < 1e-12,
        "{centre}"
    );
}

#[test]
fn box_distances_known_answers() {
    let unit_box = Shape::Cuboid {
        centre: Vec3::zeros(),
        rotation: Rotation3::identity(),
        half_extents: Vec3::new(1.0, 1.0, 1.0),
    };
    let v = Vec3::new;
    let cases = [
        // Parallel to a face, above it.
        (v(-0.5, 0.0, 2.0), v(0.5, 0.0, 2.0), 1.0),
        // Passing a vertical edge at 45°: the nearest box point is on the edge.
        (v(2.0, 0.0, 0.0), v(0.0, 2.0, 0.0), 0.0),
        (v(3.0, 0.0, 0.0), v(0.0, 3.0, 0.0), 0.5_f64.sqrt()),
        // Through the centre: as deep as the centre.
        (v(-3.0, 0.0, 0.0), v(3.0, 0.0, 0.0), -1.0),
        // Entering half-way along x only.
        (v(0.5, 0.2, 0.0), v(3.0, 0.2, 0.0), -0.5),
        // Beside a vertex.
        (v(2.0, 2.0, 2.0), v(3.0, 3.0, 3.0), 3.0_f64.sqrt()),
    ];
    for (a, b, expected) in cases {
        let found = unit_box.segment_distance(&a, &b);
        assert!(
            (found - expected).abs() < 1e-12,
            "{a} {b}: {found} vs {expected}"
        );
    }
}

#[test]
fn the_tool_is_the_pen() {
    let robot = robot();
    let tool = robot.tool_capsules();
    assert!(!tool.is_empty());
    for (index, capsule) in robot.capsules().iter().enumerate() {
        assert_eq!(
            tool.contains(&index),
            capsule.link == "pen_tip",
            "{capsule:?}"
        );
    }
}

#[test]
fn the_work_surface_spares_the_tool_and_nothing_else() {
    let robot = robot();
    let mut rng = rng(13);
    // A pose with the pen pointing straight away from the base, so that only the pen reaches a
    // surface through its tip.
    let kin = std::iter::repeat_with(|| robot.forward(&random_q(&mut rng, &robot)))
        .take(100_000)
        .find(|kin| {
            let outward = Vec3::new(kin.tcp().x, kin.tcp().y, 0.0).normalize();
            kin.tool_axis().dot(&outward) > 0.97
                && kin.tcp().z > 0.3
                && robot.first_collision(kin, 0.0).is_none()
        })
        .expect("such a pose within 100,000 draws");
    let surface = Shape::work_surface(&kin.tcp(), &kin.tool_axis());
    let touched = robot
        .first_contact(&kin, &surface, 0.0, ToolContact::Forbidden)
        .expect("the pen tip's cap crosses the surface");
    assert!(robot.tool_capsules().contains(&touched.capsule));
    assert_eq!(
        robot.first_contact(&kin, &surface, 0.0, ToolContact::Allowed),
        None
    );
    // Moved 15 cm back towards the flange, the surface cuts the arm itself.
    let raised = Shape::work_surface(&(kin.tcp() - kin.tool_axis() * 0.15), &kin.tool_axis());
    let hit = robot
        .first_contact(&kin, &raised, 0.0, ToolContact::Allowed)
        .expect("the hand reaches below a raised surface");
    assert!(!robot.tool_capsules().contains(&hit.capsule));
    // At home the surface under the pen's tip cuts the base (the pen points down).
    let kin = robot.forward(&home());
    let under_tip = Shape::work_surface(&kin.tcp(), &kin.tool_axis());
    let hit = robot
        .first_contact(&kin, &under_tip, 0.0, ToolContact::Allowed)
        .expect("the base lies below the pen's tip");
    assert_eq!(robot.capsules()[hit.capsule].link, "link0");
}

#[test]
fn first_contact_is_the_first_capsule_an_exhaustive_check_finds() {
    let robot = robot();
    let mut rng = rng(12);
    let mut contacts = 0;
    for case in 0..600 {
        let kin = robot.forward(&random_q(&mut rng, &robot));
        let mut shape = random_shape(&mut rng, case % 4);
        if let Shape::HalfSpace { point, .. } = &mut shape {
            *point += Vec3::new(0.3, 0.0, 0.4);
        }
        let clearance = rng.random_range(0.0..0.05);
        for tool in [ToolContact::Allowed, ToolContact::Forbidden] {
            let expected = robot.capsules().iter().enumerate().find_map(|(i, c)| {
                if tool == ToolContact::Allowed && robot.tool_capsules().contains(&i) {
                    return None;
                }
                let [a, b] = [&c.start, &c.end].map(|p| kin.segment_point(c.segment, p));
                let gap = sampled_distance(&shape, &a, &b, 4_000) - c.radius;
                (gap < clearance - 1e-4).then_some(i)
            });
            let found = robot.first_contact(&kin, &shape, clearance, tool);
            if let Some(i) = expected {
                let hit = found.expect("a clear contact is found");
                assert!(hit.capsule <= i, "case {case}: {} after {i}", hit.capsule);
                assert!(hit.clearance < clearance);
                contacts += 1;
            } else if let Some(hit) = found {
                // Only a near-touch the sampling cannot resolve may differ.
                assert!(hit.clearance > clearance - 1e-4, "case {case}: {hit:?}");
            }
        }
    }
    assert!(contacts > 200, "{contacts} contacts");
}

#[test]
fn scene_files_read_back_and_write_back() {
    let text = r#"{"obstacles": [
        {"name": "table", "half_space": {"point": [0, 0, 0], "normal": [0, 0, 2]}},
        {"name": "fixture", "clearance_m": 0.01,
         "box": {"centre": [0.5, 0.3, 0.1], "size": [0.2, 0.1, 0.2], "rpy": [0, 0, 0.3]}},
        {"sphere": {"centre": [0.4, -0.4, 0.5], "radius": 0.05}},
        {"capsule": {"start": [0.3, 0.5, 0], "end": [0.3, 0.5, 0.8], "radius": 0.04}}
    ]}"#;
    let scene: Scene = serde_json::from_str(text).unwrap();
    let names: Vec<&str> = scene.obstacles.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["table", "fixture", "obstacles[2]", "obstacles[3]"]);
    assert_eq!(
        scene.obstacles[0].shape,
        Shape::HalfSpace {
            point: Vec3::zeros(),
            normal: Vec3::z()
        }
    );
    let Shape::Cuboid {
        rotation,
        half_extents,
        ..
    } = &scene.obstacles[1].shape
    else {
        panic!("a box");
    };
    assert_eq!(*half_extents, Vec3::new(0.1, 0.05, 0.1));
    assert_eq!(*rotation, rotation_from_rpy(0.0, 0.0, 0.3));
    assert_eq!(scene.obstacles[1].clearance_m, 0.01);
    assert_eq!(scene.obstacles[2].clearance_m, 0.0);
    let again: Scene = serde_json::from_str(&serde_json::to_string(&scene).unwrap()).unwrap();
    for (a, b) in scene.obstacles.iter().zip(&again.obstacles) {
        assert_eq!((&a.name, a.clearance_m), (&b.name, b.clearance_m));
        // Written back, a box's turn goes through roll–pitch–yaw and back.
        let probe = Vec3::new(0.45, 0.32, 0.15);
        let ends = (probe, probe + Vec3::x() * 0.3);
        let (da, db) = (
            a.shape.segment_distance(&ends.0, &ends.1),
            b.shape.segment_distance(&ends.0, &ends.1),
        );
        assert!((da - db).abs() < 1e-12, "{a:?} vs {b:?}");
    }
    assert!(Scene::default().is_empty());
}

#[test]
fn bad_scene_files_name_the_obstacle_and_the_field() {
    let cases = [
        (
            r#"{"obstacles": [{"name": "wall", "half_space": {"point": [0, 0, 0], "normal": [0, 0, 0]}}]}"#,
            "obstacles[0] ('wall'): half_space.normal must be a direction",
        ),
        (
            r#"{"obstacles": [{"sphere": {"centre": [0, 0, 0], "radius": 0.1}}, {"sphere": {"centre": [0, 0, 0], "radius": -1}}]}"#,
            "obstacles[1]: sphere.radius must be a number ≥ 0, got -1",
        ),
        (
            r#"{"obstacles": [{"sphere": {"centre": [0, 0, 0], "radius": 0.1}, "box": {"centre": [0, 0, 0], "size": [1, 1, 1]}}]}"#,
            "obstacles[0]: shape must be exactly one of",
        ),
        (
            r#"{"obstacles": [{"name": "post"}]}"#,
            "obstacles[0] ('post'): shape must be exactly one of",
        ),
        (
            r#"{"obstacles": [{"box": {"centre": [0, 0, 0], "size": [1, -1, 1]}}]}"#,
            "obstacles[0]: box.size must be three lengths ≥ 0",
        ),
        (
            r#"{"obstacles": [{"sphere": {"centre": [0, 0, 0], "radius": 0.1}, "clearance_m": -0.01}]}"#,
            "obstacles[0]: clearance_m must be a number ≥ 0",
        ),
        (
            r#"{"obstacles": [{"sphere": {"center": [0, 0, 0], "radius": 0.1}}]}"#,
            "unknown field `center`",
        ),
        (r#"{"obstacle": []}"#, "unknown field `obstacle`"),
    ];
    for (text, expected) in cases {
        let error = serde_json::from_str::<Scene>(text).unwrap_err().to_string();
        assert!(error.contains(expected), "{text}: {error}");
    }
}

#[test]
fn an_obstacle_is_plain_data() {
    let obstacle = Obstacle {
        name: "ball".into(),
        shape: Shape::Sphere {
            centre: Vec3::new(0.3, 0.0, 0.4),
            radius: 0.05,
        },
        clearance_m: 0.0,
        tool_may_touch: true,
    };
    let scene = Scene {
        obstacles: vec![obstacle.clone()],
    };
    let text = serde_json::to_string(&scene).unwrap();
    assert_eq!(
        text,
        r#"{"obstacles":[{"name":"ball","clearance_m":0.0,"tool_may_touch":true,"sphere":{"centre":[0.3,0.0,0.4],"radius":0.05}}]}"#
    );
    assert_eq!(serde_json::from_str::<Scene>(&text).unwrap(), scene);
}

/// The first `s` at which a ray comes within a grown capsule, in closed form, against a fine
/// march along the ray with the point distance from the solid's definition.
#[test]
fn capsule_ray_entry_matches_a_march_along_the_ray() {
    let mut rng = rng(71);
    let mut entered = 0;
    for _ in 0..300 {
        let start = random_point(&mut rng, 0.3);
        let end = start + random_unit(&mut rng) * rng.random_range(0.0..0.4);
        let radius = rng.random_range(0.01..0.1);
        let inflation = rng.random_range(0.0..0.1);
        let origin = random_point(&mut rng, 1.0);
        // Aimed near the capsule, so that many rays enter it and many graze past.
        let aim = (start + end) * 0.5 + random_point(&mut rng, 0.2);
        let direction = (aim - origin).normalize();
        let grown = Shape::Capsule {
            start,
            end,
            radius: radius + inflation,
        };
        let step = 1e-4;
        let marched = (0..40_000)
            .map(|k| k as f64 * step)
            .find(|s| point_signed_distance(&grown, &(origin + direction * *s)) <= 0.0);
        let found =
            emg_kinematics::capsule_ray_entry(&start, &end, radius, inflation, &origin, &direction);
        match (found, marched) {
            (Some(s), Some(m)) => {
                assert!((s - m).abs() <= step, "closed form {s}, march {m}");
                entered += 1;
            }
            (None, None) => {}
            other => panic!("closed form and march disagree: {other:?}"),
        }
    }
    assert!(entered > 30, "only {entered} rays entered");
}

/// The base column holds every capsule of the base link and of the first body, however the
/// first joint (and every other) turns.
#[test]
fn the_base_column_holds_the_first_two_bodies_in_every_configuration() {
    let robot = robot();
    let (start, end, radius) = robot
        .base_column()
        .expect("the FR3's base carries capsules");
    let column = Shape::Capsule { start, end, radius };
    let mut rng = rng(72);
    for _ in 0..200 {
        let kin = robot.forward(&random_q(&mut rng, &robot));
        for capsule in robot.capsules().iter().filter(|c| c.segment <= 1) {
            for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
                let centre = kin.segment_point(
                    capsule.segment,
                    &(capsule.start + (capsule.end - capsule.start) * t),
                );
                for direction in [
                    Vec3::x(),
                    -Vec3::x(),
                    Vec3::y(),
                    -Vec3::y(),
                    Vec3::z(),
                    -Vec3::z(),
                ] {
                    let surface = centre + direction * capsule.radius;
                    assert!(
                        point_signed_distance(&column, &surface) <= 1e-12,
                        "{} sticks out of the column",
                        capsule.link
                    );
                }
            }
        }
    }
}
