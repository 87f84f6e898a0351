//! The UR5e's kinematics as its controller computes them: the standard DH chain of its flange,
//! the closed-form inverse kinematics with its eight branches, followed from one configuration
//! to the next as the controller follows a Cartesian move; and the checker's TCP of a
//! configuration.

use std::f64::consts::FRAC_PI_2;

use emg_kinematics::Vec3;
use emg_verify::{Joints, ReferenceModel};

use crate::geometry::{Pose, Rotation, wrap};

/// The arccosine of `x` (rad), `x` clamped to `[-1, 1]`.
fn acos(x: f64) -> f64 {
    libm::acos(x.clamp(-1.0, 1.0))
}

/// The UR5e's standard DH parameter `d` of each joint (m).
pub const UR5E_D: [f64; 6] = [0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996];

/// The UR5e's standard DH parameter `a` of each joint (m).
pub const UR5E_A: [f64; 6] = [0.0, -0.425, -0.3922, 0.0, 0.0, 0.0];

/// The UR5e's standard DH parameter `alpha` of each joint (rad).
pub const UR5E_ALPHA: [f64; 6] = [FRAC_PI_2, 0.0, 0.0, FRAC_PI_2, -FRAC_PI_2, 0.0];

/// DH frame `i + 1` in frame `i` at joint angle `theta`: `Rz(θ) Tz(d) Tx(a) Rx(α)`.
fn dh(i: usize, theta: f64) -> Pose {
    Pose {
        position: Vec3::new(
            UR5E_A[i] * libm::cos(theta),
            UR5E_A[i] * libm::sin(theta),
            UR5E_D[i],
        ),
        rotation: Rotation::about_z(theta).then(&Rotation::about_x(UR5E_ALPHA[i])),
    }
}

/// The UR5e's flange (DH frame 6) in its Base frame (DH frame 0) at joints `q`.
pub fn ur5e_flange(q: &[f64; 6]) -> Pose {
    (0..6).fold(
        Pose {
            position: Vec3::zeros(),
            rotation: Rotation::IDENTITY,
        },
        |pose, i| pose.then(&dh(i, q[i])),
    )
}

/// The signs of the closed form's three choices: `±acos` of the shoulder (joint 1), of the
/// wrist (joint 5) and of the elbow (joint 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Branch {
    /// The shoulder's sign.
    pub shoulder: i8,
    /// The elbow's sign.
    pub elbow: i8,
    /// The wrist's sign.
    pub wrist: i8,
}

/// One solution of the closed-form inverse kinematics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkSolution {
    /// The joints (rad), each in `(-π, π]`.
    pub q: [f64; 6],
    /// The branch it lies on.
    pub branch: Branch,
}

/// Every solution (up to 8) of the UR5e's closed-form inverse kinematics for its flange at
/// `flange` (in the Base frame), each joint in `(-π, π]`; at a wrist singularity (joint 5 at 0
/// or π) joint 6 is taken as 0.
pub fn ur5e_inverse(flange: &Pose) -> Vec<IkSolution> {
    let (d4, d6) = (UR5E_D[3], UR5E_D[5]);
    let (a2, a3) = (UR5E_A[1], UR5E_A[2]);
    let p06 = flange.position;
    let r06 = &flange.rotation.0;
    // The wrist centre (frame 5's origin) lies d6 back along the flange's z-axis, and d4 from
    // the base's vertical plane through joint 2's axis (frame 1's z-axis).
    let p05 = p06 - flange.rotation.column(2) * d6;
    let radius = (p05.x * p05.x + p05.y * p05.y).sqrt();
    let mut solutions = Vec::new();
    if radius < d4 * (1.0 - 1e-12) {
        return solutions;
    }
    let (psi, phi) = (libm::atan2(p05.y, p05.x), acos(d4 / radius));
    for shoulder in [1_i8, -1] {
        let t1 = psi + f64::from(shoulder) * phi + FRAC_PI_2;
        let (s1, c1) = (libm::sin(t1), libm::cos(t1));
        let c5 = (p06.x * s1 - p06.y * c1 - d4) / d6;
        if c5.abs() > 1.0 + 1e-9 {
            continue;
        }
        for wrist in [1_i8, -1] {
            let t5 = f64::from(wrist) * acos(c5);
            let s5 = libm::sin(t5);
            let t6 = if s5.abs() < 1e-12 {
                0.0
            } else {
                libm::atan2(
                    (-r06[0][1] * s1 + r06[1][1] * c1) / s5,
                    (r06[0][0] * s1 - r06[1][0] * c1) / s5,
                )
            };
            // Frame 4 in frame 1: the planar arm of joints 2, 3 and 4.
            let t14 = dh(0, t1)
                .inverse()
                .then(flange)
                .then(&dh(5, t6).inverse())
                .then(&dh(4, t5).inverse());
            let (px, py) = (t14.position.x, t14.position.y);
            let c3 = (px * px + py * py - a2 * a2 - a3 * a3) / (2.0 * a2 * a3);
            if c3.abs() > 1.0 + 1e-9 {
                continue;
            }
            for elbow in [1_i8, -1] {
                let t3 = f64::from(elbow) * acos(c3);
                let t2 =
                    libm::atan2(py, px) - libm::atan2(a3 * libm::sin(t3), a2 + a3 * libm::cos(t3));
                let t234 = libm::atan2(t14.rotation.0[1][0], t14.rotation.0[0][0]);
                let t4 = t234 - t2 - t3;
                solutions.push(IkSolution {
                    q: [t1, t2, t3, t4, t5, t6].map(wrap),
                    branch: Branch {
                        shoulder,
                        elbow,
                        wrist,
                    },
                });
            }
        }
    }
    solutions
}

/// `solution` with each joint replaced by its 2π-equivalent nearest `previous`.
pub fn nearest_equivalent(solution: &[f64; 6], previous: &[f64; 6]) -> [f64; 6] {
    std::array::from_fn(|i| previous[i] + wrap(solution[i] - previous[i]))
}

/// The solution of [`ur5e_inverse`] for `flange` nearest `previous` (each joint its
/// 2π-equivalent nearest `previous`), as a controller continuing from `previous` takes it.
pub fn ur5e_follow(flange: &Pose, previous: &[f64; 6]) -> Option<IkSolution> {
    ur5e_inverse(flange)
        .into_iter()
        .map(|s| IkSolution {
            q: nearest_equivalent(&s.q, previous),
            branch: s.branch,
        })
        .min_by(|a, b| distance2(&a.q, previous).total_cmp(&distance2(&b.q, previous)))
}

/// Squared Euclidean distance between two configurations.
pub(crate) fn distance2(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Largest change of any joint between two configurations (rad).
pub(crate) fn largest_change(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The checker's joint vector of a UR5e configuration.
pub fn checker_joints(q: &[f64; 6]) -> Joints {
    let mut joints = Joints::zeros();
    for (i, value) in q.iter().enumerate() {
        joints[i] = *value;
    }
    joints
}

/// The TCP pose the checker gives configuration `q`.
pub fn checker_tcp(model: &ReferenceModel, q: &[f64; 6]) -> Pose {
    let (position, rotation) = model.tcp_frame(&checker_joints(q));
    let column = |c: usize| rotation.column(c).into_owned();
    Pose {
        position,
        rotation: Rotation::from_columns(&column(0), &column(1), &column(2)),
    }
}
