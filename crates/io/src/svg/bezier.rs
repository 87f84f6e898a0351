//! Cubic Bézier curves in a plane: points, tangents, splitting, inflections and extent.

use nalgebra::Vector2;

/// A point or vector in a plane.
pub(crate) type V2 = Vector2<f64>;

/// The 2D cross product `a × b` (positive when `b` lies counter-clockwise of `a`).
pub(crate) fn cross(a: &V2, b: &V2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// A cubic Bézier curve by its four control points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Cubic {
    /// Start, two handles, end.
    pub p: [V2; 4],
}

impl Cubic {
    /// The cubic that traces the quadratic Bézier `p0`, `q`, `p2` (degree elevation, exact).
    pub fn from_quadratic(p0: V2, q: V2, p2: V2) -> Self {
        Self {
            p: [
                p0,
                p0 + (q - p0) * (2.0 / 3.0),
                p2 + (q - p2) * (2.0 / 3.0),
                p2,
            ],
        }
    }

    /// The curve with every control point mapped by `f` (exact for affine maps).
    pub fn map(&self, f: impl Fn(V2) -> V2) -> Self {
        Self { p: self.p.map(f) }
    }

    /// The point at parameter `t ∈ [0, 1]`.
    pub fn point(&self, t: f64) -> V2 {
        let s = 1.0 - t;
        let [a, b, c, d] = self.p;
        a * (s * s * s) + b * (3.0 * s * s * t) + c * (3.0 * s * t * t) + d * (t * t * t)
    }

    /// The length of the control polygon: an upper bound of the curve's length.
    pub fn hull_length(&self) -> f64 {
        let [a, b, c, d] = self.p;
        (b - a).norm() + (c - b).norm() + (d - c).norm()
    }

    /// The two halves of the curve at `t` (de Casteljau), and the unit tangent where they
    /// meet when the curve has one there (`None` at a cusp).
    pub fn split(&self, t: f64) -> (Self, Self, Option<V2>) {
        let [a, b, c, d] = self.p;
        let lerp = |u: V2, v: V2| u + (v - u) * t;
        let (ab, bc, cd) = (lerp(a, b), lerp(b, c), lerp(c, d));
        let (abc, bcd) = (lerp(ab, bc), lerp(bc, cd));
        let m = lerp(abc, bcd);
        let handle = bcd - abc;
        let tangent = (handle.norm() > self.negligible()).then(|| handle.normalize());
        (
            Self { p: [a, ab, abc, m] },
            Self { p: [m, bcd, cd, d] },
            tangent,
        )
    }

    /// A length below which a handle gives no direction: a millionth of the control polygon.
    fn negligible(&self) -> f64 {
        (self.hull_length() * 1e-6).max(1e-15)
    }

    /// The unit tangent at the start: along the first handle that is not negligible (a handle
    /// on its end point leaves the direction to the next control point); `None` for a point.
    pub fn start_tangent(&self) -> Option<V2> {
        let [a, b, c, d] = self.p;
        self.first_direction([b - a, c - a, d - a])
    }

    /// The unit tangent at the end (see [`Cubic::start_tangent`]).
    pub fn end_tangent(&self) -> Option<V2> {
        let [a, b, c, d] = self.p;
        self.first_direction([d - c, d - b, d - a])
    }

    /// The direction of the first of `handles` that is not negligible, as a unit vector.
    fn first_direction(&self, handles: [V2; 3]) -> Option<V2> {
        handles
            .into_iter()
            .find(|v| v.norm() > self.negligible())
            .map(|v| v.normalize())
    }

    /// The parameters in `(0, 1)`, ascending, where the curve's turning changes sign.
    pub fn inflections(&self) -> Vec<f64> {
        let [p0, p1, p2, p3] = self.p;
        // B'/3 = a + 2 b t + c t², B''/6 = b + c t; B' × B'' ∝ a×b + (a×c) t + (b×c) t².
        let a = p1 - p0;
        let b = p2 - p1 * 2.0 + p0;
        let c = p3 - p2 * 3.0 + p1 * 3.0 - p0;
        let mut roots = quadratic_roots(cross(&b, &c), cross(&a, &c), cross(&a, &b));
        roots.retain(|t| *t > 1e-6 && *t < 1.0 - 1e-6);
        roots.sort_by(f64::total_cmp);
        roots.dedup_by(|x, y| (*x - *y).abs() < 1e-9);
        roots
    }

    /// The points where the curve reaches its extent along x or y (its ends included): the
    /// curve's bounding box is theirs.
    pub fn extreme_points(&self) -> Vec<V2> {
        let [p0, p1, p2, p3] = self.p;
        let (a, b, c) = (p1 - p0, p2 - p1 * 2.0 + p0, p3 - p2 * 3.0 + p1 * 3.0 - p0);
        let mut points = vec![p0, p3];
        for axis in 0..2 {
            // B'(t)/3 along the axis: a + 2 b t + c t².
            for t in quadratic_roots(c[axis], 2.0 * b[axis], a[axis]) {
                if t > 0.0 && t < 1.0 {
                    points.push(self.point(t));
                }
            }
        }
        points
    }
}

/// The real roots of `a t² + b t + c` (of `b t + c` when `a` is negligible beside the others).
fn quadratic_roots(a: f64, b: f64, c: f64) -> Vec<f64> {
    let scale = a.abs().max(b.abs()).max(c.abs());
    if scale == 0.0 || !scale.is_finite() {
        return Vec::new();
    }
    let (a, b, c) = (a / scale, b / scale, c / scale);
    if a.abs() < 1e-12 {
        return if b.abs() < 1e-12 {
            Vec::new()
        } else {
            vec![-c / b]
        };
    }
    let discriminant = b * b - 4.0 * a * c;
    if discriminant < 0.0 {
        return Vec::new();
    }
    // The stable pair: q = −(b + sign(b) √D) / 2, roots q / a and c / q.
    let q = -0.5 * (b + b.signum() * discriminant.sqrt());
    let mut roots = vec![q / a];
    if q != 0.0 {
        roots.push(c / q);
    }
    roots
}

#[cfg(test)]
impl Cubic {
    /// The curve through the control points `points`, each `(x, y)`.
    pub(crate) fn from_xy(points: [(f64, f64); 4]) -> Self {
        Self {
            p: points.map(|(x, y)| V2::new(x, y)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_roots_are_found_stably() {
        let mut roots = quadratic_roots(1.0, -3.0, 2.0);
        roots.sort_by(f64::total_cmp);
        assert_eq!(roots.len(), 2);
        assert!((roots[0] - 1.0).abs() < 1e-12 && (roots[1] - 2.0).abs() < 1e-12);
        assert_eq!(quadratic_roots(0.0, 2.0, -1.0), vec![0.5]);
        assert!(quadratic_roots(1.0, 0.0, 1.0).is_empty());
        assert!(quadratic_roots(0.0, 0.0, 0.0).is_empty());
    }

    #[test]
    fn an_s_curve_has_one_inflection_in_its_middle() {
        let s = Cubic::from_xy([(0.0, 0.0), (1.0, 1.0), (2.0, -1.0), (3.0, 0.0)]);
        let inflections = s.inflections();
        assert_eq!(inflections.len(), 1);
        assert!((inflections[0] - 0.5).abs() < 1e-12);
        let arch = Cubic::from_xy([(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)]);
        assert!(arch.inflections().is_empty());
        let top = arch
            .extreme_points()
            .into_iter()
            .map(|p| p.y)
            .fold(f64::NEG_INFINITY, f64::max);
        assert!((top - 0.75).abs() < 1e-12);
    }

    #[test]
    fn splitting_keeps_the_curve_and_its_tangent() {
        let c = Cubic::from_xy([(0.0, 0.0), (1.0, 2.0), (3.0, 2.0), (4.0, 0.0)]);
        let (left, right, tangent) = c.split(0.3);
        for k in 0..=10 {
            let u = k as f64 / 10.0;
            assert!((left.point(u) - c.point(0.3 * u)).norm() < 1e-12);
            assert!((right.point(u) - c.point(0.3 + 0.7 * u)).norm() < 1e-12);
        }
        let tangent = tangent.unwrap();
        assert!((tangent - left.end_tangent().unwrap()).norm() < 1e-12);
        assert!((tangent - right.start_tangent().unwrap()).norm() < 1e-12);
        let quad = Cubic::from_quadratic(V2::new(0.0, 0.0), V2::new(1.0, 2.0), V2::new(2.0, 0.0));
        // The quadratic's midpoint: (p0 + 2 q + p2) / 4.
        assert!((quad.point(0.5) - V2::new(1.0, 1.0)).norm() < 1e-12);
    }
}
