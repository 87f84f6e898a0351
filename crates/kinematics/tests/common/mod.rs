//! Helpers shared by the integration tests: the shipped robot, seeded random configurations
//! and directions, and central finite differences.
#![allow(dead_code)]

use emg_kinematics::{JointVector, Robot, Vec3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

/// Finite-difference step for central differences.
pub const FD_STEP: f64 = 1e-6;

/// The FR3-with-pen chain of the shipped robot file.
pub fn robot() -> Robot {
    Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").expect("shipped robot file loads")
}

/// The text of the shipped robot file.
pub fn robot_text() -> String {
    std::fs::read_to_string(fr3_path()).expect("shipped robot file is readable")
}

/// A deterministic generator.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// SPEC §1 home configuration.
pub fn home() -> JointVector {
    JointVector::from_column_slice(&[
        0.0,
        -FRAC_PI_4,
        0.0,
        -3.0 * FRAC_PI_4,
        0.0,
        FRAC_PI_2,
        FRAC_PI_4,
    ])
}

/// A configuration drawn uniformly within the robot's joint limits.
pub fn random_q(rng: &mut ChaCha8Rng, robot: &Robot) -> JointVector {
    let limits = robot.limits();
    robot.configuration_from_fn(|i| rng.random_range(limits.lower[i]..limits.upper[i]))
}

/// The six-joint UR5e-with-pen chain of the shipped robot file.
pub fn ur5e() -> Robot {
    Robot::from_urdf_file(
        data_dir().join("robots/ur5e_pen.urdf"),
        "base_link",
        "pen_tip",
    )
    .expect("shipped UR5e file loads")
}

/// An arm of each supported joint count: the FR3 (seven) and the UR5e (six).
pub fn arms() -> [Robot; 2] {
    [robot(), ur5e()]
}

/// A direction drawn uniformly on the unit sphere.
pub fn random_unit(rng: &mut ChaCha8Rng) -> Vec3 {
    let z: f64 = rng.random_range(-1.0..1.0);
    let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let r = (1.0 - z * z).sqrt();
    let (sin, cos) = libm::sincos(phi);
    Vec3::new(r * cos, r * sin, z)
}

/// A point drawn uniformly in the cube `[-half, half]³`.
pub fn random_point(rng: &mut ChaCha8Rng, half: f64) -> Vec3 {
    Vec3::new(
        rng.random_range(-half..half),
        rng.random_range(-half..half),
        rng.random_range(-half..half),
    )
}

/// Central finite difference of a vector-valued function of `q` along joint `i`.
pub fn central_difference<const R: usize>(
    q: &JointVector,
    i: usize,
    f: impl Fn(&JointVector) -> nalgebra::SVector<f64, R>,
) -> nalgebra::SVector<f64, R> {
    let mut plus = *q;
    let mut minus = *q;
    plus[i] += FD_STEP;
    minus[i] -= FD_STEP;
    (f(&plus) - f(&minus)) / (2.0 * FD_STEP)
}

/// Angle (rad) between two vectors, accurate for tiny angles.
pub fn angle_between(a: &Vec3, b: &Vec3) -> f64 {
    libm::atan2(a.cross(b).norm(), a.dot(b))
}

/// The workspace's shipped data directory.
pub fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

/// The shipped FR3 robot file.
pub fn fr3_path() -> std::path::PathBuf {
    data_dir().join("robots/fr3_pen.urdf")
}
