//! Rotations from angles and back, with the same bits on every machine.
//!
//! `nalgebra`'s constructors from angles take their sines and cosines from the platform's C
//! library, whose last bits differ between platforms (and, with glibc, between CPUs with and
//! without fused multiply-adds). These take them from the `libm` crate, pure Rust and the same
//! arithmetic everywhere, so a robot file, a scene or a task turns into the same numbers on
//! every machine (the workspace's `clippy.toml` forbids the others); and [`Transform`], a rigid
//! motion as files write it.

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion};
use serde::{Deserialize, Serialize};

use crate::vectors::Vec3;

/// The rotation of URDF's `rpy` (fixed axes x, y, z in turn): `R = R_z(yaw) R_y(pitch) R_x(roll)`.
pub fn rotation_from_rpy(roll: f64, pitch: f64, yaw: f64) -> Rotation3<f64> {
    let (sr, cr) = libm::sincos(roll);
    let (sp, cp) = libm::sincos(pitch);
    let (sy, cy) = libm::sincos(yaw);
    Rotation3::from_matrix_unchecked(Matrix3::new(
        cy * cp,
        cy * sp * sr - sy * cr,
        cy * sp * cr + sy * sr,
        sy * cp,
        sy * sp * sr + cy * cr,
        sy * sp * cr - cy * sr,
        -sp,
        cp * sr,
        cp * cr,
    ))
}

/// The `(roll, pitch, yaw)` of `rotation` ([`rotation_from_rpy`]'s inverse): pitch in
/// `[−π/2, π/2]`; at pitch `±π/2`, where only roll ∓ yaw is defined, yaw is 0.
pub fn rpy_of(rotation: &Rotation3<f64>) -> (f64, f64, f64) {
    let m = rotation.matrix();
    let cos_pitch = (m[(0, 0)] * m[(0, 0)] + m[(1, 0)] * m[(1, 0)]).sqrt();
    let pitch = libm::atan2(-m[(2, 0)], cos_pitch);
    if cos_pitch > 1e-12 {
        (
            libm::atan2(m[(2, 1)], m[(2, 2)]),
            pitch,
            libm::atan2(m[(1, 0)], m[(0, 0)]),
        )
    } else if m[(2, 0)] < 0.0 {
        // Pitch π/2: the first row is (0, sin(roll − yaw), cos(roll − yaw)).
        (libm::atan2(m[(0, 1)], m[(1, 1)]), pitch, 0.0)
    } else {
        // Pitch −π/2: the first row is (0, −sin(roll + yaw), −cos(roll + yaw)).
        (libm::atan2(-m[(0, 1)], m[(1, 1)]), pitch, 0.0)
    }
}

/// The rotation by `angle` (rad) about the unit vector `axis` (Rodrigues' formula).
pub fn rotation_about(axis: &Vec3, angle: f64) -> Rotation3<f64> {
    let (sin, cos) = libm::sincos(angle);
    let skew = axis.cross_matrix();
    Rotation3::from_matrix_unchecked(Matrix3::identity() + skew * sin + skew * skew * (1.0 - cos))
}

/// The smallest rotation taking the unit vector `from` onto the unit vector `to`: about
/// `from × to` by the angle between them; the half turn about an axis ⟂ `from` when they are
/// opposite.
pub fn rotation_onto(from: &Vec3, to: &Vec3) -> Rotation3<f64> {
    let axis = from.cross(to);
    let (sin, cos) = (axis.norm(), from.dot(to));
    if sin > 1e-15 {
        return rotation_about(&(axis / sin), libm::atan2(sin, cos));
    }
    if cos > 0.0 {
        return Rotation3::identity();
    }
    let helper = if from.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let axis = from.cross(&helper).normalize();
    // A half turn: R = 2 a aᵀ − I.
    Rotation3::from_matrix_unchecked(axis * axis.transpose() * 2.0 - Matrix3::identity())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `nalgebra`'s constructors are the reference (to rounding: they use the C library).
    #[allow(clippy::disallowed_methods)]
    #[test]
    fn rpy_and_axis_angle_match_nalgebra() {
        for (roll, pitch, yaw) in [
            (0.0, 0.0, 0.0),
            (0.3, -1.1, 2.9),
            (-std::f64::consts::FRAC_PI_2, 0.0, std::f64::consts::PI),
            (1.0, 1.5, -0.4),
        ] {
            let ours = rotation_from_rpy(roll, pitch, yaw);
            let reference = Rotation3::from_euler_angles(roll, pitch, yaw);
            assert!((ours.matrix() - reference.matrix()).amax() < 1e-15);
            let (r, p, y) = rpy_of(&ours);
            assert!((rotation_from_rpy(r, p, y).matrix() - ours.matrix()).amax() < 1e-14);
        }
        let axis = Vec3::new(1.0, -2.0, 0.5).normalize();
        let reference = Rotation3::from_axis_angle(&nalgebra::Unit::new_unchecked(axis), 0.7);
        assert!((rotation_about(&axis, 0.7).matrix() - reference.matrix()).amax() < 1e-15);
    }

    #[test]
    fn rpy_of_a_gimbal_lock_gives_the_same_rotation() {
        for pitch in [std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_2] {
            let rotation = rotation_from_rpy(0.8, pitch, -0.3);
            let (r, p, y) = rpy_of(&rotation);
            assert_eq!(y, 0.0);
            assert!((rotation_from_rpy(r, p, y).matrix() - rotation.matrix()).amax() < 1e-12);
        }
    }

    #[test]
    fn rotation_onto_takes_from_onto_to() {
        let from = Vec3::new(0.0, 0.0, 1.0);
        for to in [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 2.0, -0.5).normalize(),
            Vec3::new(0.0, 1e-9, -1.0).normalize(),
            Vec3::new(1e-17, 0.0, -1.0),
            Vec3::new(0.0, 0.0, -1.0),
        ] {
            let rotation = rotation_onto(&from, &to);
            assert!((rotation * from - to).amax() < 1e-12, "{to:?}");
            let m = rotation.matrix();
            assert!((m * m.transpose() - Matrix3::identity()).amax() < 1e-12);
            assert!((m.determinant() - 1.0).abs() < 1e-12);
        }
    }
}

/// A rigid motion in the base frame: a turn by the URDF roll–pitch–yaw `rpy` (rad, about the
/// base's fixed x, y, z axes through its origin), then a shift by `translation_m` (m).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    /// The shift (m).
    pub translation_m: [f64; 3],
    /// The turn (rad).
    #[serde(default)]
    pub rpy: [f64; 3],
}

impl Transform {
    /// The motion as an isometry.
    pub fn isometry(&self) -> Isometry3<f64> {
        let [roll, pitch, yaw] = self.rpy;
        Isometry3::from_parts(
            Translation3::from(Vec3::from(self.translation_m)),
            UnitQuaternion::from_rotation_matrix(&rotation_from_rpy(roll, pitch, yaw)),
        )
    }

    /// The transform of `motion`.
    pub fn of(motion: &Isometry3<f64>) -> Self {
        let (roll, pitch, yaw) = rpy_of(&motion.rotation.to_rotation_matrix());
        Self {
            translation_m: motion.translation.vector.into(),
            rpy: [roll, pitch, yaw],
        }
    }
}
