//! The null space `N` of the position Jacobian and the task-aligned basis `B(q)` (SPEC §4).

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

use crate::fk::PositionJacobian;
use crate::{DOF, JointVector};

/// Dimension of the null space of a full-rank 3×7 position Jacobian.
const NULL_DIM: usize = DOF - 3;

/// An orthonormal basis of the null space of `J` (7×4, columns are basis vectors).
pub type NullSpaceBasis = SMatrix<f64, DOF, NULL_DIM>;

/// Thresholds of the Gram–Schmidt construction of `B(q)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BasisConfig {
    /// Absolute floor of the residual below which a projected gradient is replaced.
    pub residual_floor: f64,
    /// Residual threshold relative to the gradient's norm.
    pub residual_relative: f64,
}

impl Default for BasisConfig {
    fn default() -> Self {
        Self {
            residual_floor: 1e-8,
            residual_relative: 1e-3,
        }
    }
}

/// The task-aligned null-space basis `B(q)` (7×4) of the RL action space (Sec. 4.2).
#[derive(Clone, Debug)]
pub struct TaskBasis {
    /// Columns: the orthonormalised projections of `∇w_d`, `∇(z·n)`, `∇(−mean q̄²)`, then the
    /// remaining orthogonal complement.
    pub columns: NullSpaceBasis,
    /// Which of the first three columns fell back to a column of `N` (gradient ≈ 0 in the null space).
    pub fallback: [bool; 3],
}

/// Orthonormal basis `N` of the null space of `J`: the orthogonal complement of `J`'s row
/// space, completed from the coordinate axes with largest residual first. Spans the same space
/// as the right singular vectors of `J`'s zero singular values.
pub fn null_space_basis(jacobian: &PositionJacobian) -> NullSpaceBasis {
    let mut rows = [JointVector::zeros(); 3];
    let mut rank = 0;
    for r in 0..3 {
        let row = jacobian.row(r).transpose();
        let scale = row.norm();
        let residual = orthogonalise(row, &rows[..rank]);
        let norm = residual.norm();
        if norm > 1e-12 * scale.max(1e-300) && norm > 1e-300 {
            rows[rank] = residual / norm;
            rank += 1;
        }
    }
    let mut basis = [JointVector::zeros(); DOF];
    basis[..rank].copy_from_slice(&rows[..rank]);
    let mut found = rank;
    let mut null = NullSpaceBasis::zeros();
    for column in 0..NULL_DIM {
        let best = (0..DOF)
            .map(|axis| orthogonalise(JointVector::ith(axis, 1.0), &basis[..found]))
            .max_by(|a, b| a.norm_squared().total_cmp(&b.norm_squared()))
            .expect("DOF > 0");
        let unit = best / best.norm();
        basis[found] = unit;
        found += 1;
        null.set_column(column, &unit);
    }
    null
}

/// The task-aligned basis `B(q)`: modified Gram–Schmidt (applied twice) of `N Nᵀ g` for the
/// three `gradients` in order; a residual below `max(floor, relative·‖g‖)` is replaced by the
/// unused column of `N` with the largest residual (sign aligned with `g`); the fourth column is
/// the remaining orthogonal complement, oriented so that `det[J; Bᵀ] > 0` (continuous in `q`).
pub fn task_aligned_basis(
    jacobian: &PositionJacobian,
    null: &NullSpaceBasis,
    gradients: [&JointVector; 3],
    cfg: &BasisConfig,
) -> TaskBasis {
    let mut columns = [JointVector::zeros(); NULL_DIM];
    let mut fallback = [false; 3];
    for (k, gradient) in gradients.into_iter().enumerate() {
        let projected = null * (null.transpose() * gradient);
        let residual = orthogonalise(projected, &columns[..k]);
        let threshold = cfg.residual_floor.max(cfg.residual_relative * gradient.norm());
        let norm = residual.norm();
        columns[k] = if norm >= threshold {
            residual / norm
        } else {
            fallback[k] = true;
            let unit = largest_complement(null, &columns[..k]);
            if unit.dot(gradient) < 0.0 { -unit } else { unit }
        };
    }
    let mut last = largest_complement(null, &columns[..3]);
    let mut frame = SMatrix::<f64, DOF, DOF>::zeros();
    for r in 0..3 {
        frame.set_row(r, &jacobian.row(r));
    }
    for (k, column) in columns[..3].iter().enumerate() {
        frame.set_row(3 + k, &column.transpose());
    }
    frame.set_row(6, &last.transpose());
    if frame.determinant() < 0.0 {
        last = -last;
    }
    columns[3] = last;
    TaskBasis {
        columns: NullSpaceBasis::from_columns(&columns),
        fallback,
    }
}

/// The column of `N` with the largest residual against `used`, orthogonalised and normalised.
fn largest_complement(null: &NullSpaceBasis, used: &[JointVector]) -> JointVector {
    let best = (0..NULL_DIM)
        .map(|c| orthogonalise(null.column(c).into_owned(), used))
        .max_by(|a, b| a.norm_squared().total_cmp(&b.norm_squared()))
        .expect("null space is not empty");
    best / best.norm()
}

/// Modified Gram–Schmidt of `v` against orthonormal `basis`, applied twice for stability.
fn orthogonalise<const R: usize>(mut v: SVector<f64, R>, basis: &[SVector<f64, R>]) -> SVector<f64, R> {
    for _ in 0..2 {
        for b in basis {
            v -= b * b.dot(&v);
        }
    }
    v
}
