//! Time-optimal path parametrization by reachability analysis (TOPP-RA, Pham & Pham 2018):
//! on a grid `s_0 < … < s_N` of the path, with `x = ṡ²` and `u = s̈` constant between grid
//! points (`x_{i+1} = x_i + 2 Δ_i u_i`), a backward pass computes the controllable sets
//! `K_i = [0, k_i]` (every `x_i` from which rest at `s_N` can be reached within the limits) and
//! a forward pass from rest takes the largest `u_i` that keeps `x_{i+1}` in `K_{i+1}`.
//!
//! Constraints: joint speeds `|q'_j| ṡ ≤ v_j` and the tool speed `|p'(s)| ṡ ≤ v_tool` at each
//! grid point (both bound `x` alone: the maximum velocity curve), and joint accelerations
//! `|q'_j u + q''_j x| ≤ a_j` at both ends of each interval (toppra's interpolation scheme:
//! `(u_i, x_i)` at `s_i` and `(u_i, x_i + 2Δ_i u_i)` at `s_{i+1}`). Each backward step is a two-variable LP in `(x, u)`,
//! solved exactly: for fixed `x` the admissible `u` is an interval whose ends are linear in `x`,
//! and the largest `x` is the smallest crossing of a lower end above an upper end.

use emg_kinematics::{JointVector, MAX_DOF};

/// `|q'_j|` below this counts as zero: the acceleration constraint of joint `j` then bounds `x`
/// alone (`|q''_j| x ≤ a_j`).
const NEGLIGIBLE_DERIVATIVE: f64 = 1e-12;

/// One grid point of the path: where it is and the path's derivatives there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridPoint {
    /// Path parameter.
    pub s: f64,
    /// `q'(s)`.
    pub dq: JointVector,
    /// `q''(s)`.
    pub ddq: JointVector,
    /// The largest `x = ṡ²` the joint and tool speed limits allow here.
    pub x_max: f64,
}

/// A line `α + β x` bounding `u` from below or above.
#[derive(Clone, Copy)]
struct Bound {
    alpha: f64,
    beta: f64,
}

/// The bounds on `u` over grid interval `i` from the acceleration limits: at `s_i` on
/// `(u, x)` and, as toppra's interpolation scheme does, at `s_{i+1}` on `(u, x + 2Δu)` (so the
/// acceleration at both ends of the interval holds), each lower and upper bound a line in `x`.
struct AccelerationBounds {
    lower: [Bound; 2 * MAX_DOF],
    upper: [Bound; 2 * MAX_DOF],
    count: usize,
    /// The largest `x` the constraints whose `u` coefficient is negligible allow.
    x_max: f64,
}

impl AccelerationBounds {
    /// Interval `i` of `grid`, the limits at each end scaled by its factor.
    fn new(grid: &[GridPoint], i: usize, acceleration: &JointVector, factor: &[f64]) -> Self {
        let mut bounds = Self {
            lower: [Bound {
                alpha: 0.0,
                beta: 0.0,
            }; 2 * MAX_DOF],
            upper: [Bound {
                alpha: 0.0,
                beta: 0.0,
            }; 2 * MAX_DOF],
            count: 0,
            x_max: f64::INFINITY,
        };
        let delta = grid[i + 1].s - grid[i].s;
        let (here, next) = (&grid[i], &grid[i + 1]);
        for j in 0..MAX_DOF {
            // −a ≤ c_u u + c_x x ≤ a.
            bounds.push(here.dq[j], here.ddq[j], acceleration[j] * factor[i]);
            bounds.push(
                next.dq[j] + 2.0 * delta * next.ddq[j],
                next.ddq[j],
                acceleration[j] * factor[i + 1],
            );
        }
        bounds
    }

    fn push(&mut self, c_u: f64, c_x: f64, limit: f64) {
        if c_u.abs() < NEGLIGIBLE_DERIVATIVE {
            if c_x != 0.0 {
                self.x_max = self.x_max.min(limit / c_x.abs());
            }
            return;
        }
        let beta = -c_x / c_u;
        self.lower[self.count] = Bound {
            alpha: -limit / c_u.abs(),
            beta,
        };
        self.upper[self.count] = Bound {
            alpha: limit / c_u.abs(),
            beta,
        };
        self.count += 1;
    }
}

/// Path speeds `x_i = ṡ²` at the grid points of the fastest motion from rest at `s_0` to rest
/// at `s_N` within the limits; `factor[i]` scales both the speed bound (`x ≤ factor_i x_max`)
/// and the acceleration limits at grid point `i` (a local slow-down: about `√factor_i` of the
/// speed).
///
/// # Panics
///
/// Unless there are at least two grid points, `s` increases strictly and `factor` has one
/// entry per grid point.
pub fn topp_ra(grid: &[GridPoint], acceleration: &JointVector, factor: &[f64]) -> Vec<f64> {
    let n = grid.len() - 1;
    assert!(
        n >= 1 && factor.len() == grid.len(),
        "a grid and one factor per point"
    );
    // Backward pass: k[i] = max x in K_i.
    let mut reach = vec![0.0; n + 1];
    for i in (0..n).rev() {
        let delta = grid[i + 1].s - grid[i].s;
        assert!(delta > 0.0, "grid increases strictly");
        let bounds = AccelerationBounds::new(grid, i, acceleration, factor);
        let mut bound = (grid[i].x_max * factor[i]).min(bounds.x_max);
        // x + 2Δu ∈ [0, k_{i+1}].
        let step = Bound {
            alpha: 0.0,
            beta: -1.0 / (2.0 * delta),
        };
        let upper_step = Bound {
            alpha: reach[i + 1] / (2.0 * delta),
            ..step
        };
        for l in bounds.lower[..bounds.count].iter().chain([&step]) {
            for m in bounds.upper[..bounds.count].iter().chain([&upper_step]) {
                // Feasible while α_l + β_l x ≤ α_m + β_m x; at x = 0 it holds (u = 0 is
                // admissible), so only β_l > β_m bounds x.
                // (α_m − α_l) / (β_l − β_m) < bound, without dividing unless it is.
                let slope = l.beta - m.beta;
                if slope > 0.0 && m.alpha - l.alpha < bound * slope {
                    bound = (m.alpha - l.alpha) / slope;
                }
            }
        }
        reach[i] = bound.max(0.0);
    }
    // Forward pass from rest: the largest admissible u at each point.
    let mut x = vec![0.0; n + 1];
    for i in 0..n {
        let delta = grid[i + 1].s - grid[i].s;
        let bounds = AccelerationBounds::new(grid, i, acceleration, factor);
        let u = bounds.upper[..bounds.count]
            .iter()
            .map(|m| m.alpha + m.beta * x[i])
            .fold((reach[i + 1] - x[i]) / (2.0 * delta), f64::min);
        x[i + 1] = (x[i] + 2.0 * delta * u).clamp(0.0, reach[i + 1]);
    }
    x
}

/// The duration of the profile `x` on `grid`: `Σ 2Δ_i / (√x_i + √x_{i+1})`.
pub fn profile_duration(grid: &[GridPoint], x: &[f64]) -> f64 {
    grid.windows(2)
        .zip(x.windows(2))
        .map(|(g, x)| 2.0 * (g[1].s - g[0].s) / (x[0].sqrt() + x[1].sqrt()))
        .sum()
}
