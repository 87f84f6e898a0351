//! Capsules fitted to collision geometry: they contain every triangle (corners and random inner
//! points) and every ball of random geometry, one or several capsules; a tessellated cylinder
//! gets one capsule of the cylinder's radius along its axis; an L of two bars gets two capsules
//! that enclose less than the one around both.

mod common;

use common::{random_point, random_unit, rng};
use emg_kinematics::{
    Ball, Covered, FittedCapsule, Vec3, fit_capsules, rotation_about, segment_distance,
};
use rand::RngExt;

/// Whether `p` lies in one of `capsules` (to rounding).
fn covered_by(capsules: &[FittedCapsule], p: &Vec3, radius: f64) -> bool {
    capsules
        .iter()
        .any(|c| segment_distance(&c.start, &c.end, p, p) + radius <= c.radius + 1e-9)
}

/// Two triangles per quad of a closed prism with `sides` sides around the z axis, of
/// circumradius `radius`, from z = 0 to `length`.
fn prism(sides: usize, radius: f64, length: f64) -> Covered {
    let corner = |k: usize, z: f64| {
        let angle = std::f64::consts::TAU * k as f64 / sides as f64;
        let (sin, cos) = libm::sincos(angle);
        Vec3::new(radius * cos, radius * sin, z)
    };
    let mut triangles = Vec::new();
    for k in 0..sides {
        let (a, b) = (corner(k, 0.0), corner(k + 1, 0.0));
        let (c, d) = (corner(k, length), corner(k + 1, length));
        triangles.push([a, b, d]);
        triangles.push([a, d, c]);
        triangles.push([Vec3::zeros(), b, a]);
        triangles.push([Vec3::new(0.0, 0.0, length), c, d]);
    }
    Covered {
        triangles,
        balls: Vec::new(),
    }
}

#[test]
fn fitted_capsules_contain_every_triangle_and_ball() {
    let mut rng = rng(31);
    for case in 0..200 {
        let direction = random_unit(&mut rng);
        let spread = rng.random_range(0.02..0.4);
        let point = |rng: &mut rand_chacha::ChaCha8Rng| {
            direction * rng.random_range(-spread..spread) + random_point(rng, 0.05)
        };
        let count = rng.random_range(1..40);
        let triangles = (0..count)
            .map(|_| [point(&mut rng), point(&mut rng), point(&mut rng)])
            .collect();
        let balls = (0..case % 3)
            .map(|_| Ball {
                centre: point(&mut rng),
                radius: 0.03,
            })
            .collect();
        let covered = Covered { triangles, balls };
        for max in 1..=3 {
            let capsules = fit_capsules(&covered, max).expect("geometry is not empty");
            assert!((1..=max).contains(&capsules.len()));
            for triangle in &covered.triangles {
                for k in 0..20 {
                    let (a, b) = (k as f64 / 20.0, (k % 7) as f64 / 7.0);
                    let (a, b) = if a + b > 1.0 {
                        (1.0 - a, 1.0 - b)
                    } else {
                        (a, b)
                    };
                    let p = triangle[0]
                        + (triangle[1] - triangle[0]) * a
                        + (triangle[2] - triangle[0]) * b;
                    assert!(covered_by(&capsules, &p, 0.0), "case {case}, {max}: {p}");
                }
            }
            for ball in &covered.balls {
                assert!(
                    covered_by(&capsules, &ball.centre, ball.radius),
                    "case {case}"
                );
            }
        }
    }
    assert_eq!(fit_capsules(&Covered::default(), 3), None);
}

#[test]
fn a_cylinder_gets_a_capsule_of_its_radius_along_its_axis() {
    let (radius, length) = (0.05, 0.3);
    // Circumscribed: the prism contains the cylinder.
    let sides = 32;
    let circumradius = radius / libm::cos(std::f64::consts::PI / sides as f64);
    let capsules = fit_capsules(&prism(sides, circumradius, length), 3).unwrap();
    assert_eq!(capsules.len(), 1, "{capsules:?}");
    let capsule = capsules[0];
    // At least the circumradius; a little more only where it shortens the axis by more.
    assert!(
        capsule.radius >= circumradius && capsule.radius < 1.02 * radius,
        "{capsule:?}"
    );
    let axis = (capsule.end - capsule.start).normalize();
    assert!(axis.z.abs() > 1.0 - 1e-9, "{capsule:?}");
    for end in [capsule.start, capsule.end] {
        assert!(end.xy().norm() < 1e-6, "{capsule:?}");
    }
    // About the cylinder plus its two caps: 1 + 4r/3L of the cylinder's volume.
    let cylinder = std::f64::consts::PI * radius * radius * length;
    let ratio = capsule.volume() / cylinder;
    let caps = 1.0 + 4.0 * radius / (3.0 * length);
    assert!(ratio > 1.0 && ratio < caps + 0.03, "{ratio} vs {caps}");
}

#[test]
fn an_l_shape_is_split_in_two() {
    let mut bars = prism(4, 0.03, 0.4);
    // A second bar along x from the top of the first.
    let turn = rotation_about(&Vec3::y(), std::f64::consts::FRAC_PI_2);
    bars.triangles.extend(
        prism(4, 0.03, 0.4)
            .triangles
            .iter()
            .map(|t| t.map(|p| turn * p + Vec3::new(0.0, 0.0, 0.4))),
    );
    let one = fit_capsules(&bars, 1).unwrap();
    let two = fit_capsules(&bars, 2).unwrap();
    assert_eq!(two.len(), 2);
    let total: f64 = two.iter().map(FittedCapsule::volume).sum();
    assert!(
        total < 0.5 * one[0].volume(),
        "{total} vs {}",
        one[0].volume()
    );
}
