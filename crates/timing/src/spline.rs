//! The natural cubic spline through joint waypoints: C² in the path parameter, exact at every
//! knot, with second derivatives from one tridiagonal solve.

use emg_kinematics::JointVector;

/// A path point: `q(s)` and its first three derivatives with respect to the path parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathPoint {
    /// `q(s)` (rad).
    pub q: JointVector,
    /// `q'(s)`.
    pub dq: JointVector,
    /// `q''(s)`.
    pub ddq: JointVector,
    /// `q'''(s)` (piecewise constant; the right-hand value at a knot).
    pub dddq: JointVector,
}

/// The natural cubic spline (`q'' = 0` at both ends) through `values[k]` at `knots[k]`, the
/// spline `scipy.interpolate.CubicSpline(knots, values, bc_type="natural")` builds.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSpline {
    knots: Vec<f64>,
    values: Vec<JointVector>,
    /// `q''` at each knot.
    second: Vec<JointVector>,
}

impl JointSpline {
    /// The spline through `values` at `knots`.
    ///
    /// # Panics
    ///
    /// Unless there are at least two knots, as many values, and the knots increase strictly.
    pub fn natural(knots: Vec<f64>, values: Vec<JointVector>) -> Self {
        assert!(knots.len() >= 2, "a spline needs two knots");
        assert_eq!(knots.len(), values.len(), "one value per knot");
        assert!(
            knots.windows(2).all(|w| w[1] > w[0]),
            "knots increase strictly"
        );
        let n = knots.len() - 1;
        let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
        let slope = |k: usize| (values[k + 1] - values[k]) / h[k];
        // Rows k = 1..n−1: h_{k−1} M_{k−1} + 2(h_{k−1} + h_k) M_k + h_k M_{k+1}
        // = 6 (slope_k − slope_{k−1}), with M_0 = M_n = 0; Thomas elimination.
        let mut second = vec![JointVector::zeros(); n + 1];
        let mut upper = vec![0.0; n + 1];
        let mut rhs = vec![JointVector::zeros(); n + 1];
        for k in 1..n {
            let diagonal = 2.0 * (h[k - 1] + h[k]) - h[k - 1] * upper[k - 1];
            upper[k] = h[k] / diagonal;
            rhs[k] = (6.0 * (slope(k) - slope(k - 1)) - rhs[k - 1] * h[k - 1]) / diagonal;
        }
        for k in (1..n).rev() {
            second[k] = rhs[k] - second[k + 1] * upper[k];
        }
        Self {
            knots,
            values,
            second,
        }
    }

    /// The knots (path parameter at each waypoint).
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The waypoints the spline passes through.
    pub fn values(&self) -> &[JointVector] {
        &self.values
    }

    /// The path parameter of the last knot (the first is 0 for paths built here).
    pub fn end(&self) -> f64 {
        self.knots[self.knots.len() - 1]
    }

    /// The segment holding `s` (clamped to the first and last).
    fn segment(&self, s: f64) -> usize {
        let last = self.knots.len() - 2;
        self.knots[1..=last].partition_point(|&knot| knot <= s)
    }

    /// `q(s)` and its derivatives; `s` outside the knots extends the end segments. At the last
    /// knot `q` is the last waypoint exactly.
    pub fn eval(&self, s: f64) -> PathPoint {
        let mut hint = usize::MAX;
        self.eval_from(s, &mut hint)
    }

    /// As [`Self::eval`], searching forward from segment `*hint` (which it updates): parameters
    /// that increase from call to call cost O(1) each.
    pub fn eval_from(&self, s: f64, hint: &mut usize) -> PathPoint {
        let last = self.knots.len() - 2;
        if *hint > last || self.knots[*hint] > s {
            *hint = self.segment(s);
        }
        while *hint < last && self.knots[*hint + 1] <= s {
            *hint += 1;
        }
        let k = *hint;
        let h = self.knots[k + 1] - self.knots[k];
        let t = s - self.knots[k];
        let (m0, m1) = (self.second[k], self.second[k + 1]);
        let (y0, y1) = (self.values[k], self.values[k + 1]);
        let b = (y1 - y0) / h - (m0 * 2.0 + m1) * (h / 6.0);
        let jerk = (m1 - m0) / h;
        let q = if s == self.knots[k + 1] {
            y1
        } else {
            y0 + (b + (m0 * 0.5 + jerk * (t / 6.0)) * t) * t
        };
        PathPoint {
            q,
            dq: b + (m0 + jerk * (0.5 * t)) * t,
            ddq: m0 + jerk * t,
            dddq: jerk,
        }
    }
}

impl JointSpline {
    /// The parameters strictly inside segment `k` where some joint's `q'` is zero: with the
    /// segment's ends, where each joint takes its extreme values on the segment.
    pub fn turning_points(&self, k: usize) -> impl Iterator<Item = f64> + '_ {
        let (s0, h) = (self.knots[k], self.knots[k + 1] - self.knots[k]);
        let (m0, m1) = (self.second[k], self.second[k + 1]);
        let b = (self.values[k + 1] - self.values[k]) / h - (m0 * 2.0 + m1) * (h / 6.0);
        (0..b.len()).flat_map(move |j| {
            // q'(t) = b + m0 t + (m1 − m0)/(2h) t² on t ∈ (0, h).
            let (c2, c1, c0) = ((m1[j] - m0[j]) / (2.0 * h), m0[j], b[j]);
            let roots = if c2.abs() < 1e-12 * (c1.abs() + c0.abs()).max(1e-300) {
                [(c1 != 0.0).then(|| -c0 / c1), None]
            } else {
                let discriminant = c1 * c1 - 4.0 * c2 * c0;
                if discriminant < 0.0 {
                    [None, None]
                } else {
                    let root = discriminant.sqrt();
                    [
                        Some((-c1 + root) / (2.0 * c2)),
                        Some((-c1 - root) / (2.0 * c2)),
                    ]
                }
            };
            roots
                .into_iter()
                .flatten()
                .filter(move |t| *t > 0.0 && *t < h)
                .map(move |t| s0 + t)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wave(s: f64) -> JointVector {
        JointVector::from_fn(|i, _| libm::sin(s * (1.0 + i as f64)))
    }

    fn spline(n: usize) -> JointSpline {
        let knots: Vec<f64> = (0..=n)
            .map(|k| libm::pow(k as f64 / n as f64, 1.3))
            .collect();
        let values = knots.iter().map(|&s| wave(s)).collect();
        JointSpline::natural(knots, values)
    }

    #[test]
    fn passes_through_every_waypoint_with_natural_ends() {
        let spline = spline(17);
        for (s, q) in spline.knots().iter().zip(spline.values()) {
            assert!((spline.eval(*s).q - q).norm() < 1e-14);
        }
        assert_eq!(spline.eval(spline.end()).q, spline.values()[17]);
        assert!(spline.eval(0.0).ddq.norm() < 1e-12);
        assert!(spline.eval(spline.end()).ddq.norm() < 1e-12);
    }

    #[test]
    fn is_c2_across_knots() {
        let spline = spline(9);
        for &s in &spline.knots()[1..9] {
            let (left, right) = (spline.eval(s - 1e-9), spline.eval(s + 1e-9));
            assert!((left.q - right.q).norm() < 1e-7);
            assert!((left.dq - right.dq).norm() < 1e-6);
            assert!((left.ddq - right.ddq).norm() < 1e-4);
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let spline = spline(11);
        let h = 1e-6;
        for j in 1..40 {
            let s = j as f64 / 40.0 * spline.end();
            let (at, before, after) = (spline.eval(s), spline.eval(s - h), spline.eval(s + h));
            assert!(((after.q - before.q) / (2.0 * h) - at.dq).norm() < 1e-7);
            assert!(((after.dq - before.dq) / (2.0 * h) - at.ddq).norm() < 1e-6);
            assert!(((after.ddq - before.ddq) / (2.0 * h) - at.dddq).norm() < 1e-4);
        }
    }

    #[test]
    fn approximates_a_smooth_function() {
        let spline = spline(40);
        // Away from the ends, where the natural end condition (q'' = 0) differs from the wave.
        for j in 20..=80 {
            let s = j as f64 / 100.0 * spline.end();
            assert!((spline.eval(s).q - wave(s)).norm() < 1e-4, "at {s}");
        }
    }

    #[test]
    fn turning_points_are_where_joints_peak() {
        let spline = spline(6);
        for k in 0..6 {
            let (a, b) = (spline.knots()[k], spline.knots()[k + 1]);
            for s in spline.turning_points(k) {
                assert!(s > a && s < b);
                let dq = spline.eval(s).dq;
                assert!(dq.iter().any(|v| v.abs() < 1e-9), "{dq} at {s}");
            }
            // Every joint's largest value on the segment, sampled finely, is at most the
            // largest at the ends and turning points.
            for j in 0..7 {
                let candidates = [a, b].into_iter().chain(spline.turning_points(k));
                let best = candidates
                    .map(|s| spline.eval(s).q[j])
                    .fold(f64::MIN, f64::max);
                let sampled = (0..=1000)
                    .map(|i| spline.eval(a + (b - a) * i as f64 / 1000.0).q[j])
                    .fold(f64::MIN, f64::max);
                assert!(sampled <= best + 1e-12, "joint {j}: {sampled} > {best}");
            }
        }
    }

    #[test]
    fn two_knots_make_a_straight_segment() {
        let a = JointVector::from_element(0.5);
        let b = JointVector::from_element(-1.0);
        let spline = JointSpline::natural(vec![0.0, 2.0], vec![a, b]);
        let mid = spline.eval(1.0);
        assert!((mid.q - (a + b) / 2.0).norm() < 1e-15);
        assert!((mid.dq - (b - a) / 2.0).norm() < 1e-15);
        assert_eq!(mid.ddq, JointVector::zeros());
    }
}
