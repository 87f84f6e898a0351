//! The robot model: a serial chain of six or seven revolute joints read from a URDF file.

use nalgebra::{Isometry3, Matrix3, Point3, Translation3, UnitQuaternion, Vector3};
use std::collections::HashMap;
use std::path::Path;

use crate::broad_phase::BroadPhase;
use crate::capsule::{Capsule, CollisionPair, MAX_CAPSULES};
use crate::error::{RobotError, read_text};
use crate::rotation::{rotation_from_rpy, rotation_onto};
use crate::srdf::PairRule;
use crate::vectors::{JointVector, MAX_DOF, MIN_DOF, Vec3};

/// Lower, upper and velocity limits of the joints; entries past the arm's joints (an arm of six)
/// hold the range ±π and speed 1 rad/s, which no step uses (those joints never move).
#[derive(Clone, Debug, PartialEq)]
pub struct JointLimits {
    /// Lower position limits `q_min` (rad).
    pub lower: JointVector,
    /// Upper position limits `q_max` (rad).
    pub upper: JointVector,
    /// Velocity limits (rad/s).
    pub velocity: JointVector,
}

impl JointLimits {
    /// Mid-range configuration `q_mid = (q_min + q_max)/2`.
    pub fn mid(&self) -> JointVector {
        (self.lower + self.upper) * 0.5
    }

    /// Half range `(q_max − q_min)/2` per joint.
    pub fn half_range(&self) -> JointVector {
        (self.upper - self.lower) * 0.5
    }

    /// Normalised configuration `q̄ = (q − q_mid)/q_half ∈ [−1, 1]` (SPEC §4).
    pub fn normalise(&self, q: &JointVector) -> JointVector {
        (q - self.mid()).component_div(&self.half_range())
    }

    /// Normalised joint-limit distance `ρ(q) = max_i |q̄_i|` (Eq. 8): 0 at mid-range, 1 at a limit.
    pub fn limit_proximity(&self, q: &JointVector) -> f64 {
        self.normalise(q).amax()
    }

    /// Index of the first joint outside `[q_min + margin, q_max − margin]`, if any.
    pub fn first_violation(&self, q: &JointVector, margin: f64) -> Option<usize> {
        (0..MAX_DOF).find(|&i| !(q[i] >= self.lower[i] + margin && q[i] <= self.upper[i] - margin))
    }

    /// `q` clamped into the limits.
    pub fn clamp(&self, q: &JointVector) -> JointVector {
        q.zip_zip_map(&self.lower, &self.upper, |v, lo, hi| v.clamp(lo, hi))
    }

    /// These limits with every joint whose range is wider than a turn narrowed to within
    /// `half_width_rad` of `reference`: `[max(q_min, r − w), min(q_max, r + w)]`, where that
    /// interval is not empty. Such a joint reaches every angle of the arm within half a turn of
    /// any value, so a band of half a turn loses no pose the arm can take, only its joint values
    /// a turn away; a narrower band keeps the joint nearer `reference`. Other joints, and
    /// velocity limits, are kept.
    pub fn within(&self, reference: &JointVector, half_width_rad: f64) -> JointLimits {
        let mut narrowed = self.clone();
        for i in 0..MAX_DOF {
            let lower = self.lower[i].max(reference[i] - half_width_rad);
            let upper = self.upper[i].min(reference[i] + half_width_rad);
            if self.upper[i] - self.lower[i] > std::f64::consts::TAU && lower < upper {
                narrowed.lower[i] = lower;
                narrowed.upper[i] = upper;
            }
        }
        narrowed
    }

    /// The whole turns (multiples of 2π, per joint) that bring the middle of the range each joint
    /// of `motion` sweeps nearest `reference` while every configuration of `motion`, each turned
    /// alike, stays within the limits. A revolute joint turned by 2π stands where it stood, so
    /// the turned motion moves the arm exactly as `motion` does; a joint whose motion sweeps less
    /// than a turn stays within ±π of `reference` where its limits allow. Zero for joints whose
    /// range leaves no other choice, and for an empty motion.
    pub fn turns_toward(&self, motion: &[JointVector], reference: &JointVector) -> JointVector {
        if motion.is_empty() {
            return JointVector::zeros();
        }
        let turn = std::f64::consts::TAU;
        JointVector::from_fn(|i, _| {
            let (least, greatest) = motion
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                    (lo.min(q[i]), hi.max(q[i]))
                });
            // Turns that keep the whole motion within the limits, the nearest to the reference.
            let fewest = ((self.lower[i] - least) / turn).ceil();
            let most = ((self.upper[i] - greatest) / turn).floor();
            let wanted = ((reference[i] - (least + greatest) / 2.0) / turn).round();
            if fewest > most {
                0.0
            } else {
                wanted.clamp(fewest, most) * turn
            }
        })
    }
}

/// Fixed transform of one revolute joint, expressed so that the joint turns about its local +z.
#[derive(Clone, Debug)]
pub(crate) struct JointFrame {
    pub(crate) rotation: Matrix3<f64>,
    pub(crate) translation: Vec3,
}

impl JointFrame {
    /// The slot of a joint the arm does not have (an arm of six fills the seventh slot with
    /// it): no offset, and a "rotation" without a z column, so its axis, its Jacobian columns
    /// and every gradient entry it gets are exactly zero. The frame after it is never read.
    fn absent() -> Self {
        Self {
            rotation: Matrix3::from_diagonal(&Vec3::new(1.0, 1.0, 0.0)),
            translation: Vec3::zeros(),
        }
    }
}

/// Position range (rad) and velocity limit (rad/s) held by a joint slot the arm does not have.
const ABSENT_JOINT_LIMITS: (f64, f64, f64) = (-std::f64::consts::PI, std::f64::consts::PI, 1.0);

/// A serial arm of six or seven revolute joints with a tool: the immutable model every
/// algorithm reads.
///
/// Built once from a URDF file; cheap to share between threads (`&Robot` is all any
/// algorithm needs). Joint frames are normalised at load time so that every joint turns about
/// its local +z axis whatever axis the file gives.
#[derive(Clone, Debug)]
pub struct Robot {
    pub(crate) name: String,
    pub(crate) base_link: String,
    pub(crate) tip_link: String,
    pub(crate) joint_names: Vec<String>,
    /// Revolute joints of the chain (6 or 7); the slots past them hold [`JointFrame::absent`].
    pub(crate) dof: usize,
    pub(crate) joints: [JointFrame; MAX_DOF],
    pub(crate) tcp_offset: JointFrame,
    pub(crate) limits: JointLimits,
    pub(crate) capsules: Vec<Capsule>,
    /// The bounding spheres of the self-collision test.
    pub(crate) broad_phase: BroadPhase,
    /// Index of the first of the tool's capsules (they close the list).
    pub(crate) first_tool_capsule: usize,
    pub(crate) pairs: Vec<CollisionPair>,
    pub(crate) pair_rule: PairRule,
    pub(crate) reach_centre: Vec3,
    pub(crate) reach_radius: f64,
}

struct ChainLink<'a> {
    link: &'a urdf_rs::Link,
    segment: usize,
    offset: Isometry3<f64>,
}

impl Robot {
    /// Reads the chain from `base_link` to `tip_link` of a URDF file, with the pair rule of
    /// [`PairRule::for_robot_file`] (an SRDF file beside it lists the pairs not checked).
    pub fn from_urdf_file(
        path: impl AsRef<Path>,
        base_link: &str,
        tip_link: &str,
    ) -> Result<Self, RobotError> {
        let path = path.as_ref();
        let text = read_text(path)?;
        Self::from_urdf_str_with_rule(&text, base_link, tip_link, PairRule::for_robot_file(path)?)
    }

    /// Reads a URDF file whose links form one chain: from its root link to its only leaf link
    /// (pair rule as [`Robot::from_urdf_file`]).
    pub fn from_chain_file(path: impl AsRef<Path>) -> Result<Self, RobotError> {
        Self::from_file_between(path, None, None)
    }

    /// Reads the chain of a URDF file from `base_link` (default: the file's only root link) to
    /// `tip_link` (default: its only leaf link), pair rule as [`Robot::from_urdf_file`].
    pub fn from_file_between(
        path: impl AsRef<Path>,
        base_link: Option<&str>,
        tip_link: Option<&str>,
    ) -> Result<Self, RobotError> {
        let path = path.as_ref();
        let text = read_text(path)?;
        let urdf =
            urdf_rs::read_from_string(&text).map_err(|e| RobotError::Malformed(e.to_string()))?;
        let (base, tip) = chain_ends(&urdf, base_link, tip_link)?;
        Self::from_urdf_str_with_rule(&text, &base, &tip, PairRule::for_robot_file(path)?)
    }

    /// Reads URDF text whose links form one chain: from its root link to its only leaf link.
    pub fn from_chain_str(text: &str) -> Result<Self, RobotError> {
        Self::chain_with_rule(text, PairRule::LinkSeparation)
    }

    /// The chain from the root link to the only leaf link of URDF text, with `pair_rule`.
    fn chain_with_rule(text: &str, pair_rule: PairRule) -> Result<Self, RobotError> {
        let urdf =
            urdf_rs::read_from_string(text).map_err(|e| RobotError::Malformed(e.to_string()))?;
        let (base, tip) = chain_ends(&urdf, None, None)?;
        Self::from_urdf_str_with_rule(text, &base, &tip, pair_rule)
    }

    /// Reads the chain from `base_link` to `tip_link` of URDF text, checking bodies at least
    /// three links apart for self-collision ([`PairRule::LinkSeparation`]).
    pub fn from_urdf_str(text: &str, base_link: &str, tip_link: &str) -> Result<Self, RobotError> {
        Self::from_urdf_str_with_rule(text, base_link, tip_link, PairRule::LinkSeparation)
    }

    /// Reads the chain from `base_link` to `tip_link` of URDF text, checking the capsule pairs
    /// `pair_rule` names.
    pub fn from_urdf_str_with_rule(
        text: &str,
        base_link: &str,
        tip_link: &str,
        pair_rule: PairRule,
    ) -> Result<Self, RobotError> {
        let urdf =
            urdf_rs::read_from_string(text).map_err(|e| RobotError::Malformed(e.to_string()))?;
        let path = chain_joints(&urdf, base_link, tip_link)?;
        let links: HashMap<&str, &urdf_rs::Link> =
            urdf.links.iter().map(|l| (l.name.as_str(), l)).collect();

        let mut joints = Vec::with_capacity(MAX_DOF);
        let mut joint_names = Vec::with_capacity(MAX_DOF);
        let (mut lower, mut upper, mut velocity) = (Vec::new(), Vec::new(), Vec::new());
        let mut chain = vec![ChainLink {
            link: links[base_link],
            segment: 0,
            offset: Isometry3::identity(),
        }];
        // Transform from the current segment frame (the last revolute joint's frame) to the
        // current link's URDF frame.
        let mut offset = Isometry3::identity();
        for joint in &path {
            let origin =
                pose_to_isometry(&joint.origin).map_err(|problem| RobotError::BadJoint {
                    joint: joint.name.clone(),
                    field: "origin",
                    problem,
                })?;
            match joint.joint_type {
                urdf_rs::JointType::Fixed => offset *= origin,
                urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous => {
                    let axis_alignment = axis_alignment(joint)?;
                    let frame = offset * origin * axis_alignment;
                    joints.push(JointFrame {
                        rotation: frame.rotation.to_rotation_matrix().into_inner(),
                        translation: frame.translation.vector,
                    });
                    let (lo, hi) = position_range(joint)?;
                    joint_names.push(joint.name.clone());
                    lower.push(lo);
                    upper.push(hi);
                    velocity.push(joint.limit.velocity);
                    offset = axis_alignment.inverse();
                }
                ref other => {
                    return Err(RobotError::UnsupportedJoint {
                        joint: joint.name.clone(),
                        kind: format!("{other:?}").to_lowercase(),
                    });
                }
            }
            chain.push(ChainLink {
                link: links[joint.child.link.as_str()],
                segment: joints.len(),
                offset,
            });
        }
        let dof = joints.len();
        if !(MIN_DOF..=MAX_DOF).contains(&dof) {
            return Err(RobotError::WrongDof {
                base: base_link.into(),
                tip: tip_link.into(),
                found: dof,
                reason: if dof < MIN_DOF {
                    "with fewer, the tool cannot keep its position and still move in the null space"
                } else {
                    "joint vectors hold at most seven entries"
                },
            });
        }
        let (absent_lower, absent_upper, absent_velocity) = ABSENT_JOINT_LIMITS;
        joints.resize_with(MAX_DOF, JointFrame::absent);
        lower.resize(MAX_DOF, absent_lower);
        upper.resize(MAX_DOF, absent_upper);
        velocity.resize(MAX_DOF, absent_velocity);
        let capsules = chain_capsules(&chain)?;
        let first_tool_capsule = first_tool_capsule(&capsules, dof);
        if capsules.len() > MAX_CAPSULES {
            return Err(RobotError::TooManyCapsules {
                found: capsules.len(),
            });
        }
        let pairs = collision_pairs(&capsules, &pair_rule);
        let broad_phase = BroadPhase::new(&capsules, &pairs);
        let joints: [JointFrame; MAX_DOF] = joints.try_into().expect("length checked above");
        let reach_centre = joints[0].translation;
        let reach_radius = joints[1..dof]
            .iter()
            .map(|j| j.translation.norm())
            .sum::<f64>()
            + offset.translation.vector.norm();
        Ok(Self {
            name: urdf.name.clone(),
            base_link: base_link.into(),
            tip_link: tip_link.into(),
            joint_names,
            dof,
            joints,
            tcp_offset: JointFrame {
                rotation: offset.rotation.to_rotation_matrix().into_inner(),
                translation: offset.translation.vector,
            },
            limits: JointLimits {
                lower: JointVector::from_column_slice(&lower),
                upper: JointVector::from_column_slice(&upper),
                velocity: JointVector::from_column_slice(&velocity),
            },
            capsules,
            broad_phase,
            first_tool_capsule,
            pairs,
            pair_rule,
            reach_centre,
            reach_radius,
        }
        .with_clearance_floors())
    }

    /// SHA-256 (hex) of the chain as the planners see it: every joint frame (rotation and
    /// translation, the axis turned onto local +z), the TCP offset, and the position and velocity
    /// limits, as little-endian `f64`. Two files that describe the same arm give the same
    /// fingerprint; any change of a frame, an axis, a limit or the tool gives another.
    pub fn fingerprint(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut hash = Sha256::new();
        let frames = self.joints[..self.dof]
            .iter()
            .chain(std::iter::once(&self.tcp_offset));
        for frame in frames {
            for value in frame.rotation.iter().chain(frame.translation.iter()) {
                hash.update(value.to_le_bytes());
            }
        }
        let limits = &self.limits;
        let joints = ..self.dof;
        for value in limits.lower.as_slice()[joints]
            .iter()
            .chain(&limits.upper.as_slice()[joints])
            .chain(&limits.velocity.as_slice()[joints])
        {
            hash.update(value.to_le_bytes());
        }
        hash.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    /// The robot's name from the file.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Name of the chain's base link (the frame every position is expressed in).
    pub fn base_link(&self) -> &str {
        &self.base_link
    }

    /// Name of the chain's tip link (the TCP frame).
    pub fn tip_link(&self) -> &str {
        &self.tip_link
    }

    /// The TCP's frame in the frame of the last joint's segment (where the tool is mounted):
    /// its position (m) and its rotation (columns are the TCP frame's axes).
    pub fn tcp_offset(&self) -> (Vec3, Matrix3<f64>) {
        (self.tcp_offset.translation, self.tcp_offset.rotation)
    }

    /// Number of revolute joints `n` (6 or 7): the leading entries of every [`JointVector`] of
    /// this arm.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// The configuration whose joint `i < n` is `joint(i)`, called in joint order (a sampler's
    /// draws stay in that order), and whose entries past the arm's joints are zero.
    pub fn configuration_from_fn(&self, mut joint: impl FnMut(usize) -> f64) -> JointVector {
        JointVector::from_fn(|i, _| if i < self.dof { joint(i) } else { 0.0 })
    }

    /// The first `n` entries of `q`: the arm's joints.
    pub fn joints_of<'q>(&self, q: &'q JointVector) -> &'q [f64] {
        &q.as_slice()[..self.dof]
    }

    /// The joint vector of the arm's `n` joint values (`values.len()` must be `n`), zero past
    /// them.
    pub fn joint_vector(&self, values: &[f64]) -> JointVector {
        assert_eq!(values.len(), self.dof, "one value per joint of the arm");
        self.configuration_from_fn(|i| values[i])
    }

    /// Names of the `n` revolute joints, base to tip.
    pub fn joint_names(&self) -> &[String] {
        &self.joint_names
    }

    /// Joint position and velocity limits.
    pub fn limits(&self) -> &JointLimits {
        &self.limits
    }

    /// The same arm with its position limits narrowed to within `half_width_rad` of `reference`
    /// where they span more than a turn ([`JointLimits::within`]).
    pub fn within(&self, reference: &JointVector, half_width_rad: f64) -> Robot {
        Robot {
            limits: self.limits.within(reference, half_width_rad),
            ..self.clone()
        }
    }

    /// The collision capsules of every body of the chain.
    pub fn capsules(&self) -> &[Capsule] {
        &self.capsules
    }

    /// Indices (into [`Robot::capsules`]) of the tool's capsules: those of the last link of the
    /// chain that carries any, when that link moves with the last joint (the pen of the shipped
    /// robots); empty when the last joint's segment carries no capsule.
    pub fn tool_capsules(&self) -> std::ops::Range<usize> {
        self.first_tool_capsule..self.capsules.len()
    }

    /// The capsule pairs checked for self-collision: bodies that move relative to each other
    /// and that [`Robot::pair_rule`] checks.
    pub fn collision_pairs(&self) -> &[CollisionPair] {
        &self.pairs
    }

    /// Which bodies are checked against each other for self-collision.
    pub fn pair_rule(&self) -> &PairRule {
        &self.pair_rule
    }

    /// Mid-range configuration `q_mid`, the default seed (the robot file carries no home pose).
    pub fn mid_range(&self) -> JointVector {
        self.limits.mid()
    }

    /// The space the arm's base occupies whatever its configuration: a capsule along the first
    /// joint's axis holding every capsule of the base link and of the body the first joint
    /// turns, in every turn of that joint (the first body only spins about the axis, so no
    /// configuration moves it out of the way). `(start, end, radius)` in the base frame; `None`
    /// when those bodies carry no capsule.
    pub fn base_column(&self) -> Option<(Vec3, Vec3, f64)> {
        let kinematics = self.forward(&self.mid_range());
        let origin = kinematics.joint_origin(0);
        let axis = kinematics.joint_axis(0);
        let mut heights = (f64::INFINITY, f64::NEG_INFINITY);
        let mut radius: f64 = 0.0;
        for capsule in self.capsules.iter().filter(|c| c.segment <= 1) {
            for local in [&capsule.start, &capsule.end] {
                let offset = kinematics.segment_point(capsule.segment, local) - origin;
                let height = offset.dot(&axis);
                heights = (heights.0.min(height), heights.1.max(height));
                radius = radius.max((offset - axis * height).norm() + capsule.radius);
            }
        }
        heights
            .0
            .is_finite()
            .then(|| (origin + axis * heights.0, origin + axis * heights.1, radius))
    }

    /// The joint that only spins the tool about its own axis, if the arm has one: its last
    /// joint, where that joint's axis runs along the tool axis through the TCP (a pen mounted on
    /// the flange's axis). Turning it moves neither the TCP nor the tool axis, so a task that
    /// constrains only those (every task here: the position, the tool cone) leaves it free; it
    /// still turns the tool's and the flange's bodies, which a collision check must see.
    pub fn tool_roll_joint(&self) -> Option<usize> {
        /// Distance (m) and sine of the angle below which the axis counts as the tool's.
        const ON_AXIS: f64 = 1e-9;
        let last = self.dof.checked_sub(1)?;
        let kinematics = self.forward(&self.mid_range());
        let axis = kinematics.joint_axis(last);
        let off_axis = (kinematics.tcp() - kinematics.joint_origin(last)).cross(&axis);
        (axis.cross(&kinematics.tool_axis()).norm() < ON_AXIS && off_axis.norm() < ON_AXIS)
            .then_some(last)
    }

    /// A sphere (centre, radius) that contains every TCP position the arm can reach.
    pub fn reach_sphere(&self) -> (Vec3, f64) {
        (self.reach_centre, self.reach_radius)
    }
}

/// The joints from `base` down to `tip`, in order, checking the chain is serial.
/// The chain's base and tip: those named, else the file's only root and only leaf link.
fn chain_ends(
    urdf: &urdf_rs::Robot,
    base: Option<&str>,
    tip: Option<&str>,
) -> Result<(String, String), RobotError> {
    let is_child = |name: &str| urdf.joints.iter().any(|j| j.child.link == name);
    let is_parent = |name: &str| urdf.joints.iter().any(|j| j.parent.link == name);
    let names = |keep: &dyn Fn(&str) -> bool| {
        urdf.links
            .iter()
            .map(|l| l.name.as_str())
            .filter(|name| keep(name))
            .collect::<Vec<_>>()
    };
    let roots = names(&|name| !is_child(name));
    let leaves = names(&|name| !is_parent(name));
    let only = |given: Option<&str>, found: &[&str]| match (given, found) {
        (Some(name), _) => Some(name.to_string()),
        (None, [one]) => Some(one.to_string()),
        (None, _) => None,
    };
    match (only(base, &roots), only(tip, &leaves)) {
        (Some(base), Some(tip)) => Ok((base, tip)),
        _ => Err(RobotError::AmbiguousChain {
            roots: roots.join(", "),
            leaves: leaves.join(", "),
        }),
    }
}

fn chain_joints<'a>(
    urdf: &'a urdf_rs::Robot,
    base: &str,
    tip: &str,
) -> Result<Vec<&'a urdf_rs::Joint>, RobotError> {
    let available = || {
        urdf.links
            .iter()
            .map(|l| l.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (role, name) in [("base", base), ("tip", tip)] {
        if !urdf.links.iter().any(|l| l.name == name) {
            return Err(RobotError::MissingLink {
                role,
                name: name.into(),
                available: available(),
            });
        }
    }
    let parent_joint: HashMap<&str, &urdf_rs::Joint> = urdf
        .joints
        .iter()
        .map(|j| (j.child.link.as_str(), j))
        .collect();
    let not_a_chain = || RobotError::NotAChain {
        base: base.into(),
        tip: tip.into(),
    };
    let mut path = Vec::new();
    let mut link = tip;
    while link != base {
        let joint = parent_joint.get(link).ok_or_else(not_a_chain)?;
        // A walk longer than the file's joints has met a loop.
        if path.len() == urdf.joints.len() {
            return Err(not_a_chain());
        }
        path.push(*joint);
        link = joint.parent.link.as_str();
        if !urdf.links.iter().any(|l| l.name == link) {
            return Err(RobotError::MissingLink {
                role: "joint parent",
                name: link.into(),
                available: available(),
            });
        }
    }
    path.reverse();
    for joint in &path {
        let parent = joint.parent.link.as_str();
        let children: Vec<&str> = urdf
            .joints
            .iter()
            .filter(|j| j.parent.link == parent)
            .map(|j| j.name.as_str())
            .collect();
        if children.len() > 1 {
            return Err(RobotError::Branching {
                link: parent.into(),
                count: children.len(),
                joints: children.join(", "),
            });
        }
    }
    Ok(path)
}

/// The transform of a URDF `<origin>`; fails unless its six numbers are finite.
fn pose_to_isometry(pose: &urdf_rs::Pose) -> Result<Isometry3<f64>, String> {
    let [x, y, z] = pose.xyz.0;
    let [roll, pitch, yaw] = pose.rpy.0;
    if !pose.xyz.0.iter().chain(&pose.rpy.0).all(|v| v.is_finite()) {
        return Err(format!(
            "xyz {:?} rpy {:?} must be finite numbers",
            pose.xyz.0, pose.rpy.0
        ));
    }
    Ok(Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_rotation_matrix(&rotation_from_rpy(roll, pitch, yaw)),
    ))
}

/// Rotation that takes local +z onto the joint's axis, so the joint turns about +z after it.
fn axis_alignment(joint: &urdf_rs::Joint) -> Result<Isometry3<f64>, RobotError> {
    let axis = Vector3::from(joint.axis.xyz.0);
    let norm = axis.norm();
    if !(norm.is_finite() && norm > 1e-9) {
        return Err(RobotError::BadJoint {
            joint: joint.name.clone(),
            field: "axis",
            problem: format!("{:?} is not a usable direction", joint.axis.xyz.0),
        });
    }
    let rotation = rotation_onto(&Vector3::z(), &(axis / norm));
    Ok(Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_rotation_matrix(&rotation),
    ))
}

/// Position range (rad) of a `continuous` joint, an unbounded revolute joint: a full turn each
/// way of zero. A robot file that wants another range declares the joint `revolute` with its
/// `<limit lower upper>`.
pub const CONTINUOUS_JOINT_RANGE_RAD: f64 = std::f64::consts::TAU;

/// The position range of a revolute joint (its `<limit>`) or a continuous one
/// (±[`CONTINUOUS_JOINT_RANGE_RAD`]), after checking the range and the velocity limit.
fn position_range(joint: &urdf_rs::Joint) -> Result<(f64, f64), RobotError> {
    let bad = |field, problem: String| RobotError::BadJoint {
        joint: joint.name.clone(),
        field,
        problem,
    };
    let (lo, hi) = match joint.joint_type {
        urdf_rs::JointType::Continuous => (-CONTINUOUS_JOINT_RANGE_RAD, CONTINUOUS_JOINT_RANGE_RAD),
        _ => (joint.limit.lower, joint.limit.upper),
    };
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(bad(
            "limit",
            format!("lower {lo} must be finite and below upper {hi}"),
        ));
    }
    let v = joint.limit.velocity;
    if !(v.is_finite() && v > 0.0) {
        return Err(bad("velocity", format!("{v} must be a positive number")));
    }
    Ok((lo, hi))
}

/// Distance (m) within which a sphere counts as the cap of a cylinder end: a capsule written
/// the standard way, as a cylinder plus a sphere of the same radius at each end, reads back as
/// one capsule.
const CAP_TOLERANCE_M: f64 = 1e-6;

/// One collision element of a link, in its segment's frame.
struct CollisionShape {
    /// Axis end points (equal for a sphere).
    start: Vec3,
    end: Vec3,
    radius: f64,
    /// A `<cylinder>`: it needs a sphere cap at each end.
    cylinder: bool,
}

/// Index of the first capsule of the tool (see [`Robot::tool_capsules`]); capsules come in chain
/// order, so the tool's close the list.
fn first_tool_capsule(capsules: &[Capsule], dof: usize) -> usize {
    match capsules.last() {
        Some(last) if last.segment == dof => capsules
            .iter()
            .position(|c| c.chain_index == last.chain_index)
            .expect("the last capsule is in the list"),
        _ => capsules.len(),
    }
}

fn chain_capsules(chain: &[ChainLink<'_>]) -> Result<Vec<Capsule>, RobotError> {
    let mut capsules = Vec::new();
    for (chain_index, entry) in chain.iter().enumerate() {
        let shapes = entry
            .link
            .collision
            .iter()
            .map(|collision| collision_shape(entry, collision))
            .collect::<Result<Vec<_>, _>>()?;
        for (index, shape) in shapes.iter().enumerate() {
            if is_cap(shape, &shapes) {
                continue;
            }
            if shape.cylinder {
                for end in [&shape.start, &shape.end] {
                    let capped = shapes.iter().enumerate().any(|(other, cap)| {
                        other != index && !cap.cylinder && caps(cap, end, shape.radius)
                    });
                    if !capped {
                        return Err(RobotError::UncappedCylinder {
                            link: entry.link.name.clone(),
                        });
                    }
                }
            }
            capsules.push(Capsule {
                link: entry.link.name.clone(),
                chain_index,
                segment: entry.segment,
                start: shape.start,
                end: shape.end,
                radius: shape.radius,
            });
        }
    }
    Ok(capsules)
}

/// Whether the sphere `cap` sits on the end point `end` of a cylinder of radius `radius`.
fn caps(cap: &CollisionShape, end: &Vec3, radius: f64) -> bool {
    (cap.start - end).norm() <= CAP_TOLERANCE_M && (cap.radius - radius).abs() <= CAP_TOLERANCE_M
}

/// Whether `shape` is a sphere capping an end of one of the link's cylinders.
fn is_cap(shape: &CollisionShape, shapes: &[CollisionShape]) -> bool {
    !shape.cylinder
        && (shape.start - shape.end).norm() == 0.0
        && shapes.iter().any(|cylinder| {
            cylinder.cylinder
                && [&cylinder.start, &cylinder.end]
                    .into_iter()
                    .any(|end| caps(shape, end, cylinder.radius))
        })
}

/// A `<capsule>`, `<cylinder>` or `<sphere>` collision element in its segment's frame: an axis
/// of the given length along the element's z-axis, swept by the radius.
fn collision_shape(
    entry: &ChainLink<'_>,
    collision: &urdf_rs::Collision,
) -> Result<CollisionShape, RobotError> {
    let (radius, half_length, cylinder) = match collision.geometry {
        urdf_rs::Geometry::Capsule { radius, length } => (radius, 0.5 * length, false),
        urdf_rs::Geometry::Cylinder { radius, length } => (radius, 0.5 * length, true),
        urdf_rs::Geometry::Sphere { radius } => (radius, 0.0, false),
        ref other => {
            return Err(RobotError::UnsupportedGeometry {
                link: entry.link.name.clone(),
                kind: match other {
                    urdf_rs::Geometry::Box { .. } => "box",
                    _ => "mesh",
                },
            });
        }
    };
    let bad = |field, problem| RobotError::BadGeometry {
        link: entry.link.name.clone(),
        field,
        problem,
    };
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(bad("radius", format!("{radius} must be a number ≥ 0")));
    }
    if !(half_length.is_finite() && half_length >= 0.0) {
        let length = 2.0 * half_length;
        return Err(bad("length", format!("{length} must be a number ≥ 0")));
    }
    let origin = pose_to_isometry(&collision.origin).map_err(|p| bad("origin", p))?;
    let frame = entry.offset * origin;
    Ok(CollisionShape {
        start: (frame * Point3::new(0.0, 0.0, -half_length)).coords,
        end: (frame * Point3::new(0.0, 0.0, half_length)).coords,
        radius,
        cylinder,
    })
}

fn collision_pairs(capsules: &[Capsule], rule: &PairRule) -> Vec<CollisionPair> {
    let mut pairs = Vec::new();
    for (i, a) in capsules.iter().enumerate() {
        for (j, b) in capsules.iter().enumerate().skip(i + 1) {
            if a.segment != b.segment && rule.checks(&a.link, a.chain_index, &b.link, b.chain_index)
            {
                pairs.push(CollisionPair {
                    first: i,
                    second: j,
                });
            }
        }
    }
    pairs
}
