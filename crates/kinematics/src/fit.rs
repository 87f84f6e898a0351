//! Bounding capsules fitted to a link's collision geometry (meshes, boxes, cylinders, spheres):
//! the collision model of a robot description that does not come in capsules.

use nalgebra::{Matrix3, SymmetricEigen};

use crate::vectors::Vec3;

/// A ball: mesh vertices are balls of radius 0, sphere elements keep their radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    /// Centre (m).
    pub centre: Vec3,
    /// Radius (m).
    pub radius: f64,
}

/// A link's collision geometry as covered volumes: the convex hull of each triangle and each
/// ball. A closed mesh's solid lies within the convex hull of its surface, which a capsule
/// around every triangle contains (a capsule is convex).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Covered {
    /// Triangles (corners, m).
    pub triangles: Vec<[Vec3; 3]>,
    /// Balls.
    pub balls: Vec<Ball>,
}

/// A capsule around a [`Covered`] geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FittedCapsule {
    /// First end of the axis (m).
    pub start: Vec3,
    /// Second end of the axis (m).
    pub end: Vec3,
    /// Radius (m).
    pub radius: f64,
}

impl FittedCapsule {
    /// Enclosed volume `πr²L + 4/3·πr³` (m³).
    pub fn volume(&self) -> f64 {
        let r = self.radius;
        std::f64::consts::PI * r * r * ((self.end - self.start).norm() + 4.0 / 3.0 * r)
    }
}

/// A split is kept when its two capsules enclose at most this share of the single capsule's
/// volume.
const SPLIT_GAIN: f64 = 0.75;

/// Radii tried between the smallest possible and a ball around everything, before refining.
const RADIUS_SCAN: usize = 200;

/// Capsules (at most `max_capsules`, 1 to 3) whose union contains `covered`: one along the
/// principal axis of the geometry with the radius that minimises its volume, replaced by two
/// fitted to the halves on either side of the median plane across that axis (triangles cut by
/// the plane are clipped into both halves) when those enclose at most 3/4 of its volume, and a
/// third by splitting the larger half again under the same rule. `None` for empty geometry.
pub fn fit_capsules(covered: &Covered, max_capsules: usize) -> Option<Vec<FittedCapsule>> {
    let single = fit_capsule(covered)?;
    if max_capsules < 2 {
        return Some(vec![single]);
    }
    let Some((lower, upper)) = split(covered) else {
        return Some(vec![single]);
    };
    let (Some(a), Some(b)) = (fit_capsule(&lower), fit_capsule(&upper)) else {
        return Some(vec![single]);
    };
    if a.volume() + b.volume() > SPLIT_GAIN * single.volume() {
        return Some(vec![single]);
    }
    if max_capsules < 3 {
        return Some(vec![a, b]);
    }
    let (larger, other, larger_fit) = if a.volume() >= b.volume() {
        (&lower, b, a)
    } else {
        (&upper, a, b)
    };
    match fit_capsules(larger, 2) {
        Some(parts) if parts.len() == 2 => Some(vec![parts[0], parts[1], other]),
        _ => Some(vec![larger_fit, other]),
    }
}

/// Every ball the geometry must lie in: triangle corners (radius 0) and the balls.
fn balls_of(covered: &Covered) -> Vec<Ball> {
    covered
        .triangles
        .iter()
        .flatten()
        .map(|&centre| Ball {
            centre,
            radius: 0.0,
        })
        .chain(covered.balls.iter().copied())
        .collect()
}

/// Unit direction of largest spread of the balls' centres (any unit vector when they do not
/// spread).
fn principal_axis(balls: &[Ball]) -> Vec3 {
    let mean = balls.iter().map(|b| b.centre).sum::<Vec3>() / balls.len() as f64;
    let scatter: Matrix3<f64> = balls
        .iter()
        .map(|b| {
            let d = b.centre - mean;
            d * d.transpose()
        })
        .sum();
    let eigen = SymmetricEigen::new(scatter);
    let largest = eigen.eigenvalues.imax();
    let axis = eigen.eigenvectors.column(largest).into_owned();
    if axis.norm() > 0.5 {
        axis.normalize()
    } else {
        Vec3::z()
    }
}

/// The smallest-volume capsule along the balls' principal axis that contains every ball.
fn fit_capsule(covered: &Covered) -> Option<FittedCapsule> {
    let balls = balls_of(covered);
    if balls.is_empty() {
        return None;
    }
    let axis = principal_axis(&balls);
    let helper = if axis.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let u = axis.cross(&helper).normalize();
    let v = axis.cross(&u);
    // The axis line passes through `centre` (a point of the plane ⟂ axis through the origin):
    // an approximate smallest circle around the balls' footprints (Bădoiu–Clarkson steps).
    let footprint: Vec<(f64, f64, f64)> = balls
        .iter()
        .map(|b| (b.centre.dot(&u), b.centre.dot(&v), b.radius))
        .collect();
    let (mut cu, mut cv) = {
        let (lo_u, hi_u, lo_v, hi_v) = footprint.iter().fold(
            (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ),
            |(a, b, c, d), &(x, y, _)| (a.min(x), b.max(x), c.min(y), d.max(y)),
        );
        (0.5 * (lo_u + hi_u), 0.5 * (lo_v + hi_v))
    };
    for step in 0..200 {
        let reach = |&(x, y, r): &(f64, f64, f64)| libm::hypot(x - cu, y - cv) + r;
        let far = footprint
            .iter()
            .max_by(|a, b| reach(a).total_cmp(&reach(b)))
            .expect("balls are not empty");
        let f = 1.0 / (step as f64 + 2.0);
        cu += (far.0 - cu) * f;
        cv += (far.1 - cv) * f;
    }
    // Axial position t and radial offset r of each ball from the axis line.
    let placed: Vec<(f64, f64, f64)> = balls
        .iter()
        .map(|b| {
            let (x, y) = (b.centre.dot(&u) - cu, b.centre.dot(&v) - cv);
            (b.centre.dot(&axis), libm::hypot(x, y), b.radius)
        })
        .collect();
    let smallest = placed
        .iter()
        .map(|&(_, r, rho)| r + rho)
        .fold(0.0, f64::max);
    let (t_min, t_max) = placed
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
    // Segment [a, b] along the axis for radius `radius`: every ball within reach.
    let segment = |radius: f64| {
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        for &(t, r, rho) in &placed {
            let slack = ((radius - rho).powi(2) - r * r).max(0.0).sqrt();
            a = a.min(t + slack);
            b = b.max(t - slack);
        }
        if b < a {
            let middle = 0.5 * (a + b);
            (middle, middle)
        } else {
            (a, b)
        }
    };
    let volume = |radius: f64| {
        let (a, b) = segment(radius);
        FittedCapsule {
            start: Vec3::zeros(),
            end: Vec3::x() * (b - a),
            radius,
        }
        .volume()
    };
    let largest = smallest + 0.5 * (t_max - t_min);
    let step = (largest - smallest) / RADIUS_SCAN as f64;
    let best = (0..=RADIUS_SCAN)
        .map(|k| smallest + step * k as f64)
        .min_by(|a, b| volume(*a).total_cmp(&volume(*b)))
        .expect("the scan is not empty");
    // Golden-section refinement between the scanned neighbours of the best radius.
    let golden = (5.0_f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = ((best - step).max(smallest), best + step);
    for _ in 0..60 {
        let (left, right) = (hi - golden * (hi - lo), lo + golden * (hi - lo));
        if volume(left) <= volume(right) {
            hi = right;
        } else {
            lo = left;
        }
    }
    let radius = if volume(0.5 * (lo + hi)) < volume(best) {
        0.5 * (lo + hi)
    } else {
        best
    };
    // A hair of slack absorbs the rounding of the radial offsets.
    let radius = radius * (1.0 + 1e-12) + 1e-12;
    let (a, b) = segment(radius);
    let origin = u * cu + v * cv;
    Some(FittedCapsule {
        start: origin + axis * a,
        end: origin + axis * b,
        radius,
    })
}

/// The geometry on either side of the plane through the median ball centre across the
/// principal axis: triangles clipped into both sides, balls to the side of their centre (a
/// ball is then covered whole by its side's capsule). `None` when a side would be empty.
fn split(covered: &Covered) -> Option<(Covered, Covered)> {
    let balls = balls_of(covered);
    if balls.len() < 4 {
        return None;
    }
    let axis = principal_axis(&balls);
    let mut along: Vec<f64> = balls.iter().map(|b| b.centre.dot(&axis)).collect();
    along.sort_by(f64::total_cmp);
    let cut = along[along.len() / 2];
    let side = |p: &Vec3| p.dot(&axis) - cut;
    let (mut lower, mut upper) = (Covered::default(), Covered::default());
    for triangle in &covered.triangles {
        for (sign, half) in [(-1.0, &mut lower), (1.0, &mut upper)] {
            let clipped = clip(triangle, |p| sign * side(p));
            for k in 1..clipped.len().saturating_sub(1) {
                half.triangles
                    .push([clipped[0], clipped[k], clipped[k + 1]]);
            }
        }
    }
    for ball in &covered.balls {
        if side(&ball.centre) < 0.0 {
            lower.balls.push(*ball);
        } else {
            upper.balls.push(*ball);
        }
    }
    let empty = |c: &Covered| c.triangles.is_empty() && c.balls.is_empty();
    (!empty(&lower) && !empty(&upper)).then_some((lower, upper))
}

/// The part of `triangle` where `inside(p) ≤ 0`, as a convex polygon (Sutherland–Hodgman).
fn clip(triangle: &[Vec3; 3], inside: impl Fn(&Vec3) -> f64) -> Vec<Vec3> {
    let mut polygon = Vec::with_capacity(4);
    for k in 0..3 {
        let (p, q) = (triangle[k], triangle[(k + 1) % 3]);
        let (dp, dq) = (inside(&p), inside(&q));
        if dp <= 0.0 {
            polygon.push(p);
        }
        if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
            polygon.push(p + (q - p) * (dp / (dp - dq)));
        }
    }
    polygon
}
