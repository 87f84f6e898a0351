//! Every analytic derivative of the crate against central finite differences (step 1e-6) of the
//! value it differentiates, evaluated through `Robot::forward`, on 1,000 random configurations
//! within the limits, on an arm of seven joints (FR3) and one of six (UR5e, whose seventh entries
//! are then exactly zero on both sides): the position Jacobian, the tool-axis Jacobian, the directional
//! manipulability gradient (random unit d, λ_μ = 1e-3) and the tool-alignment gradient
//! (random unit n). Tolerance 1e-6 relative to max(‖analytic‖, 1).

mod common;

use common::{arms, central_difference, random_q, random_unit, rng, robot};
use emg_kinematics::{JointVector, Vec3, directional_manipulability, tool_alignment_gradient};
use nalgebra::{Matrix3, Vector1};

const CONFIGS: usize = 1000;
const TOLERANCE: f64 = 1e-6;
const LAMBDA_MU: f64 = 1e-3;

#[test]
fn position_jacobian_matches_finite_differences() {
    for robot in arms() {
        let mut rng = rng(1);
        let mut worst = 0.0f64;
        for _ in 0..CONFIGS {
            let q = random_q(&mut rng, &robot);
            let kin = robot.forward(&q);
            let analytic = kin.jacobian();
            for absent in robot.dof()..7 {
                assert!(analytic.column(absent).iter().all(|v| *v == 0.0));
            }
            for i in 0..7 {
                let numeric = central_difference(&q, i, |q| robot.forward(q).tcp());
                let err =
                    (analytic.column(i) - numeric).norm() / analytic.column(i).norm().max(1.0);
                worst = worst.max(err);
            }
        }
        println!("position Jacobian: worst relative error {worst:.3e}");
        assert!(worst < TOLERANCE, "worst relative error {worst:e}");
    }
}

#[test]
fn tool_axis_jacobian_matches_finite_differences() {
    for robot in arms() {
        let mut rng = rng(2);
        let mut worst = 0.0f64;
        for _ in 0..CONFIGS {
            let q = random_q(&mut rng, &robot);
            let analytic = robot.forward(&q).tool_axis_jacobian();
            for i in 0..7 {
                let numeric = central_difference(&q, i, |q| robot.forward(q).tool_axis());
                let err =
                    (analytic.column(i) - numeric).norm() / analytic.column(i).norm().max(1.0);
                worst = worst.max(err);
            }
        }
        println!("tool-axis Jacobian: worst relative error {worst:.3e}");
        assert!(worst < TOLERANCE, "worst relative error {worst:e}");
    }
}

/// `w_d` computed directly from its definition, independently of the crate's function.
fn directional_manipulability_value(
    robot: &emg_kinematics::Robot,
    q: &JointVector,
    d: &Vec3,
) -> f64 {
    let kin = robot.forward(q);
    let j = kin.jacobian();
    let a = j * j.transpose() + Matrix3::identity() * (LAMBDA_MU * LAMBDA_MU);
    let s = d.dot(&(a.try_inverse().expect("damped JJᵀ is invertible") * d));
    1.0 / s.sqrt()
}

#[test]
fn directional_manipulability_gradient_matches_finite_differences() {
    for robot in arms() {
        let mut rng = rng(3);
        let (mut worst, mut worst_value) = (0.0f64, 0.0f64);
        for _ in 0..CONFIGS {
            let q = random_q(&mut rng, &robot);
            let d = random_unit(&mut rng);
            let kin = robot.forward(&q);
            let (value, gradient) =
                directional_manipulability(&kin, &kin.jacobian_gram(), &d, LAMBDA_MU);
            let reference = directional_manipulability_value(&robot, &q, &d);
            worst_value = worst_value.max((value - reference).abs() / reference.max(1.0));
            let numeric = JointVector::from_fn(|i, _| {
                central_difference(&q, i, |q| {
                    Vector1::new(directional_manipulability_value(&robot, q, &d))
                })[0]
            });
            assert!((robot.dof()..7).all(|absent| gradient[absent] == 0.0));
            worst = worst.max((gradient - numeric).norm() / gradient.norm().max(1.0));
        }
        println!(
            "w_d: worst value error {worst_value:.3e}, worst gradient relative error {worst:.3e}"
        );
        assert!(
            worst_value < 1e-9,
            "w_d value differs from its definition by {worst_value:e}"
        );
        assert!(worst < TOLERANCE, "worst relative error {worst:e}");
    }
}

#[test]
fn directional_manipulability_value_is_the_directional_singular_value_without_damping() {
    // Along a left singular vector u_k of J, w_d (λ_μ → 0) equals σ_k: a known-answer check
    // that fixes the exponent and the normalisation, not only the derivative.
    let robot = robot();
    let mut rng = rng(31);
    for _ in 0..100 {
        let q = random_q(&mut rng, &robot);
        let kin = robot.forward(&q);
        let svd = kin.jacobian().svd(true, false);
        let u = svd.u.expect("u requested");
        for k in 0..3 {
            let d: Vec3 = u.column(k).into_owned();
            let (value, _) = directional_manipulability(&kin, &kin.jacobian_gram(), &d, 0.0);
            let sigma = svd.singular_values[k];
            assert!(
                (value - sigma).abs() < 1e-9 * sigma.max(1.0),
                "w_d {value} vs σ {sigma}"
            );
        }
    }
}

#[test]
fn tool_alignment_gradient_matches_finite_differences() {
    for robot in arms() {
        let mut rng = rng(4);
        let mut worst = 0.0f64;
        for _ in 0..CONFIGS {
            let q = random_q(&mut rng, &robot);
            let n = random_unit(&mut rng);
            let gradient = tool_alignment_gradient(&robot.forward(&q), &n);
            let numeric = JointVector::from_fn(|i, _| {
                central_difference(&q, i, |q| {
                    Vector1::new(robot.forward(q).tool_axis().dot(&n))
                })[0]
            });
            assert!((robot.dof()..7).all(|absent| gradient[absent] == 0.0));
            worst = worst.max((gradient - numeric).norm() / gradient.norm().max(1.0));
        }
        println!("tool alignment: worst relative error {worst:.3e}");
        assert!(worst < TOLERANCE, "worst relative error {worst:e}");
    }
}
