//! An independent re-check of recorded trajectories.
//!
//! The checker re-reads the robot file itself and recomputes every quantity with plain 4×4
//! homogeneous transforms (URDF joint origin × rotation about the file's joint axis), its own
//! collision-pair rule and its own segment-distance routine. It shares no kinematics code with
//! the controllers, so a shortcut or a bug there cannot hide a constraint violation here.

use nalgebra::{Matrix4, Rotation3, Unit, Vector3, Vector4};

use crate::config::ConstraintConfig;
use crate::rollout::{Termination, Trajectory};
use crate::task::Task;

/// Numerical slack when comparing recomputed values with recorded ones and with bounds.
const SLACK: f64 = 1e-9;

/// One body's capsule in its link frame.
struct ReferenceCapsule {
    link: String,
    chain_index: usize,
    start: Vector3<f64>,
    end: Vector3<f64>,
    radius: f64,
}

/// One joint of the chain, as the file states it.
struct ReferenceJoint {
    origin: Matrix4<f64>,
    axis: Option<Unit<Vector3<f64>>>,
    lower: f64,
    upper: f64,
    velocity: f64,
}

/// The robot as the checker sees it, built straight from the URDF file.
pub struct ReferenceModel {
    joints: Vec<ReferenceJoint>,
    capsules: Vec<ReferenceCapsule>,
}

/// A step of a trajectory that does not hold up.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("step {step}: {problem}")]
pub struct CheckFailure {
    /// Index of the offending step.
    pub step: usize,
    /// What is wrong.
    pub problem: String,
}

impl ReferenceModel {
    /// Reads the chain from `base` to `tip` of URDF text.
    pub fn from_urdf_str(text: &str, base: &str, tip: &str) -> Result<Self, String> {
        let urdf = urdf_rs::read_from_string(text).map_err(|e| e.to_string())?;
        let mut path = Vec::new();
        let mut link = tip.to_string();
        while link != base {
            let joint = urdf
                .joints
                .iter()
                .find(|j| j.child.link == link)
                .ok_or_else(|| format!("no joint leads to link '{link}'"))?;
            path.push(joint);
            link = joint.parent.link.clone();
        }
        path.reverse();
        let mut joints = Vec::new();
        let mut capsules = Vec::new();
        let mut link_names = vec![base.to_string()];
        link_names.extend(path.iter().map(|j| j.child.link.clone()));
        for joint in &path {
            let [x, y, z] = joint.origin.xyz.0;
            let [r, p, yaw] = joint.origin.rpy.0;
            let mut origin = Rotation3::from_euler_angles(r, p, yaw).to_homogeneous();
            origin[(0, 3)] = x;
            origin[(1, 3)] = y;
            origin[(2, 3)] = z;
            let revolute = matches!(joint.joint_type, urdf_rs::JointType::Revolute);
            joints.push(ReferenceJoint {
                origin,
                axis: revolute.then(|| Unit::new_normalize(Vector3::from(joint.axis.xyz.0))),
                lower: joint.limit.lower,
                upper: joint.limit.upper,
                velocity: joint.limit.velocity,
            });
        }
        for (chain_index, name) in link_names.iter().enumerate() {
            let link = urdf
                .links
                .iter()
                .find(|l| &l.name == name)
                .ok_or("missing link")?;
            for collision in &link.collision {
                let (radius, half) = match collision.geometry {
                    urdf_rs::Geometry::Capsule { radius, length } => (radius, length / 2.0),
                    urdf_rs::Geometry::Sphere { radius } => (radius, 0.0),
                    _ => return Err(format!("link '{name}': unsupported collision geometry")),
                };
                let [x, y, z] = collision.origin.xyz.0;
                let [r, p, yaw] = collision.origin.rpy.0;
                let rotation = Rotation3::from_euler_angles(r, p, yaw);
                let centre = Vector3::new(x, y, z);
                let axis = rotation * Vector3::z() * half;
                capsules.push(ReferenceCapsule {
                    link: name.clone(),
                    chain_index,
                    start: centre - axis,
                    end: centre + axis,
                    radius,
                });
            }
        }
        Ok(Self { joints, capsules })
    }

    /// Reads the chain from `base` to `tip` of a URDF file.
    pub fn from_urdf_file(path: &std::path::Path, base: &str, tip: &str) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Self::from_urdf_str(&text, base, tip)
    }

    /// Link frames base to tip (one per link of the chain) for configuration `q`.
    fn link_frames(&self, q: &[f64]) -> Vec<Matrix4<f64>> {
        let mut frames = vec![Matrix4::identity()];
        let mut revolute = 0;
        for joint in &self.joints {
            let mut transform = frames.last().expect("base frame") * joint.origin;
            if let Some(axis) = &joint.axis {
                transform *= Rotation3::from_axis_angle(axis, q[revolute]).to_homogeneous();
                revolute += 1;
            }
            frames.push(transform);
        }
        frames
    }

    /// TCP position and tool axis (z of the tip link) for `q`.
    pub fn tcp_pose(&self, q: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
        let tip = *self.link_frames(q).last().expect("tip frame");
        (
            tip.fixed_view::<3, 1>(0, 3).into_owned(),
            tip.fixed_view::<3, 1>(0, 2).into_owned(),
        )
    }

    /// Joint limits `(lower, upper)` of the revolute joints in order.
    pub fn limits(&self) -> Vec<(f64, f64)> {
        self.joints
            .iter()
            .filter(|j| j.axis.is_some())
            .map(|j| (j.lower, j.upper))
            .collect()
    }

    /// Velocity limits (rad/s) of the revolute joints in order, as the file states them.
    pub fn velocity_limits(&self) -> Vec<f64> {
        self.joints
            .iter()
            .filter(|j| j.axis.is_some())
            .map(|j| j.velocity)
            .collect()
    }

    /// Smallest clearance (m) over capsule pairs at least three links apart, with their links.
    pub fn min_clearance(&self, q: &[f64]) -> (f64, String, String) {
        let frames = self.link_frames(q);
        let world = |c: &ReferenceCapsule, v: &Vector3<f64>| {
            (frames[c.chain_index] * Vector4::new(v.x, v.y, v.z, 1.0)).xyz()
        };
        let mut best = (f64::INFINITY, String::new(), String::new());
        for (i, a) in self.capsules.iter().enumerate() {
            for b in &self.capsules[i + 1..] {
                if a.chain_index.abs_diff(b.chain_index) < 3 {
                    continue;
                }
                let gap = segments_gap(
                    &world(a, &a.start),
                    &world(a, &a.end),
                    &world(b, &b.start),
                    &world(b, &b.end),
                ) - a.radius
                    - b.radius;
                if gap < best.0 {
                    best = (gap, a.link.clone(), b.link.clone());
                }
            }
        }
        best
    }

    /// Verifies every recorded step of `trajectory` against the constraints and its own
    /// records: joint limits, TCP and tool angle as recorded, line tolerance, tool cone, no
    /// self-collision, increasing timestamps, joint speeds within the velocity limits (when the
    /// constraints enforce them), the reported path length, and that a rejected step
    /// really breaks the constraint it is blamed on.
    pub fn check(
        &self,
        task: &Task,
        trajectory: &Trajectory,
        constraints: &ConstraintConfig,
    ) -> Result<(), CheckFailure> {
        let limits = self.limits();
        let velocity_limits = self.velocity_limits();
        let fail = |step: usize, problem: String| Err(CheckFailure { step, problem });
        if trajectory.steps.is_empty() {
            return fail(0, "the trajectory holds no step, not even its seed".into());
        }
        let valid_steps = match trajectory.termination {
            Termination::InvalidStart { .. } if trajectory.steps.len() != 1 => {
                return fail(
                    1,
                    format!(
                        "an invalid start must hold only the seed, found {} steps",
                        trajectory.steps.len()
                    ),
                );
            }
            Termination::InvalidStart { .. } => 0,
            _ => trajectory.steps.len(),
        };
        for (k, step) in trajectory.steps.iter().enumerate().take(valid_steps) {
            let q = step.q.as_slice();
            for (i, (lo, hi)) in limits.iter().enumerate() {
                if !(q[i] >= *lo && q[i] <= *hi) {
                    return fail(
                        k,
                        format!("joint {} = {} outside [{lo}, {hi}]", i + 1, q[i]),
                    );
                }
            }
            let (tcp, z) = self.tcp_pose(q);
            if !within((tcp - step.tcp).norm(), SLACK) {
                return fail(
                    k,
                    format!("recorded TCP {:?} but FK gives {:?}", step.tcp, tcp),
                );
            }
            let offset = tcp - task.p0;
            let lateral = (offset - task.d * offset.dot(&task.d)).norm();
            if !within(lateral, constraints.line_tolerance_m + SLACK) {
                return fail(k, format!("TCP {lateral} m off the line"));
            }
            let angle = angle_deg(&z, &task.n);
            if !within(angle, constraints.theta_max_deg + 1e-6) {
                return fail(k, format!("tool axis {angle}° from n"));
            }
            if !within((angle - step.tool_angle_deg).abs(), 1e-6) {
                return fail(
                    k,
                    format!(
                        "recorded tool angle {} but FK gives {angle}",
                        step.tool_angle_deg
                    ),
                );
            }
            let (gap, a, b) = self.min_clearance(q);
            if !within(constraints.collision_margin_m - SLACK, gap) {
                return fail(k, format!("{a} and {b} collide (clearance {gap} m)"));
            }
            if !step.time_s.is_finite() {
                return fail(k, format!("timestamp {} is not finite", step.time_s));
            }
            if k > 0 {
                let previous = &trajectory.steps[k - 1];
                if within(step.time_s, previous.time_s) {
                    return fail(k, "timestamps do not increase".into());
                }
                if let Some(fraction) = constraints.velocity_limit_fraction {
                    let elapsed = step.time_s - previous.time_s;
                    for (i, limit) in velocity_limits.iter().enumerate() {
                        let speed = (step.q[i] - previous.q[i]).abs() / elapsed;
                        let allowed = fraction.get() * limit;
                        if !within(speed, allowed * (1.0 + SLACK)) {
                            return fail(
                                k,
                                format!(
                                    "joint {} moves at {speed} rad/s, above {allowed} rad/s",
                                    i + 1
                                ),
                            );
                        }
                    }
                }
            }
        }
        if let Some(last) = trajectory.steps.last() {
            let length = (last.tcp - task.p0).dot(&task.d);
            if !within((length - trajectory.path_length_m).abs(), SLACK) {
                return fail(
                    trajectory.steps.len() - 1,
                    format!(
                        "reported path length {} but the last step gives {length}",
                        trajectory.path_length_m
                    ),
                );
            }
        }
        let blamed = match &trajectory.termination {
            Termination::Violation {
                violation,
                rejected_q,
            } => Some((violation, rejected_q.as_slice().to_vec())),
            Termination::InvalidStart { violation } => trajectory
                .steps
                .first()
                .map(|s| (violation, s.q.as_slice().to_vec())),
            Termination::StepCap => None,
        };
        if let Some((violation, q)) = blamed
            && !self.breaks(task, &q, violation, constraints)
        {
            return fail(
                trajectory.steps.len(),
                format!("the final configuration does not break {violation:?}"),
            );
        }
        Ok(())
    }

    /// Whether configuration `q` breaks the constraint named by `violation`.
    fn breaks(
        &self,
        task: &Task,
        q: &[f64],
        violation: &crate::constraints::Violation,
        constraints: &ConstraintConfig,
    ) -> bool {
        use crate::constraints::Violation;
        let (tcp, z) = self.tcp_pose(q);
        match violation {
            // NaN breaks every bound (as in the rollout); a joint number out of range breaks none.
            Violation::JointLimit { joint, .. } => {
                match joint
                    .checked_sub(1)
                    .and_then(|i| self.limits().get(i).copied().zip(q.get(i)))
                {
                    Some(((lo, hi), value)) => !(*value >= lo && *value <= hi),
                    None => false,
                }
            }
            Violation::LineTolerance { .. } => {
                let offset = tcp - task.p0;
                let lateral = (offset - task.d * offset.dot(&task.d)).norm();
                !within(lateral, constraints.line_tolerance_m - SLACK)
            }
            Violation::ToolCone { .. } => {
                let angle = angle_deg(&z, &task.n);
                !within(angle, constraints.theta_max_deg - 1e-6)
            }
            Violation::SelfCollision { .. } => {
                self.min_clearance(q).0 < constraints.collision_margin_m + SLACK
            }
        }
    }
}

/// Angle between unit vectors (degrees) as `atan2(|a × b|, a·b)`: `acos(a·b)` loses half the
/// digits near 0°, where one rounding of the dot product already reads as ~1e-6°.
fn angle_deg(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b)).to_degrees()
}

/// `value <= bound`; false when either is NaN, so that every check fails closed.
fn within(value: f64, bound: f64) -> bool {
    value <= bound
}

/// Distance between segments `a0–a1` and `b0–b1`: the minimum over the unconstrained stationary
/// point (when it lies inside both segments) and the four end-point-to-segment distances.
fn segments_gap(a0: &Vector3<f64>, a1: &Vector3<f64>, b0: &Vector3<f64>, b1: &Vector3<f64>) -> f64 {
    let point_to_segment = |p: &Vector3<f64>, s0: &Vector3<f64>, s1: &Vector3<f64>| {
        let axis = s1 - s0;
        let length2 = axis.norm_squared();
        let t = if length2 > 0.0 {
            ((p - s0).dot(&axis) / length2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p - (s0 + axis * t)).norm()
    };
    let mut best = point_to_segment(a0, b0, b1)
        .min(point_to_segment(a1, b0, b1))
        .min(point_to_segment(b0, a0, a1))
        .min(point_to_segment(b1, a0, a1));
    let (u, v, w) = (a1 - a0, b1 - b0, a0 - b0);
    let (uu, uv, vv, uw, vw) = (u.dot(&u), u.dot(&v), v.dot(&v), u.dot(&w), v.dot(&w));
    let det = uu * vv - uv * uv;
    if det > 1e-14 * uu * vv {
        let s = (uv * vw - vv * uw) / det;
        let t = (uu * vw - uv * uw) / det;
        if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) {
            best = best.min(((a0 + u * s) - (b0 + v * t)).norm());
        }
    }
    best
}
