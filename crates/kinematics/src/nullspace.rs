//! The null space `N` of the position Jacobian and the task-aligned basis `B(q)` (SPEC §4).

use nalgebra::{Matrix3, Matrix4, SMatrix, Vector4};
use serde::{Deserialize, Serialize};

use crate::fk::{Kinematics, PositionJacobian};
use crate::vectors::{JointVector, MAX_DOF};

/// Dimension of the null space of a full-rank 3×7 position Jacobian: the most columns a basis
/// holds.
const NULL_DIM: usize = MAX_DOF - 3;

/// An orthonormal basis of the null space of `J` (columns are basis vectors): n × (n − 3) for
/// an arm of `n` joints, zero-padded to 7×4 (the rows and columns past them are zero).
pub type NullSpaceBasis = SMatrix<f64, MAX_DOF, NULL_DIM>;

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

/// The task-aligned null-space basis `B(q)` (n × (n − 3), zero-padded to 7×4) of the RL action
/// space (Sec. 4.2).
#[derive(Clone, Debug)]
pub struct TaskBasis {
    /// Columns: the orthonormalised projections of `∇w_d`, `∇(z·n)`, `∇(−mean q̄²)`, then (seven
    /// joints) the remaining orthogonal complement or (six joints) zero.
    pub columns: NullSpaceBasis,
    /// Which of the first three columns fell back to a column of `N` (gradient ≈ 0 in the null space).
    pub fallback: [bool; 3],
}

/// Orthonormal basis `N` of the null space of `J` at `kin`: the last `n − 3` columns of the
/// orthogonal factor of a Householder QR of `Jᵀ` (no allocation). Spans the same space as the
/// right singular vectors of `J`'s zero singular values.
pub fn null_space_basis(kin: &Kinematics) -> NullSpaceBasis {
    let mut null = householder_null_space(kin.jacobian()).0;
    absent_columns_zeroed(&mut null, kin.dof());
    null
}

/// `basis` with its columns past the `n − 3` of an arm of `n = dof` joints set to zero. The
/// Householder factor of a Jacobian whose trailing columns are zero ends with the unit vectors
/// of those absent joints, exactly: its reflectors are zero in their rows.
fn absent_columns_zeroed(basis: &mut NullSpaceBasis, dof: usize) {
    for column in dof - 3..NULL_DIM {
        basis.column_mut(column).fill(0.0);
    }
}

/// The task-aligned basis `B(q) = N C` at `kin`: modified Gram–Schmidt (applied twice) of the
/// null-space projections `N Nᵀ g` of the three `gradients` in order, carried out in the
/// coordinates of `N`; a residual below `max(floor, relative·‖g‖)` is replaced by the unused
/// column of `N` with the largest residual (sign aligned with `g`). With seven joints the fourth
/// column is the remaining orthogonal complement, oriented so that `det[J; Bᵀ] > 0` (so it
/// varies continuously with `q`); with six the three columns span the null space and the fourth
/// is zero. The gradients are zero past the arm's joints. Allocation-free.
pub fn task_aligned_basis(
    kin: &Kinematics,
    gradients: [&JointVector; 3],
    cfg: &BasisConfig,
) -> TaskBasis {
    let (null, orientation) = householder_null_space(kin.jacobian());
    let null_dim = kin.dof() - 3;
    let mut coords = [Vector4::zeros(); NULL_DIM];
    let mut fallback = [false; 3];
    for (k, gradient) in gradients.into_iter().enumerate() {
        let projected = null.transpose() * gradient;
        let residual = orthogonalise(projected, &coords[..k]);
        let threshold = cfg
            .residual_floor
            .max(cfg.residual_relative * gradient.norm());
        let norm = residual.norm();
        coords[k] = if norm >= threshold {
            residual / norm
        } else {
            fallback[k] = true;
            let unit = (0..null_dim)
                .map(|axis| orthogonalise(Vector4::ith(axis, 1.0), &coords[..k]))
                .max_by(|a, b| a.norm_squared().total_cmp(&b.norm_squared()))
                .expect("null space is not empty");
            let unit = unit / unit.norm();
            if unit.dot(&projected) < 0.0 {
                -unit
            } else {
                unit
            }
        };
    }
    if null_dim == NULL_DIM {
        coords[3] = complement(&coords[0], &coords[1], &coords[2]) * orientation;
    }
    TaskBasis {
        columns: null * Matrix4::from_columns(&coords),
        fallback,
    }
}

/// Householder QR `Jᵀ = Q R`: returns `N` = the last four columns of `Q` and the sign of
/// `det[J; Nᵀ] = det(R₃ₓ₃)·det(Q)` (each proper reflector contributes `det = −1`).
///
/// Plain arrays, every sum accumulated in index order; the independent dot products of one
/// reflector (one per column it is applied to) run side by side. Reflector `k` is zero above
/// row `k`, so its sums and updates start at row `k`: the rows above would only add and
/// subtract exact zeros (the null-space columns are exactly zero there until reflector `k`
/// reaches them).
fn householder_null_space(jacobian: &PositionJacobian) -> (NullSpaceBasis, f64) {
    // Column c of Jᵀ is row c of J.
    let mut columns: [[f64; MAX_DOF]; 3] =
        std::array::from_fn(|c| std::array::from_fn(|r| jacobian[(c, r)]));
    let mut reflectors = [[0.0; MAX_DOF]; 3];
    let mut sign = 1.0;
    for k in 0..3 {
        let mut v = [0.0; MAX_DOF];
        v[k..].copy_from_slice(&columns[k][k..]);
        let norm = dot_from(k, &v, &v).sqrt();
        let alpha = if v[k] > 0.0 { -norm } else { norm };
        v[k] -= alpha;
        let length = dot_from(k, &v, &v).sqrt();
        if length > 0.0 {
            v[k..].iter_mut().for_each(|x| *x /= length);
            reflect(k, &v, &mut columns[k..]);
            sign = -sign;
        }
        if alpha < 0.0 {
            sign = -sign;
        }
        reflectors[k] = v;
    }
    let mut null: [[f64; MAX_DOF]; NULL_DIM] = std::array::from_fn(|c| {
        let mut column = [0.0; MAX_DOF];
        column[3 + c] = 1.0;
        column
    });
    for (k, v) in reflectors.iter().enumerate().rev() {
        reflect(k, v, &mut null);
    }
    (NullSpaceBasis::from_fn(|r, c| null[c][r]), sign)
}

/// `x ← x − 2 v (v·x)` for every column `x`, over the rows from `first` on (`v` is zero above
/// it).
fn reflect(first: usize, v: &[f64; MAX_DOF], columns: &mut [[f64; MAX_DOF]]) {
    let mut projections = [0.0; NULL_DIM];
    for (projection, column) in projections.iter_mut().zip(columns.iter()) {
        *projection = dot_from(first, v, column);
    }
    for (projection, column) in projections.iter().zip(columns.iter_mut()) {
        for r in first..MAX_DOF {
            column[r] -= v[r] * (2.0 * projection);
        }
    }
}

/// `a·b` over the rows from `first` on, summed in index order from zero.
#[inline]
fn dot_from(first: usize, a: &[f64; MAX_DOF], b: &[f64; MAX_DOF]) -> f64 {
    let mut sum = 0.0;
    for r in first..MAX_DOF {
        sum += a[r] * b[r];
    }
    sum
}

/// The unit vector `x` with `det[a b c x] = 1` for orthonormal `a`, `b`, `c` in R⁴ (the
/// four-dimensional cross product: cofactors of the last column).
fn complement(a: &Vector4<f64>, b: &Vector4<f64>, c: &Vector4<f64>) -> Vector4<f64> {
    let minor = |skip: usize| {
        let rows: [usize; 3] = match skip {
            0 => [1, 2, 3],
            1 => [0, 2, 3],
            2 => [0, 1, 3],
            _ => [0, 1, 2],
        };
        Matrix3::from_fn(|r, col| [a, b, c][col][rows[r]]).determinant()
    };
    Vector4::new(-minor(0), minor(1), -minor(2), minor(3))
}

/// Modified Gram–Schmidt of `v` against orthonormal `basis`, applied twice for stability.
fn orthogonalise(mut v: Vector4<f64>, basis: &[Vector4<f64>]) -> Vector4<f64> {
    for _ in 0..2 {
        for b in basis {
            v -= b * b.dot(&v);
        }
    }
    v
}
