//! Rigid poses as URScript writes them: rotation matrices, rotation vectors (axis × angle),
//! slerp, and angles wrapped into `(-π, π]`.

use std::f64::consts::{PI, TAU};

use emg_kinematics::Vec3;

/// `angle` (rad) wrapped into `(-π, π]`.
pub fn wrap(angle: f64) -> f64 {
    let wrapped = angle - TAU * ((angle + PI) / TAU).floor();
    if wrapped <= -PI {
        wrapped + TAU
    } else {
        wrapped
    }
}

/// The angle (degrees) between two vectors.
pub fn angle_deg(a: &Vec3, b: &Vec3) -> f64 {
    libm::atan2(a.cross(b).norm(), a.dot(b)).to_degrees()
}

/// A rotation matrix, row by row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotation(pub [[f64; 3]; 3]);

impl Rotation {
    /// No rotation.
    pub const IDENTITY: Self = Self([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);

    /// The rotation whose columns are `x`, `y` and `z`.
    pub fn from_columns(x: &Vec3, y: &Vec3, z: &Vec3) -> Self {
        Self([[x.x, y.x, z.x], [x.y, y.y, z.y], [x.z, y.z, z.z]])
    }

    /// Column `c` (the rotated frame's axis `c` in the outer frame).
    pub fn column(&self, c: usize) -> Vec3 {
        Vec3::new(self.0[0][c], self.0[1][c], self.0[2][c])
    }

    /// The inverse rotation.
    pub fn transpose(&self) -> Self {
        let m = &self.0;
        Self([
            [m[0][0], m[1][0], m[2][0]],
            [m[0][1], m[1][1], m[2][1]],
            [m[0][2], m[1][2], m[2][2]],
        ])
    }

    /// The product `self · other`.
    pub fn then(&self, other: &Self) -> Self {
        let (a, b) = (&self.0, &other.0);
        let mut m = [[0.0; 3]; 3];
        for (r, row) in m.iter_mut().enumerate() {
            for (c, value) in row.iter_mut().enumerate() {
                *value = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
            }
        }
        Self(m)
    }

    /// `self · v`.
    pub fn apply(&self, v: &Vec3) -> Vec3 {
        let m = &self.0;
        Vec3::new(
            m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z,
        )
    }

    /// The rotation by `|v|` (rad) about `v` (Rodrigues' formula): URScript's rotation vector.
    pub fn from_rotation_vector(v: &Vec3) -> Self {
        let angle = v.norm();
        if angle < 1e-300 {
            return Self::IDENTITY;
        }
        let a = v / angle;
        let (s, c) = (libm::sin(angle), libm::cos(angle));
        let t = 1.0 - c;
        Self([
            [
                c + t * a.x * a.x,
                t * a.x * a.y - s * a.z,
                t * a.x * a.z + s * a.y,
            ],
            [
                t * a.x * a.y + s * a.z,
                c + t * a.y * a.y,
                t * a.y * a.z - s * a.x,
            ],
            [
                t * a.x * a.z - s * a.y,
                t * a.y * a.z + s * a.x,
                c + t * a.z * a.z,
            ],
        ])
    }

    /// The rotation vector (axis × angle, angle in `[0, π]`) of this rotation.
    pub fn rotation_vector(&self) -> Vec3 {
        let m = &self.0;
        let cosine = ((m[0][0] + m[1][1] + m[2][2] - 1.0) / 2.0).clamp(-1.0, 1.0);
        // sin(angle) × axis.
        let w = Vec3::new(m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]) * 0.5;
        let sine = w.norm();
        let angle = libm::atan2(sine, cosine);
        if sine > 1e-6 || cosine > 0.0 {
            return if sine > 0.0 {
                w * (angle / sine)
            } else {
                Vec3::zeros()
            };
        }
        // Near a half turn: (R + Rᵀ)/2 = cos(angle) I + (1 − cos(angle)) a aᵀ.
        let diagonal = |i: usize| (m[i][i] - cosine) / (1.0 - cosine);
        let k = (0..3)
            .max_by(|&i, &j| diagonal(i).total_cmp(&diagonal(j)))
            .unwrap_or(0);
        let mut axis = Vec3::zeros();
        for i in 0..3 {
            let identity = if i == k { cosine } else { 0.0 };
            axis[i] = ((m[i][k] + m[k][i]) / 2.0 - identity) / (1.0 - cosine);
        }
        let axis = axis / axis.norm();
        let axis = if axis.dot(&w) < 0.0 { -axis } else { axis };
        axis * angle
    }

    /// The angle (rad) of the rotation from `self` to `other`.
    pub fn angle_to(&self, other: &Self) -> f64 {
        self.transpose().then(other).rotation_vector().norm()
    }

    /// The rotation a fraction `s` of the way from `self` to `other` along the shortest turn:
    /// `self · exp(s · log(selfᵀ · other))`.
    pub fn slerp(&self, other: &Self, s: f64) -> Self {
        let relative = self.transpose().then(other).rotation_vector();
        self.then(&Self::from_rotation_vector(&(relative * s)))
    }

    /// The rotation by `angle` about z.
    pub(crate) fn about_z(angle: f64) -> Self {
        let (s, c) = (libm::sin(angle), libm::cos(angle));
        Self([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    }

    /// The rotation by `angle` about x.
    pub(crate) fn about_x(angle: f64) -> Self {
        let (s, c) = (libm::sin(angle), libm::cos(angle));
        Self([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    }
}

/// A rigid pose: a frame's origin and its axes in an outer frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// The origin (m).
    pub position: Vec3,
    /// The axes.
    pub rotation: Rotation,
}

impl Pose {
    /// URScript's `p[x, y, z, rx, ry, rz]`: position (m) and rotation vector.
    pub fn from_ur(values: &[f64; 6]) -> Self {
        Self {
            position: Vec3::new(values[0], values[1], values[2]),
            rotation: Rotation::from_rotation_vector(&Vec3::new(values[3], values[4], values[5])),
        }
    }

    /// The pose as URScript's `p[x, y, z, rx, ry, rz]`.
    pub fn to_ur(self) -> [f64; 6] {
        let v = self.rotation.rotation_vector();
        [
            self.position.x,
            self.position.y,
            self.position.z,
            v.x,
            v.y,
            v.z,
        ]
    }

    /// `self` followed by `other` (`other` given in `self`'s frame).
    pub fn then(&self, other: &Self) -> Self {
        Self {
            position: self.position + self.rotation.apply(&other.position),
            rotation: self.rotation.then(&other.rotation),
        }
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Self {
        let rotation = self.rotation.transpose();
        Self {
            position: -rotation.apply(&self.position),
            rotation,
        }
    }

    /// The distance (m) between the origins and the angle (rad) between the frames.
    pub fn difference(&self, other: &Self) -> (f64, f64) {
        (
            (self.position - other.position).norm(),
            self.rotation.angle_to(&other.rotation),
        )
    }
}
