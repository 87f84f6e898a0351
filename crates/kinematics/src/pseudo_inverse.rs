//! Damped pseudo-inverse `J⁺ = Jᵀ(JJᵀ + λ²I)⁻¹` with variable damping (SPEC §3, Eq. 2).

use nalgebra::{Matrix3, SMatrix};
use serde::{Deserialize, Serialize};

use crate::fk::PositionJacobian;
use crate::vectors::MAX_DOF;

/// Variable-damping schedule: `λ = λ_max·√(1 − (σ_min/σ_0)²)` when `σ_min < σ_0`, else 0.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DampingConfig {
    /// Singular-value threshold `σ_0` below which damping starts.
    pub sigma_threshold: f64,
    /// Damping `λ_max` reached at a singularity (`σ_min = 0`).
    pub lambda_max: f64,
}

impl Default for DampingConfig {
    fn default() -> Self {
        Self {
            sigma_threshold: 0.05,
            lambda_max: 0.05,
        }
    }
}

/// Relative margin above `σ_0²` within which the damping decision is left to the eigenvalue:
/// far above the eigenvalue's rounding error, so the shortcut never changes `λ`.
const WELL_CONDITIONED_MARGIN: f64 = 1e-6;

/// The damped pseudo-inverse and the quantities it was built from.
#[derive(Clone, Debug)]
pub struct DampedPseudoInverse {
    /// `J⁺` (7×3).
    pub matrix: SMatrix<f64, MAX_DOF, 3>,
    /// Damping `λ` that was applied.
    pub lambda: f64,
    /// `JJᵀ`, kept for [`DampedPseudoInverse::sigma_min`] and [`DampedPseudoInverse::gram`].
    gram: Matrix3<f64>,
}

impl DampedPseudoInverse {
    /// `JJᵀ` of the Jacobian it was built from (for [`crate::directional_manipulability`],
    /// so that a step computes the product once).
    pub fn gram(&self) -> &Matrix3<f64> {
        &self.gram
    }

    /// Smallest singular value `σ_min` of `J` (closed-form eigenvalue of `JJᵀ`).
    pub fn sigma_min(&self) -> f64 {
        smallest_symmetric_eigenvalue(&self.gram).max(0.0).sqrt()
    }
}

/// `J⁺ = Jᵀ(JJᵀ + λ²I)⁻¹` with `λ` from [`DampingConfig`] (no allocation).
///
/// `σ_min` is only computed where damping may apply: when `JJᵀ − σ_0²(1 + 10⁻⁶) I` is positive
/// definite (Sylvester's criterion, a few products), `σ_min > σ_0` and `λ = 0`.
pub fn damped_pseudo_inverse(
    jacobian: &PositionJacobian,
    cfg: &DampingConfig,
) -> DampedPseudoInverse {
    let jjt = jacobian * jacobian.transpose();
    let threshold_squared = cfg.sigma_threshold * cfg.sigma_threshold;
    let lambda =
        if positive_definite_above(&jjt, threshold_squared * (1.0 + WELL_CONDITIONED_MARGIN)) {
            0.0
        } else {
            let sigma_min = smallest_symmetric_eigenvalue(&jjt).max(0.0).sqrt();
            if sigma_min < cfg.sigma_threshold {
                cfg.lambda_max * (1.0 - (sigma_min / cfg.sigma_threshold).powi(2)).sqrt()
            } else {
                0.0
            }
        };
    let damped = jjt + Matrix3::identity() * (lambda * lambda);
    let inverse = damped.try_inverse().unwrap_or_else(Matrix3::zeros);
    DampedPseudoInverse {
        matrix: jacobian.transpose() * inverse,
        lambda,
        gram: jjt,
    }
}

/// Whether the symmetric `m − shift·I` is positive definite (its leading principal minors are
/// positive), i.e. every eigenvalue of `m` exceeds `shift`.
fn positive_definite_above(m: &Matrix3<f64>, shift: f64) -> bool {
    let (a, b, c) = (m[(0, 0)] - shift, m[(1, 1)] - shift, m[(2, 2)] - shift);
    let (ab, ac, bc) = (m[(0, 1)], m[(0, 2)], m[(1, 2)]);
    let minor2 = a * b - ab * ab;
    let minor3 = a * (b * c - bc * bc) - ab * (ab * c - bc * ac) + ac * (ab * bc - b * ac);
    a > 0.0 && minor2 > 0.0 && minor3 > 0.0
}

/// Smallest eigenvalue of a symmetric 3×3 matrix, in closed form (trigonometric method).
pub(crate) fn smallest_symmetric_eigenvalue(m: &Matrix3<f64>) -> f64 {
    let p1 = m[(0, 1)].powi(2) + m[(0, 2)].powi(2) + m[(1, 2)].powi(2);
    let trace_third = m.trace() / 3.0;
    if p1 <= f64::EPSILON * m.norm_squared() {
        return m[(0, 0)].min(m[(1, 1)]).min(m[(2, 2)]);
    }
    let p2 = (m[(0, 0)] - trace_third).powi(2)
        + (m[(1, 1)] - trace_third).powi(2)
        + (m[(2, 2)] - trace_third).powi(2)
        + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let b = (m - Matrix3::identity() * trace_third) / p;
    let r = (b.determinant() * 0.5).clamp(-1.0, 1.0);
    let phi = libm::acos(r) / 3.0;
    trace_third + 2.0 * p * libm::cos(phi + 2.0 * std::f64::consts::FRAC_PI_3)
}
