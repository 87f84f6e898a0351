//! Time-optimal path parametrization by reachability analysis (TOPP-RA, Pham & Pham 2018):
//! on a grid `s_0 < … < s_N` of the path, with `x = ṡ²` and `u = s̈` constant between grid
//! points (`x_{i+1} = x_i + 2 Δ_i u_i`), a backward pass computes the controllable sets
//! `K_i = [0, k_i]` (every `x_i` from which rest at `s_N` can be reached within the limits) and
//! a forward pass from rest takes the largest `u_i` that keeps `x_{i+1}` in `K_{i+1}`.
//!
//! Constraints at each grid point (collocation): joint speeds `|q'_j| ṡ ≤ v_j`, the tool speed
//! `|p'(s)| ṡ ≤ v_tool` (both bound `x` alone: the maximum velocity curve), and joint
//! accelerations `|q'_j u + q''_j x| ≤ a_j`. Each backward step is a two-variable LP in `(x, u)`,
//! solved exactly: for fixed `x` the admissible `u` is an interval whose ends are linear in `x`,
//! and the largest `x` is the smallest crossing of a lower end above an upper end.

use emg_kinematics::{DOF, JointVector};

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

/// The `u` bounds at a grid point from the acceleration limits (scaled by `factor`), and the
/// largest `x` the joints with negligible `q'_j` allow.
fn acceleration_bounds(
    point: &GridPoint,
    acceleration: &JointVector,
    factor: f64,
) -> ([Bound; DOF], [Bound; DOF], usize, f64) {
    let mut lower = [Bound {
        alpha: 0.0,
        beta: 0.0,
    }; DOF];
    let mut upper = lower;
    let mut count = 0;
    let mut x_max = f64::INFINITY;
    for j in 0..DOF {
        let (a, b, limit) = (point.dq[j], point.ddq[j], acceleration[j] * factor);
        if a.abs() < NEGLIGIBLE_DERIVATIVE {
            if b != 0.0 {
                x_max = x_max.min(limit / b.abs());
            }
            continue;
        }
        lower[count] = Bound {
            alpha: -limit / a.abs(),
            beta: -b / a,
        };
        upper[count] = Bound {
            alpha: limit / a.abs(),
            beta: -b / a,
        };
        count += 1;
    }
    (lower, upper, count, x_max)
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
        let (lower, upper, count, x_joint) = acceleration_bounds(&grid[i], acceleration, factor[i]);
        let mut bound = (grid[i].x_max * factor[i]).min(x_joint);
        // x + 2Δu ∈ [0, k_{i+1}].
        let step = Bound {
            alpha: 0.0,
            beta: -1.0 / (2.0 * delta),
        };
        let upper_step = Bound {
            alpha: reach[i + 1] / (2.0 * delta),
            ..step
        };
        for l in lower[..count].iter().chain([&step]) {
            for m in upper[..count].iter().chain([&upper_step]) {
                // Feasible while α_l + β_l x ≤ α_m + β_m x; at x = 0 it holds (u = 0 is
                // admissible), so only β_l > β_m bounds x.
                if l.beta > m.beta {
                    bound = bound.min((m.alpha - l.alpha) / (l.beta - m.beta));
                }
            }
        }
        reach[i] = bound.max(0.0);
    }
    // Forward pass from rest: the largest admissible u at each point.
    let mut x = vec![0.0; n + 1];
    for i in 0..n {
        let delta = grid[i + 1].s - grid[i].s;
        let (_, upper, count, _) = acceleration_bounds(&grid[i], acceleration, factor[i]);
        let u = upper[..count]
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
