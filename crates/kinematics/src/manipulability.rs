//! Directional manipulability `w_d` and the tool-alignment objective `z·n`, with analytic gradients.

use nalgebra::Matrix3;

use crate::fk::Kinematics;
use crate::vectors::{JointVector, MAX_DOF, Vec3};

/// Directional manipulability `w_d = (dᵀ(JJᵀ + λ_μ²I)⁻¹d)^(−1/2)` (SPEC §4, the `k_μ` term of
/// Eq. 3) and its analytic gradient.
///
/// With `A = JJᵀ + λ_μ²I`, `w = A⁻¹d`, `s = dᵀw`:
/// `∂w_d/∂q_i = s^(−3/2) · wᵀ H_i (Jᵀw)` where `H_i = ∂J/∂q_i` has columns
/// `∂J_k/∂q_i = ω_min(i,k) × J_max(i,k)` (revolute joints).
/// `gram` is `JJᵀ` of `kin`'s Jacobian ([`Kinematics::jacobian_gram`], or
/// [`crate::DampedPseudoInverse::gram`] where the step has built the pseudo-inverse already).
/// Returns `(w_d, ∇w_d)`; allocation-free.
pub fn directional_manipulability(
    kin: &Kinematics,
    gram: &Matrix3<f64>,
    d: &Vec3,
    lambda_mu: f64,
) -> (f64, JointVector) {
    debug_assert_eq!(
        *gram,
        kin.jacobian_gram(),
        "gram is JJᵀ of this configuration"
    );
    let jacobian = kin.jacobian();
    let a = gram + Matrix3::identity() * (lambda_mu * lambda_mu);
    let w = a.try_inverse().unwrap_or_else(Matrix3::zeros) * d;
    let s = d.dot(&w);
    if s <= 0.0 {
        return (0.0, JointVector::zeros());
    }
    let value = 1.0 / s.sqrt();
    let u = jacobian.transpose() * w;
    let axes: [Vec3; MAX_DOF] = std::array::from_fn(|i| kin.joint_axis(i));
    let columns: [Vec3; MAX_DOF] = std::array::from_fn(|k| jacobian.column(k).into_owned());
    let scale = value * value * value;
    // wᵀH_i u = Σ_{k≥i} u_k w·(ω_i × J_k) + Σ_{k<i} u_k w·(ω_k × J_i)
    //         = ω_i·Σ_{k≥i} u_k (J_k × w) + J_i·Σ_{k<i} u_k (w × ω_k):
    // suffix and prefix sums turn the 49 triple products into 14 cross products.
    let mut suffix = [Vec3::zeros(); MAX_DOF + 1];
    for k in (0..MAX_DOF).rev() {
        suffix[k] = suffix[k + 1] + columns[k].cross(&w) * u[k];
    }
    let mut prefix = Vec3::zeros();
    let mut gradient = JointVector::zeros();
    for i in 0..MAX_DOF {
        gradient[i] = (axes[i].dot(&suffix[i]) + columns[i].dot(&prefix)) * scale;
        prefix += w.cross(&axes[i]) * u[i];
    }
    (value, gradient)
}

/// Gradient of the tool alignment `z(q)·n` (the `k_θ` term of Eq. 3):
/// `∂(z·n)/∂q_i = n·(ω_i × z) = ω_i·(z × n)`.
pub fn tool_alignment_gradient(kin: &Kinematics, n: &Vec3) -> JointVector {
    let z_cross_n = kin.tool_axis().cross(n);
    JointVector::from_fn(|i, _| kin.joint_axis(i).dot(&z_cross_n))
}
