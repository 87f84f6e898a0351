//! The null-space basis `N` and the task-aligned basis `B(q)` (SPEC §4) on 1,000 random
//! configurations: `N` orthonormal with `J·N ≈ 0` and spanning the SVD null space; `B`
//! orthonormal, in the null space, spanning the same space as `N`, with its first three columns
//! the Gram–Schmidt sequence of the projected gradients `[∇w_d, ∇(z·n), ∇(−mean q̄²)]`, a 4th
//! column continuous under small perturbations of q, and the fallback path for a zero gradient;
//! on an arm of six joints (UR5e), three columns of each over its six joints, the rest zero.

mod common;

use common::{random_q, random_unit, rng, robot};
use emg_kinematics::{
    BasisConfig, JointVector, NullSpaceBasis, Robot, TaskBasis, Vec3, directional_manipulability,
    null_space_basis, task_aligned_basis, tool_alignment_gradient,
};
use nalgebra::{SMatrix, SVector};

const CONFIGS: usize = 1000;

type Identity4 = SMatrix<f64, 4, 4>;

/// The three SPEC §4 gradients at q for task direction d and plane normal n.
fn gradients(robot: &Robot, q: &JointVector, d: &Vec3, n: &Vec3) -> [JointVector; 3] {
    let kin = robot.forward(q);
    let (_, grad_wd) = directional_manipulability(&kin, &kin.jacobian_gram(), d, 1e-3);
    let grad_align = tool_alignment_gradient(&kin, n);
    let limits = robot.limits();
    let grad_centre =
        -(2.0 / robot.dof() as f64) * limits.normalise(q).component_div(&limits.half_range());
    [grad_wd, grad_align, grad_centre]
}

fn basis_at(robot: &Robot, q: &JointVector, d: &Vec3, n: &Vec3) -> (NullSpaceBasis, TaskBasis) {
    let kin = robot.forward(q);
    let null = null_space_basis(&kin);
    let [g0, g1, g2] = gradients(robot, q, d, n);
    let basis = task_aligned_basis(&kin, [&g0, &g1, &g2], &BasisConfig::default());
    (null, basis)
}

#[test]
fn null_space_basis_is_orthonormal_and_annihilated_by_the_jacobian() {
    let robot = robot();
    let mut rng = rng(10);
    let (mut worst_orth, mut worst_null, mut worst_svd) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..CONFIGS {
        let q = random_q(&mut rng, &robot);
        let kin = robot.forward(&q);
        let j = kin.jacobian();
        let null = null_space_basis(&kin);
        worst_orth = worst_orth.max((null.transpose() * null - Identity4::identity()).amax());
        worst_null = worst_null.max((j * null).amax());
        // Same space as the right singular vectors of the zero singular values: the projector
        // N Nᵀ equals I − V₃V₃ᵀ, V₃ = the right singular vectors of the non-zero singular values.
        let svd = j.svd(false, true);
        let v_t = svd.v_t.expect("v_t requested");
        let row_projector = v_t.transpose() * v_t;
        let reference = SMatrix::<f64, 7, 7>::identity() - row_projector;
        worst_svd = worst_svd.max((null * null.transpose() - reference).amax());
    }
    println!(
        "N: ‖NᵀN − I‖max {worst_orth:.3e}, ‖JN‖max {worst_null:.3e}, projector vs SVD {worst_svd:.3e}"
    );
    assert!(worst_orth < 1e-10, "NᵀN − I = {worst_orth:e}");
    assert!(worst_null < 1e-10, "J·N = {worst_null:e}");
    assert!(
        worst_svd < 1e-9,
        "N Nᵀ differs from the SVD null-space projector by {worst_svd:e}"
    );
}

#[test]
fn task_aligned_basis_is_an_ordered_gram_schmidt_basis_of_the_null_space() {
    let robot = robot();
    let mut rng = rng(11);
    let (mut worst_orth, mut worst_null, mut worst_span, mut worst_order) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut non_fallback = [0usize; 3];
    for _ in 0..CONFIGS {
        let q = random_q(&mut rng, &robot);
        let d = random_unit(&mut rng);
        let n = random_unit(&mut rng);
        let kin = robot.forward(&q);
        let (null, basis) = basis_at(&robot, &q, &d, &n);
        let b = basis.columns;
        worst_orth = worst_orth.max((b.transpose() * b - Identity4::identity()).amax());
        worst_null = worst_null.max((kin.jacobian() * b).amax());
        worst_span = worst_span.max((b * b.transpose() - null * null.transpose()).amax());
        // det[J; Bᵀ] > 0 fixes the orientation of the 4th column.
        let mut frame = SMatrix::<f64, 7, 7>::zeros();
        frame.fixed_rows_mut::<3>(0).copy_from(kin.jacobian());
        frame.fixed_rows_mut::<4>(3).copy_from(&b.transpose());
        assert!(frame.determinant() > 0.0, "det[J; Bᵀ] must be positive");
        // Column k (when not a fallback) is the normalised residual of N Nᵀ g_k against the
        // previous columns: in particular column 0 is parallel to N Nᵀ ∇w_d, same sign.
        let projector = null * null.transpose();
        for (k, g) in gradients(&robot, &q, &d, &n).iter().enumerate() {
            if basis.fallback[k] {
                continue;
            }
            non_fallback[k] += 1;
            let mut residual: SVector<f64, 7> = projector * g;
            for c in 0..k {
                let column = b.column(c);
                residual -= column * column.dot(&residual);
            }
            let expected = residual / residual.norm();
            worst_order = worst_order.max((b.column(k) - expected).norm());
        }
    }
    println!(
        "B: ‖BᵀB − I‖ {worst_orth:.3e}, ‖JB‖ {worst_null:.3e}, ‖BBᵀ − NNᵀ‖ {worst_span:.3e}, \
         columns vs Gram–Schmidt {worst_order:.3e} (non-fallback counts {non_fallback:?})"
    );
    assert!(
        non_fallback[0] > CONFIGS * 9 / 10,
        "∇w_d should rarely fall back"
    );
    assert!(worst_orth < 1e-10, "BᵀB − I = {worst_orth:e}");
    assert!(worst_null < 1e-10, "J·B = {worst_null:e}");
    assert!(worst_span < 1e-9, "B Bᵀ − N Nᵀ = {worst_span:e}");
    assert!(
        worst_order < 1e-6,
        "columns differ from ordered Gram–Schmidt by {worst_order:e}"
    );
}

/// Largest change of any column of `B` between `q` and `q + dq`.
fn column_changes(
    robot: &Robot,
    q: &JointVector,
    dq: &JointVector,
    d: &Vec3,
    n: &Vec3,
) -> [f64; 4] {
    let (_, b1) = basis_at(robot, q, d, n);
    let (_, b2) = basis_at(robot, &(q + dq), d, n);
    std::array::from_fn(|k| (b1.columns.column(k) - b2.columns.column(k)).norm())
}

fn random_direction7(rng: &mut rand_chacha::ChaCha8Rng) -> JointVector {
    let v = JointVector::from_fn(|_, _| common::random_point(rng, 1.0).x);
    v / v.norm()
}

#[test]
fn task_aligned_basis_is_continuous_in_q() {
    let robot = robot();
    let mut rng = rng(12);
    let (mut worst_last, mut worst_all, mut worst_conditioned) = (0.0f64, 0.0f64, 0.0f64);
    let mut worst_ratio = 0.0f64;
    for _ in 0..CONFIGS {
        let q = random_q(&mut rng, &robot);
        let d = random_unit(&mut rng);
        let n = random_unit(&mut rng);
        let direction = random_direction7(&mut rng);
        let big = column_changes(&robot, &q, &(direction * 1e-5), &d, &n);
        let small = column_changes(&robot, &q, &(direction * 1e-6), &d, &n);
        let big_max = big.iter().copied().fold(0.0, f64::max);
        let small_max = small.iter().copied().fold(0.0, f64::max);
        worst_last = worst_last.max(big[3]);
        worst_all = worst_all.max(big_max);
        // A jump (sign flip, column swap) does not shrink with the step; a smooth change
        // shrinks tenfold for a tenfold smaller step.
        worst_ratio = worst_ratio.max(small_max / big_max.max(1e-300));
        // Where every projected gradient keeps ≥ 10 % of its norm in the null space, the
        // Gram–Schmidt sequence is well conditioned and every column moves less than 1e-3.
        let kin = robot.forward(&q);
        let null = null_space_basis(&kin);
        let conditioned = gradients(&robot, &q, &d, &n)
            .iter()
            .all(|g| (null * (null.transpose() * g)).norm() >= 0.1 * g.norm());
        if conditioned {
            worst_conditioned = worst_conditioned.max(big_max);
        }
    }
    println!(
        "B continuity (|Δq| = 1e-5): 4th column {worst_last:.3e}, all columns {worst_all:.3e}, \
         well-conditioned configs {worst_conditioned:.3e}; worst change ratio 1e-6/1e-5 step {worst_ratio:.4}"
    );
    assert!(
        worst_last < 1e-2,
        "4th column moved by {worst_last:e} for |Δq| = 1e-5"
    );
    assert!(
        worst_all < 1e-2,
        "a column moved by {worst_all:e} for |Δq| = 1e-5"
    );
    assert!(
        worst_conditioned < 1e-3,
        "a column moved by {worst_conditioned:e} on a well-conditioned config"
    );
    assert!(
        worst_ratio < 0.15,
        "a column change did not scale with the step (ratio {worst_ratio})"
    );
}

#[test]
fn fourth_column_never_flips_along_a_path() {
    // Walk 2,000 steps of 2 mrad through joint space (reflecting at the limits); the 4th
    // column's orientation must never reverse between consecutive steps.
    let robot = robot();
    let limits = robot.limits().clone();
    let mut rng = rng(14);
    let d = random_unit(&mut rng);
    let n = random_unit(&mut rng);
    let mut q = robot.mid_range();
    let mut direction = random_direction7(&mut rng);
    let (_, mut previous) = basis_at(&robot, &q, &d, &n);
    let mut worst_dot = f64::INFINITY;
    for step in 0..2000 {
        if step % 50 == 0 {
            direction = random_direction7(&mut rng);
        }
        let next = q + direction * 2e-3;
        if limits.first_violation(&next, 0.0).is_some() {
            direction = -direction;
            continue;
        }
        q = next;
        let (_, current) = basis_at(&robot, &q, &d, &n);
        worst_dot = worst_dot.min(current.columns.column(3).dot(&previous.columns.column(3)));
        previous = current;
    }
    println!("path: smallest dot product of consecutive 4th columns {worst_dot:.6}");
    assert!(
        worst_dot > 0.5,
        "4th column reversed along the path (dot {worst_dot})"
    );
}

#[test]
fn zero_gradient_falls_back_to_a_null_space_column() {
    let robot = robot();
    let mut rng = rng(13);
    for _ in 0..200 {
        let q = random_q(&mut rng, &robot);
        let d = random_unit(&mut rng);
        let n = random_unit(&mut rng);
        let kin = robot.forward(&q);
        let null = null_space_basis(&kin);
        let [_, g1, g2] = gradients(&robot, &q, &d, &n);
        let zero = JointVector::zeros();
        let basis = task_aligned_basis(&kin, [&zero, &g1, &g2], &BasisConfig::default());
        assert!(basis.fallback[0], "a zero gradient must fall back");
        let b = basis.columns;
        assert!((b.transpose() * b - Identity4::identity()).amax() < 1e-10);
        assert!((kin.jacobian() * b).amax() < 1e-10);
        assert!((b * b.transpose() - null * null.transpose()).amax() < 1e-9);
        // A gradient lying entirely in J's row space projects to zero in the null space too.
        let row_gradient: JointVector = kin.jacobian().transpose() * random_unit(&mut rng);
        let basis = task_aligned_basis(&kin, [&g1, &row_gradient, &g2], &BasisConfig::default());
        assert!(
            basis.fallback[1],
            "a gradient in the row space of J must fall back"
        );
        assert!(!basis.fallback[0]);
        let b = basis.columns;
        assert!((b.transpose() * b - Identity4::identity()).amax() < 1e-10);
        assert!((kin.jacobian() * b).amax() < 1e-10);
    }
}

#[test]
fn a_six_joint_arm_has_three_basis_columns_over_its_own_joints() {
    let robot = common::ur5e();
    let mut rng = rng(60);
    let identity3 = SMatrix::<f64, 3, 3>::identity();
    for _ in 0..CONFIGS {
        let q = random_q(&mut rng, &robot);
        let (d, n) = (random_unit(&mut rng), random_unit(&mut rng));
        let kin = robot.forward(&q);
        let (null, basis) = basis_at(&robot, &q, &d, &n);
        for b in [&null, &basis.columns] {
            assert!(b.column(3).iter().all(|v| *v == 0.0), "fourth column {b}");
            assert!(
                b.row(6).iter().all(|v| *v == 0.0),
                "seventh joint moves: {b}"
            );
            let active = b.fixed_view::<7, 3>(0, 0);
            assert!((active.transpose() * active - identity3).amax() < 1e-12);
            assert!((kin.jacobian() * active).amax() < 1e-12);
        }
        // Both span the null space of the 3×6 Jacobian (its SVD's last three right singular
        // vectors): equal orthogonal projectors.
        let jacobian6 = kin.jacobian().fixed_view::<3, 6>(0, 0).into_owned();
        let gram = jacobian6.transpose() * jacobian6;
        let eigen = gram.symmetric_eigen();
        let mut order: Vec<usize> = (0..6).collect();
        order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
        let mut svd_projector = SMatrix::<f64, 6, 6>::zeros();
        for &k in &order[..3] {
            let v = eigen.eigenvectors.column(k);
            svd_projector += v * v.transpose();
        }
        for b in [&null, &basis.columns] {
            let active = b.fixed_view::<6, 3>(0, 0);
            let projector = active * active.transpose();
            assert!((projector - svd_projector).amax() < 1e-8);
        }
        // The first column follows the projected manipulability gradient unless it fell back.
        if !basis.fallback[0] {
            let [g0, _, _] = gradients(&robot, &q, &d, &n);
            let projected = null * (null.transpose() * g0);
            assert!((basis.columns.column(0) - projected.normalize()).norm() < 1e-9);
        }
    }
}
