//! The damped pseudo-inverse (SPEC §3): `σ_min` against nalgebra's SVD, `λ = 0` and
//! `J·J⁺ = I` where `σ_min ≥ 0.05`, the damping schedule `λ = 0.05·√(1 − (σ_min/0.05)²)` near
//! singularities, and `J⁺` against its SVD form `V diag(σ/(σ² + λ²)) Uᵀ` everywhere.

mod common;

use common::{random_q, rng, robot};
use emg_kinematics::{
    DampingConfig, JointVector, PositionJacobian, Robot, damped_pseudo_inverse, rotation_from_rpy,
};
use nalgebra::{Matrix3, SMatrix};

fn svd_sigma_min(j: &PositionJacobian) -> f64 {
    j.svd(false, false).singular_values.min()
}

fn expected_lambda(sigma: f64) -> f64 {
    if sigma < 0.05 {
        0.05 * (1.0 - (sigma / 0.05).powi(2)).sqrt()
    } else {
        0.0
    }
}

/// `J⁺` from the SVD: `V diag(σ/(σ² + λ²)) Uᵀ`.
fn svd_pseudo_inverse(j: &PositionJacobian, lambda: f64) -> SMatrix<f64, 7, 3> {
    let svd = j.svd(true, true);
    let (u, v_t) = (svd.u.expect("u"), svd.v_t.expect("v_t"));
    let gains = Matrix3::from_diagonal(&svd.singular_values.map(|s| s / (s * s + lambda * lambda)));
    v_t.transpose() * gains * u.transpose()
}

/// Configurations with `σ_min < 0.05`, found by random search and then by descending `σ_min`.
fn near_singular_configurations(robot: &Robot, count: usize) -> Vec<JointVector> {
    let mut rng = rng(22);
    let mut found = Vec::new();
    for _ in 0..200_000 {
        if found.len() == count {
            break;
        }
        let q = random_q(&mut rng, robot);
        if svd_sigma_min(robot.forward(&q).jacobian()) < 0.05 {
            found.push(q);
        }
    }
    found
}

#[test]
fn sigma_min_matches_svd_and_well_conditioned_inverse_is_exact() {
    let robot = robot();
    let mut rng = rng(20);
    let cfg = DampingConfig::default();
    let (mut worst_sigma, mut worst_identity, mut worst_lambda, mut worst_svd_form) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut undamped = 0;
    for _ in 0..1000 {
        let q = random_q(&mut rng, &robot);
        let kin = robot.forward(&q);
        let j = kin.jacobian();
        let pinv = damped_pseudo_inverse(j, &cfg);
        let sigma = svd_sigma_min(j);
        worst_sigma = worst_sigma.max((pinv.sigma_min() - sigma).abs());
        worst_lambda = worst_lambda.max((pinv.lambda - expected_lambda(sigma)).abs());
        worst_svd_form =
            worst_svd_form.max((pinv.matrix - svd_pseudo_inverse(j, pinv.lambda)).amax());
        if sigma > 0.05 + 1e-9 {
            undamped += 1;
            assert_eq!(
                pinv.lambda, 0.0,
                "no damping above the threshold (σ_min = {sigma})"
            );
            worst_identity = worst_identity.max((j * pinv.matrix - Matrix3::identity()).amax());
        }
    }
    println!(
        "pseudo-inverse (1,000 configs, {undamped} undamped): |σ_min − SVD| {worst_sigma:.3e}, \
         ‖JJ⁺ − I‖ {worst_identity:.3e}, |λ − schedule| {worst_lambda:.3e}, ‖J⁺ − SVD form‖ {worst_svd_form:.3e}"
    );
    assert!(undamped > 500);
    assert!(
        worst_sigma < 1e-9,
        "σ_min differs from the SVD by {worst_sigma:e}"
    );
    assert!(worst_identity < 1e-9, "J·J⁺ − I = {worst_identity:e}");
    assert!(
        worst_lambda < 1e-9,
        "λ differs from the schedule by {worst_lambda:e}"
    );
    assert!(
        worst_svd_form < 1e-8,
        "J⁺ differs from its SVD form by {worst_svd_form:e}"
    );
}

#[test]
fn damping_follows_the_schedule_near_singularities() {
    let robot = robot();
    let cfg = DampingConfig::default();
    let configurations = near_singular_configurations(&robot, 50);
    assert!(
        configurations.len() >= 10,
        "found only {} near-singular configurations",
        configurations.len()
    );
    let (mut worst_sigma, mut worst_lambda, mut worst_svd_form, mut smallest) =
        (0.0f64, 0.0f64, 0.0f64, f64::INFINITY);
    for q in &configurations {
        let j = *robot.forward(q).jacobian();
        let pinv = damped_pseudo_inverse(&j, &cfg);
        let sigma = svd_sigma_min(&j);
        smallest = smallest.min(sigma);
        assert!(sigma < 0.05);
        assert!(
            pinv.lambda > 0.0,
            "damping must be active below the threshold"
        );
        worst_sigma = worst_sigma.max((pinv.sigma_min() - sigma).abs());
        worst_lambda = worst_lambda.max((pinv.lambda - expected_lambda(sigma)).abs());
        worst_svd_form =
            worst_svd_form.max((pinv.matrix - svd_pseudo_inverse(&j, pinv.lambda)).amax());
        // Damping bounds the joint speed of a unit Cartesian command by 1/(2λ)-ish, never by 1/σ.
        let gain = pinv.matrix.norm();
        assert!(
            gain <= 1.0 / (2.0 * pinv.lambda) * 3.0f64.sqrt() + 1e-9,
            "damped gain {gain}"
        );
    }
    println!(
        "near-singular ({} configs, smallest σ_min {smallest:.3e}): |σ_min − SVD| {worst_sigma:.3e}, \
         |λ − schedule| {worst_lambda:.3e}, ‖J⁺ − SVD form‖ {worst_svd_form:.3e}",
        configurations.len()
    );
    assert!(
        worst_sigma < 1e-9,
        "σ_min differs from the SVD by {worst_sigma:e}"
    );
    assert!(
        worst_lambda < 1e-9,
        "λ differs from the schedule by {worst_lambda:e}"
    );
    assert!(
        worst_svd_form < 1e-8,
        "J⁺ differs from its SVD form by {worst_svd_form:e}"
    );
}

#[test]
fn exact_singularity_gets_full_damping() {
    // A rank-deficient Jacobian (two rows equal): σ_min = 0, so λ = λ_max and J⁺ stays finite.
    let mut j = PositionJacobian::from_fn(|r, c| libm::sin((r * 7 + c) as f64 * 0.37));
    let row = j.row(0).into_owned();
    j.set_row(1, &row);
    let pinv = damped_pseudo_inverse(&j, &DampingConfig::default());
    assert!(pinv.sigma_min() < 1e-7, "σ_min = {}", pinv.sigma_min());
    assert!((pinv.lambda - 0.05).abs() < 1e-9, "λ = {}", pinv.lambda);
    assert!(pinv.matrix.iter().all(|v| v.is_finite()));
    assert!((pinv.matrix - svd_pseudo_inverse(&j, pinv.lambda)).amax() < 1e-6);
}

#[test]
fn sigma_min_is_accurate_for_clustered_singular_values() {
    // Synthetic J = U diag(σ₁, σ₂, σ₃) Vᵀ with the two largest singular values (nearly) equal,
    // the hardest case for a closed-form 3×3 eigenvalue, and with tiny σ_min.
    let mut rng = rng(23);
    let (mut worst, mut worst_squared) = (0.0f64, 0.0f64);
    for case in 0..2000 {
        let u = nalgebra::Rotation3::new(common::random_point(&mut rng, 3.0)).into_inner();
        let basis = SMatrix::<f64, 7, 7>::from_fn(|_, _| common::random_point(&mut rng, 1.0).x);
        let v = basis.qr().q().fixed_columns::<3>(0).into_owned();
        let large = 0.2 + common::random_point(&mut rng, 0.5).x.abs();
        let spread = [0.0, 1e-12, 1e-8, 1e-4][case % 4];
        let sigma = [0.0, 1e-6, 1e-3, 0.03, 0.1][case % 5] * large;
        let s = Matrix3::from_diagonal(&nalgebra::Vector3::new(
            large,
            large * (1.0 + spread),
            sigma,
        ));
        let j: PositionJacobian = u * s * v.transpose();
        let pinv = damped_pseudo_inverse(&j, &DampingConfig::default());
        // σ_min comes from the eigenvalues of JJᵀ, whose absolute error is ~ε·σ₁²; at an
        // exact singularity that is √ε·σ₁ ≈ 1e-8 in σ (harmless: dλ/dσ = 0 there). Away from
        // it σ_min must be accurate to 1e-9; everywhere σ_min² must be accurate to 1e-14·σ₁².
        let squared_error = (pinv.sigma_min().powi(2) - sigma * sigma).abs() / (large * large);
        worst_squared = worst_squared.max(squared_error);
        if sigma >= 1e-6 {
            worst = worst.max((pinv.sigma_min() - sigma).abs());
        }
    }
    println!(
        "clustered singular values: worst |σ_min − σ₃| {worst:.3e} (σ₃ ≥ 1e-6), worst |σ_min² − σ₃²|/σ₁² {worst_squared:.3e}"
    );
    assert!(worst < 1e-9, "σ_min off by {worst:e}");
    assert!(worst_squared < 1e-14, "σ_min² off by {worst_squared:e} σ₁²");
}

#[test]
fn damping_decision_at_the_threshold_follows_the_eigenvalue() {
    // Jacobians with singular values (1, 0.5, σ) for σ swept across σ_0 = 0.05, in a rotated
    // frame: the well-conditioned shortcut must give the λ the eigenvalue gives.
    let cfg = DampingConfig::default();
    let rotation = rotation_from_rpy(0.3, -0.7, 1.1).into_inner();
    let mut damped = 0;
    for k in -200..=200 {
        let sigma = cfg.sigma_threshold * (1.0 + f64::from(k) * 1e-8);
        let mut j = PositionJacobian::zeros();
        j[(0, 1)] = 1.0;
        j[(1, 4)] = 0.5;
        j[(2, 6)] = sigma;
        let j = rotation * j;
        let pinv = damped_pseudo_inverse(&j, &cfg);
        let from_eigenvalue = if pinv.sigma_min() < cfg.sigma_threshold {
            cfg.lambda_max * (1.0 - (pinv.sigma_min() / cfg.sigma_threshold).powi(2)).sqrt()
        } else {
            0.0
        };
        assert_eq!(pinv.lambda, from_eigenvalue, "σ = {sigma}");
        damped += usize::from(pinv.lambda > 0.0);
    }
    assert!((150..=250).contains(&damped), "{damped} of 401 damped");
}
