//! The robot as the checker sees it: read straight from the URDF file, evaluated with plain 4×4
//! homogeneous transforms (URDF joint origin × rotation about the file's joint axis), its own
//! collision-pair rule and its own segment-distance routine.

use nalgebra::{Matrix3, Matrix4, Rotation3, Unit, Vector3, Vector4};

use crate::record::{Bounds, Joints, Line, MAX_JOINTS, MIN_JOINTS, Solid};

/// The position range (rad) the planners give a `continuous` joint, as documented: a full turn
/// each way of zero.
const CONTINUOUS_RANGE: f64 = std::f64::consts::TAU;

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
    /// Chain index of the link whose capsules are the tool (the last link carrying capsules,
    /// when no revolute joint follows it), if any.
    tool_link: Option<usize>,
    /// Link pairs not checked for self-collision, from an SRDF file beside the robot file;
    /// `None`: links at least three apart are checked.
    disabled: Option<Vec<(String, String)>>,
    /// The checked capsule pairs (indices into `capsules`, the first the lower), in the order
    /// the nested loop over `capsules` meets them: `checked` applied once, when the model is
    /// read.
    pairs: Vec<(usize, usize)>,
}

/// The name the work surface goes by in failures.
const WORK_SURFACE: &str = "work surface";

/// Golden-section iterations when minimising a convex distance along a capsule's axis: the
/// bracket shrinks to 0.618^200 of the axis, far below rounding.
const GOLDEN_SECTION_STEPS: usize = 200;

/// Why the checker cannot read a robot file.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The file cannot be read.
    #[error("cannot read {path}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The text is not a URDF document.
    #[error("not a URDF document: {0}")]
    Urdf(String),
    /// No joint has this link as its child, so the chain cannot reach the base.
    #[error("no joint leads to link '{0}' on the way from the tip to the base")]
    Unreachable(String),
    /// A link of the chain is named by a joint but not defined.
    #[error("link '{0}' is not defined")]
    MissingLink(String),
    /// A collision cylinder lacks a sphere cap on one of its ends.
    #[error("link '{0}': a collision cylinder needs a sphere of its radius on each end")]
    UncappedCylinder(String),
    /// A collision element is neither a capsule, a capped cylinder nor a sphere.
    #[error(
        "link '{0}': unsupported collision geometry (the checker reads capsules, cylinders \
         with sphere caps and spheres)"
    )]
    Geometry(String),
    /// The walk from the tip towards the base comes back to a link it has passed.
    #[error("the joints from the tip towards the base form a loop at link '{0}'")]
    Loop(String),
    /// The SRDF file beside the robot file cannot be read.
    #[error("SRDF file {path}: {problem}")]
    Srdf {
        /// The file.
        path: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A number of the file the checker needs is not usable.
    #[error("{element}: {problem}")]
    Value {
        /// The joint or link and the field, e.g. `joint 'fr3_joint1' origin`.
        element: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The chain does not have the supported number of revolute joints.
    #[error("the chain has {0} revolute joints, expected {MIN_JOINTS} or {MAX_JOINTS}")]
    JointCount(usize),
}

impl ReferenceModel {
    /// Reads the chain from `base` to `tip` of URDF text.
    pub fn from_urdf_str(text: &str, base: &str, tip: &str) -> Result<Self, ModelError> {
        let urdf = urdf_rs::read_from_string(text).map_err(|e| ModelError::Urdf(e.to_string()))?;
        let path = chain_path(&urdf, base, tip)?;
        let mut link_names = vec![base.to_string()];
        link_names.extend(path.iter().map(|j| j.child.link.clone()));
        let joints = path
            .iter()
            .map(|joint| reference_joint(joint))
            .collect::<Result<Vec<_>, _>>()?;
        let mut capsules = Vec::new();
        for (chain_index, name) in link_names.iter().enumerate() {
            capsules.extend(link_capsules(&urdf, chain_index, name)?);
        }
        let revolute = joints.iter().filter(|j| j.axis.is_some()).count();
        if !(MIN_JOINTS..=MAX_JOINTS).contains(&revolute) {
            return Err(ModelError::JointCount(revolute));
        }
        let tool_link = tool_link(&joints, &capsules);
        let mut model = Self {
            joints,
            capsules,
            tool_link,
            disabled: None,
            pairs: Vec::new(),
        };
        model.pairs = model.checked_pairs();
        Ok(model)
    }

    /// Reads the chain from `base` to `tip` of a URDF file.
    pub fn from_urdf_file(
        path: &std::path::Path,
        base: &str,
        tip: &str,
    ) -> Result<Self, ModelError> {
        let text = std::fs::read_to_string(path).map_err(|source| ModelError::Io {
            path: path.display().to_string(),
            source,
        })?;
        let mut model = Self::from_urdf_str(&text, base, tip)?;
        let srdf = path.with_extension("srdf");
        if srdf.is_file() {
            let text = std::fs::read_to_string(&srdf).map_err(|source| ModelError::Io {
                path: srdf.display().to_string(),
                source,
            })?;
            model.disabled =
                Some(
                    disabled_collisions(&text).map_err(|problem| ModelError::Srdf {
                        path: srdf.display().to_string(),
                        problem,
                    })?,
                );
            model.pairs = model.checked_pairs();
        }
        Ok(model)
    }

    /// Whether the capsules `a` and `b` are checked against each other: links at least three
    /// apart, or, with an SRDF file, links it does not list (links that never move relative to
    /// each other keep their clearance, so checking them costs nothing but time).
    fn checked(&self, a: &ReferenceCapsule, b: &ReferenceCapsule) -> bool {
        match &self.disabled {
            None => a.chain_index.abs_diff(b.chain_index) >= 3,
            Some(pairs) => !pairs
                .iter()
                .any(|(x, y)| (*x == a.link && *y == b.link) || (*x == b.link && *y == a.link)),
        }
    }

    /// The checked capsule pairs, in the order of the nested loop over `capsules`.
    fn checked_pairs(&self) -> Vec<(usize, usize)> {
        let mut pairs = Vec::new();
        for (i, a) in self.capsules.iter().enumerate() {
            for (j, b) in self.capsules.iter().enumerate().skip(i + 1) {
                if self.checked(a, b) {
                    pairs.push((i, j));
                }
            }
        }
        pairs
    }

    /// Link frames base to tip (one per link of the chain) for configuration `q`.
    fn link_frames(&self, q: &Joints) -> Vec<Matrix4<f64>> {
        let mut frames = Vec::with_capacity(self.joints.len() + 1);
        self.link_frames_into(q, &mut frames);
        frames
    }

    /// [`Self::link_frames`] written into `frames` (cleared first), so that a caller placing
    /// many configurations reuses one buffer.
    fn link_frames_into(&self, q: &Joints, frames: &mut Vec<Matrix4<f64>>) {
        frames.clear();
        frames.push(Matrix4::identity());
        let mut revolute = 0;
        for joint in &self.joints {
            let mut transform = frames.last().expect("base frame") * joint.origin;
            if let Some(axis) = &joint.axis {
                transform *= axis_rotation(axis, q[revolute]).to_homogeneous();
                revolute += 1;
            }
            frames.push(transform);
        }
    }

    /// An empty [`Placement`] of this robot, to be filled by [`Self::place`].
    pub(crate) fn placement(&self) -> Placement {
        Placement {
            frames: Vec::with_capacity(self.joints.len() + 1),
            ends: Vec::with_capacity(self.capsules.len()),
            spheres: Vec::with_capacity(self.capsules.len()),
        }
    }

    /// Places configuration `q` into `placement`: one pass of forward kinematics, every
    /// capsule's axis ends in the base frame and its bounding sphere. Each value is computed
    /// by the very operations [`Self::tcp_pose`], [`Self::min_clearance`] and
    /// [`Self::scene_margin`] use, so the results from a placement are theirs bit for bit.
    pub(crate) fn place(&self, q: &Joints, placement: &mut Placement) {
        self.link_frames_into(q, &mut placement.frames);
        placement.ends.clear();
        placement.spheres.clear();
        for capsule in &self.capsules {
            let frame = &placement.frames[capsule.chain_index];
            let world = |v: &Vector3<f64>| (frame * Vector4::new(v.x, v.y, v.z, 1.0)).xyz();
            let (start, end) = (world(&capsule.start), world(&capsule.end));
            placement.spheres.push((
                (start + end) * 0.5,
                (end - start).norm() * 0.5 + capsule.radius,
            ));
            placement.ends.push([start, end]);
        }
    }

    /// TCP position and tool axis (z of the tip link) for `q`.
    pub fn tcp_pose(&self, q: &Joints) -> (Vector3<f64>, Vector3<f64>) {
        let tip = *self.link_frames(q).last().expect("tip frame");
        (
            tip.fixed_view::<3, 1>(0, 3).into_owned(),
            tip.fixed_view::<3, 1>(0, 2).into_owned(),
        )
    }

    /// TCP position and orientation (the tip link's frame: its rotation's columns are the
    /// tip's x, y and z axes in the base frame, z the tool axis of [`Self::tcp_pose`]) for `q`.
    pub fn tcp_frame(&self, q: &Joints) -> (Vector3<f64>, Matrix3<f64>) {
        let tip = *self.link_frames(q).last().expect("tip frame");
        (
            tip.fixed_view::<3, 1>(0, 3).into_owned(),
            tip.fixed_view::<3, 3>(0, 0).into_owned(),
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

    /// Smallest clearance (m) over the checked capsule pairs (links at least three apart, or
    /// those an SRDF file beside the robot file does not disable), with their links.
    pub fn min_clearance(&self, q: &Joints) -> (f64, String, String) {
        let mut placement = self.placement();
        self.place(q, &mut placement);
        self.clearance_names(self.placed_clearance(&placement))
    }

    /// The smallest clearance (m) of a placed configuration and the index in `pairs` of its
    /// pair: the first pair in `pairs` order with the smallest clearance, as the exhaustive
    /// loop over the pairs finds it (`None`: no pair, or no clearance below infinity).
    ///
    /// Pairs are pruned, soundly: the distance between two capsules' axes is at least the
    /// distance between their bounding spheres' centres less both half axes (every axis point
    /// lies within its half axis of the centre), so a pair whose sphere bound exceeds the
    /// smallest clearance found by more than [`PRUNE_SLACK_M`] (far above the rounding of
    /// either computation, ~1e-15 m at a robot's scale) cannot be the smallest, nor tie with
    /// it. The pair with the smallest bound is measured first, so that most pairs are pruned;
    /// ties then go to the earlier pair, as the exhaustive loop's strict `<` does. Without a
    /// finite bound (a configuration that is not finite) every pair is measured in order.
    pub(crate) fn placed_clearance(&self, placement: &Placement) -> (f64, Option<usize>) {
        let gap = |(i, j): (usize, usize)| {
            let ([a0, a1], [b0, b1]) = (&placement.ends[i], &placement.ends[j]);
            segments_gap(a0, a1, b0, b1) - self.capsules[i].radius - self.capsules[j].radius
        };
        let bound = |(i, j): (usize, usize)| {
            let ((ca, ra), (cb, rb)) = (&placement.spheres[i], &placement.spheres[j]);
            (ca - cb).norm() - ra - rb
        };
        let mut seed: Option<(f64, usize)> = None;
        for (index, &pair) in self.pairs.iter().enumerate() {
            let lower = bound(pair);
            if !lower.is_finite() {
                seed = None;
                break;
            }
            if seed.is_none_or(|(least, _)| lower < least) {
                seed = Some((lower, index));
            }
        }
        let mut best: (f64, Option<usize>) = (f64::INFINITY, None);
        let Some((_, first)) = seed else {
            // The exhaustive loop: the first pair with the smallest clearance.
            for (index, &pair) in self.pairs.iter().enumerate() {
                let gap = gap(pair);
                if gap < best.0 {
                    best = (gap, Some(index));
                }
            }
            return best;
        };
        let measured = gap(self.pairs[first]);
        if measured < best.0 {
            best = (measured, Some(first));
        }
        for (index, &pair) in self.pairs.iter().enumerate() {
            if index == first || bound(pair) > best.0 + PRUNE_SLACK_M {
                continue;
            }
            let gap = gap(pair);
            if gap < best.0 || (gap == best.0 && best.1.is_some_and(|b| index < b)) {
                best = (gap, Some(index));
            }
        }
        best
    }

    /// A clearance of [`Self::placed_clearance`] with its pair's links.
    pub(crate) fn clearance_names(
        &self,
        (gap, pair): (f64, Option<usize>),
    ) -> (f64, String, String) {
        match pair {
            Some(index) => {
                let (i, j) = self.pairs[index];
                (
                    gap,
                    self.capsules[i].link.clone(),
                    self.capsules[j].link.clone(),
                )
            }
            None => (gap, String::new(), String::new()),
        }
    }
}

/// How much (m) a lower bound of a distance must exceed the value it is compared with before
/// the checker skips measuring that distance exactly: far above the rounding of the bound and
/// of the exact measure (~1e-15 m for coordinates of a few metres), far below any clearance or
/// tolerance the checker reports.
pub(crate) const PRUNE_SLACK_M: f64 = 1e-9;

/// One configuration as the checker places it ([`ReferenceModel::place`]): its link frames,
/// every capsule's axis ends in the base frame and every capsule's bounding sphere.
pub(crate) struct Placement {
    frames: Vec<Matrix4<f64>>,
    /// Per capsule, its axis ends in the base frame.
    ends: Vec<[Vector3<f64>; 2]>,
    /// Per capsule, the midpoint of its axis and half the axis plus its radius.
    spheres: Vec<(Vector3<f64>, f64)>,
}

impl Placement {
    /// TCP position and tool axis, as [`ReferenceModel::tcp_pose`] gives them.
    pub(crate) fn tcp_pose(&self) -> (Vector3<f64>, Vector3<f64>) {
        let tip = self.frames.last().expect("tip frame");
        (
            tip.fixed_view::<3, 1>(0, 3).into_owned(),
            tip.fixed_view::<3, 1>(0, 2).into_owned(),
        )
    }
}

/// The solids a configuration keeps its distance from: the work surface of a line (which the
/// tool may touch) and the obstacles of the bounds, each with its clearance, its name and
/// whether the tool's capsules may touch it.
pub(crate) struct Scene<'a> {
    solids: Vec<(std::borrow::Cow<'a, Solid>, f64, &'a str, bool)>,
}

impl<'a> Scene<'a> {
    /// The work surface of `line` (when `bounds` ask for one) and the obstacles of `bounds`.
    pub(crate) fn new(line: &Line, bounds: &'a Bounds) -> Self {
        let surface = bounds.work_surface.map(|surface| {
            (
                std::borrow::Cow::Owned(surface.solid(line)),
                0.0,
                WORK_SURFACE,
                true,
            )
        });
        let obstacles = bounds.obstacles.iter().map(|o| {
            (
                std::borrow::Cow::Borrowed(&o.solid),
                o.clearance_m,
                o.name.as_str(),
                o.tool_may_touch,
            )
        });
        Self {
            solids: surface.into_iter().chain(obstacles).collect(),
        }
    }

    /// Whether there is nothing to keep away from.
    pub(crate) fn is_empty(&self) -> bool {
        self.solids.is_empty()
    }
}

impl ReferenceModel {
    /// Smallest margin (m) over the obstacles of `bounds` and, when `bounds` ask for it, the
    /// work surface of `line` (which the tool's capsules may touch): a capsule's surface
    /// distance from the solid minus the clearance asked for, with the capsule's link and the
    /// obstacle's name; `None` when there is nothing to keep away from.
    pub fn scene_margin(
        &self,
        q: &Joints,
        line: &Line,
        bounds: &Bounds,
    ) -> Option<(f64, String, String)> {
        let mut placement = self.placement();
        self.place(q, &mut placement);
        self.placed_scene_margin(&placement, &Scene::new(line, bounds))
    }

    /// The (solid, capsule) pairs of `scene` a placed configuration is measured against, in
    /// order: every solid with every capsule, but the tool's where the tool may touch it.
    fn scene_pairs<'s>(
        &'s self,
        scene: &'s Scene<'_>,
    ) -> impl Iterator<Item = (usize, usize)> + 's {
        scene
            .solids
            .iter()
            .enumerate()
            .flat_map(move |(s, (_, _, _, tool_may_touch))| {
                self.capsules
                    .iter()
                    .enumerate()
                    .filter(move |(_, capsule)| {
                        !(*tool_may_touch && Some(capsule.chain_index) == self.tool_link)
                    })
                    .map(move |(c, _)| (s, c))
            })
    }

    /// The margin of capsule `c` from solid `s` of `scene` by `depth`: measured exactly
    /// ([`axis_depth`]) or its lower bound ([`depth_lower_bound`]).
    fn scene_pair(
        &self,
        placement: &Placement,
        scene: &Scene<'_>,
        (s, c): (usize, usize),
        depth: fn(&Solid, &Vector3<f64>, &Vector3<f64>) -> f64,
    ) -> f64 {
        let (solid, clearance, _, _) = &scene.solids[s];
        let [start, end] = &placement.ends[c];
        depth(solid, start, end) - self.capsules[c].radius - clearance
    }

    /// Whether no capsule of a placed configuration can come within its clearance of a solid
    /// of `scene`: every lower bound of a margin ([`depth_lower_bound`]) is at least zero, so
    /// every margin [`Self::scene_margin`] measures is at least minus the rounding of the
    /// bound (far below the checks' slack). False where a bound is below zero or not a
    /// number; then the margins must be measured.
    pub(crate) fn scene_clear(&self, placement: &Placement, scene: &Scene<'_>) -> bool {
        self.scene_pairs(scene)
            .all(|(s, c)| self.scene_pair(placement, scene, (s, c), depth_lower_bound) >= 0.0)
    }

    /// [`Self::scene_margin`] of a placed configuration: the first (solid, capsule) pair in
    /// order with the smallest margin, a margin that is not a number being the worst of all
    /// (the last such pair).
    ///
    /// Pairs are pruned, soundly: a pair whose lower bound ([`depth_lower_bound`]) exceeds
    /// the smallest margin found by more than [`PRUNE_SLACK_M`] cannot be the smallest, nor
    /// tie with it. The pair with the smallest bound is measured first; ties then go to the
    /// earlier pair. Where a bound is not finite, every pair is measured in order.
    pub(crate) fn placed_scene_margin(
        &self,
        placement: &Placement,
        scene: &Scene<'_>,
    ) -> Option<(f64, String, String)> {
        if scene.is_empty() {
            return None;
        }
        let named = |(margin, s, c): (f64, usize, usize)| {
            (
                margin,
                self.capsules[c].link.clone(),
                scene.solids[s].2.to_string(),
            )
        };
        // The exhaustive loop: the first smallest margin, NaN the worst of all (the last).
        let exhaustive = || {
            let mut worst: Option<(f64, usize, usize)> = None;
            for (s, c) in self.scene_pairs(scene) {
                let margin = self.scene_pair(placement, scene, (s, c), axis_depth);
                if worst.is_none_or(|w| margin.is_nan() || margin < w.0) {
                    worst = Some((margin, s, c));
                }
            }
            worst
        };
        let mut seed: Option<(f64, usize, usize)> = None;
        for (s, c) in self.scene_pairs(scene) {
            let lower = self.scene_pair(placement, scene, (s, c), depth_lower_bound);
            if !lower.is_finite() {
                seed = None;
                break;
            }
            if seed.is_none_or(|(least, ..)| lower < least) {
                seed = Some((lower, s, c));
            }
        }
        let Some((_, s0, c0)) = seed else {
            return exhaustive().map(named);
        };
        let measured = self.scene_pair(placement, scene, (s0, c0), axis_depth);
        if measured.is_nan() {
            // Only an exhaustive loop tells which NaN is the last.
            return exhaustive().map(named);
        }
        let mut worst = (measured, s0, c0);
        for (s, c) in self.scene_pairs(scene) {
            if (s, c) == (s0, c0)
                || self.scene_pair(placement, scene, (s, c), depth_lower_bound)
                    > worst.0 + PRUNE_SLACK_M
            {
                continue;
            }
            let margin = self.scene_pair(placement, scene, (s, c), axis_depth);
            if margin.is_nan() {
                return exhaustive().map(named);
            }
            if margin < worst.0 || (margin == worst.0 && (s, c) < (worst.1, worst.2)) {
                worst = (margin, s, c);
            }
        }
        Some(named(worst))
    }
}

/// A lower bound of [`axis_depth`] that costs a few operations: the exact value for a
/// half-space, a ball and a capsule (their closest points are cheap); for a box, the largest
/// over its six faces of the smaller signed distance of the segment's two ends from the
/// face's plane. A box lies inside each face's half-space, so its signed distance is at least
/// each face's (outside: the box is farther than the half-space containing it; inside: the
/// depth is the distance to the nearest face plane), and along the segment a plane's signed
/// distance is affine, smallest at an end.
fn depth_lower_bound(solid: &Solid, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    match solid {
        Solid::Box {
            centre,
            axes,
            half_extents,
        } => {
            let (la, lb) = (axes.tr_mul(&(a - centre)), axes.tr_mul(&(b - centre)));
            let mut bound = f64::NEG_INFINITY;
            for i in 0..3 {
                let above = la[i].min(lb[i]);
                let below = (-la[i]).min(-lb[i]);
                bound = bound.max(above.max(below) - half_extents[i]);
            }
            // Not a number where an end is not finite (`max` and `min` pass NaN over).
            if (la + lb).iter().all(|v| v.is_finite()) {
                bound
            } else {
                f64::NAN
            }
        }
        _ => axis_depth(solid, a, b),
    }
}

/// Smallest signed distance from the segment `a`–`b` to `solid`: the gap when apart, minus the
/// depth of the deepest point when inside. Each solid's signed distance is convex, so along the
/// segment it is a convex function of the parameter: planes at an end, balls and capsules by
/// closest points, boxes by golden-section search on their signed distance.
fn axis_depth(solid: &Solid, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    match solid {
        Solid::HalfSpace { point, outward } => {
            (a - point).dot(outward).min((b - point).dot(outward))
        }
        Solid::Ball { centre, radius } => segments_gap(a, b, centre, centre) - radius,
        Solid::Capsule {
            a: start,
            b: end,
            radius,
        } => segments_gap(a, b, start, end) - radius,
        Solid::Box {
            centre,
            axes,
            half_extents,
        } => {
            let signed = |t: f64| {
                let local = axes.transpose() * (a + (b - a) * t - centre);
                let excess = local.abs() - half_extents;
                let outside = excess.map(|e| e.max(0.0)).norm();
                outside + excess.max().min(0.0)
            };
            let golden = (5.0_f64.sqrt() - 1.0) / 2.0;
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..GOLDEN_SECTION_STEPS {
                let left = hi - golden * (hi - lo);
                let right = lo + golden * (hi - lo);
                if signed(left) <= signed(right) {
                    hi = right;
                } else {
                    lo = left;
                }
            }
            signed(0.0).min(signed(1.0)).min(signed(0.5 * (lo + hi)))
        }
    }
}

/// Angle between unit vectors (degrees) as `atan2(|a × b|, a·b)`: `acos(a·b)` loses half the
/// digits near 0°, where one rounding of the dot product already reads as ~1e-6°.
pub(crate) fn angle_deg(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    libm::atan2(a.cross(b).norm(), a.dot(b)).to_degrees()
}

/// URDF's `rpy` rotation `R_z(yaw) R_y(pitch) R_x(roll)`, its sines and cosines from the `libm`
/// crate (the same bits on every machine, unlike the C library's).
fn rpy_rotation(roll: f64, pitch: f64, yaw: f64) -> Rotation3<f64> {
    let about = |axis: Vector3<f64>, angle| axis_rotation(&Unit::new_unchecked(axis), angle);
    about(Vector3::z(), yaw) * about(Vector3::y(), pitch) * about(Vector3::x(), roll)
}

/// The rotation by `angle` about the unit `axis`: `I + sin θ [a]× + (1 − cos θ) [a]×²`.
fn axis_rotation(axis: &Unit<Vector3<f64>>, angle: f64) -> Rotation3<f64> {
    let (sin, cos) = libm::sincos(angle);
    let skew = axis.cross_matrix();
    Rotation3::from_matrix_unchecked(Matrix3::identity() + skew * sin + skew * skew * (1.0 - cos))
}

/// `value <= bound`; false when either is NaN, so that every check fails closed.
pub(crate) fn within(value: f64, bound: f64) -> bool {
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

/// The joints of `urdf` from `base` to `tip`, base first: followed from `tip` up through each
/// link's parent joint.
fn chain_path<'u>(
    urdf: &'u urdf_rs::Robot,
    base: &str,
    tip: &str,
) -> Result<Vec<&'u urdf_rs::Joint>, ModelError> {
    let mut path = Vec::new();
    let mut link = tip.to_string();
    while link != base {
        let joint = urdf
            .joints
            .iter()
            .find(|j| j.child.link == link)
            .ok_or_else(|| ModelError::Unreachable(link.clone()))?;
        if path.len() == urdf.joints.len() {
            return Err(ModelError::Loop(link));
        }
        path.push(joint);
        link = joint.parent.link.clone();
    }
    path.reverse();
    Ok(path)
}

/// The checker's joint of a URDF joint: its origin transform and, for a revolute or
/// continuous joint, its axis, position range and velocity limit, each verified.
fn reference_joint(joint: &urdf_rs::Joint) -> Result<ReferenceJoint, ModelError> {
    let element = |field: &str| format!("joint '{}' {field}", joint.name);
    finite(
        &element("origin"),
        &[&joint.origin.xyz.0, &joint.origin.rpy.0],
    )?;
    let [x, y, z] = joint.origin.xyz.0;
    let [r, p, yaw] = joint.origin.rpy.0;
    let mut origin = rpy_rotation(r, p, yaw).to_homogeneous();
    origin[(0, 3)] = x;
    origin[(1, 3)] = y;
    origin[(2, 3)] = z;
    let (revolute, lower, upper) = match joint.joint_type {
        urdf_rs::JointType::Revolute => (true, joint.limit.lower, joint.limit.upper),
        urdf_rs::JointType::Continuous => (true, -CONTINUOUS_RANGE, CONTINUOUS_RANGE),
        _ => (false, 0.0, 0.0),
    };
    let axis = Vector3::from(joint.axis.xyz.0);
    if revolute && !(axis.norm().is_finite() && axis.norm() > 1e-9) {
        return Err(ModelError::Value {
            element: element("axis"),
            problem: format!("{:?} is not a direction", joint.axis.xyz.0),
        });
    }
    if revolute && !(lower.is_finite() && upper.is_finite() && lower < upper) {
        return Err(ModelError::Value {
            element: element("limit"),
            problem: format!("[{lower}, {upper}] is not a range of finite numbers"),
        });
    }
    let velocity = joint.limit.velocity;
    if revolute && !(velocity.is_finite() && velocity > 0.0) {
        return Err(ModelError::Value {
            element: element("velocity limit"),
            problem: format!("{velocity} is not a positive number"),
        });
    }
    Ok(ReferenceJoint {
        origin,
        axis: revolute.then(|| Unit::new_normalize(axis)),
        lower,
        upper,
        velocity,
    })
}

/// The capsules of link `name` (number `chain_index` along the chain) in `urdf`, sphere caps
/// merged into their cylinders.
fn link_capsules(
    urdf: &urdf_rs::Robot,
    chain_index: usize,
    name: &str,
) -> Result<Vec<ReferenceCapsule>, ModelError> {
    let link = urdf
        .links
        .iter()
        .find(|l| l.name == name)
        .ok_or_else(|| ModelError::MissingLink(name.to_string()))?;
    let elements = link
        .collision
        .iter()
        .map(|collision| collision_capsule(name, chain_index, collision))
        .collect::<Result<Vec<_>, _>>()?;
    merge_sphere_caps(name, elements)
}

/// The capsule of one collision element of link `name`, and whether it is a cylinder (whose
/// caps may stand as spheres of their own).
fn collision_capsule(
    name: &str,
    chain_index: usize,
    collision: &urdf_rs::Collision,
) -> Result<(ReferenceCapsule, bool), ModelError> {
    let (radius, half, cylinder) = match collision.geometry {
        urdf_rs::Geometry::Capsule { radius, length } => (radius, length / 2.0, false),
        urdf_rs::Geometry::Cylinder { radius, length } => (radius, length / 2.0, true),
        urdf_rs::Geometry::Sphere { radius } => (radius, 0.0, false),
        _ => return Err(ModelError::Geometry(name.to_string())),
    };
    let element = format!("link '{name}' collision");
    finite(
        &element,
        &[&collision.origin.xyz.0, &collision.origin.rpy.0],
    )?;
    if !([radius, half].iter().all(|v| v.is_finite() && *v >= 0.0)) {
        return Err(ModelError::Value {
            element,
            problem: format!("radius {radius} and length {} must be ≥ 0", 2.0 * half),
        });
    }
    let [x, y, z] = collision.origin.xyz.0;
    let [r, p, yaw] = collision.origin.rpy.0;
    let rotation = rpy_rotation(r, p, yaw);
    let centre = Vector3::new(x, y, z);
    let axis = rotation * Vector3::z() * half;
    let capsule = ReferenceCapsule {
        link: name.to_string(),
        chain_index,
        start: centre - axis,
        end: centre + axis,
        radius,
    };
    Ok((capsule, cylinder))
}

/// The link that carries the tool: the last link with a capsule, if it moves rigidly with the
/// last revolute joint.
fn tool_link(joints: &[ReferenceJoint], capsules: &[ReferenceCapsule]) -> Option<usize> {
    // Link i + 1 is the child of joint i: the links from the last revolute joint's child on
    // move rigidly with the last joint.
    let last_moving_link = joints
        .iter()
        .rposition(|j| j.axis.is_some())
        .map_or(0, |i| i + 1);
    capsules
        .iter()
        .map(|c| c.chain_index)
        .max()
        .filter(|&link| link >= last_moving_link)
}
/// Fails, naming `element`, unless every number of `groups` is finite.
fn finite(element: &str, groups: &[&[f64; 3]]) -> Result<(), ModelError> {
    if groups.iter().all(|g| g.iter().all(|v| v.is_finite())) {
        return Ok(());
    }
    Err(ModelError::Value {
        element: element.to_string(),
        problem: format!("{groups:?} must be finite numbers"),
    })
}

/// The link pairs of the `disable_collisions` elements of an SRDF document.
fn disabled_collisions(text: &str) -> Result<Vec<(String, String)>, String> {
    let document = roxmltree::Document::parse(text).map_err(|e| e.to_string())?;
    let mut pairs = Vec::new();
    for node in document.descendants() {
        if node.tag_name().name() != "disable_collisions" {
            continue;
        }
        match (node.attribute("link1"), node.attribute("link2")) {
            (Some(a), Some(b)) => pairs.push((a.to_string(), b.to_string())),
            _ => return Err("a disable_collisions element lacks link1 or link2".into()),
        }
    }
    Ok(pairs)
}

/// Distance (m) within which a sphere sits on a cylinder end as its cap.
const CAP_TOLERANCE: f64 = 1e-6;

/// The capsules of one link's collision elements `(element, is a cylinder)`: a cylinder and the
/// spheres of its radius centred on its two ends are one capsule (the standard way to write a
/// capsule in URDF); a cylinder missing a cap is refused.
fn merge_sphere_caps(
    link: &str,
    elements: Vec<(ReferenceCapsule, bool)>,
) -> Result<Vec<ReferenceCapsule>, ModelError> {
    let on_end = |sphere: &ReferenceCapsule, end: &Vector3<f64>, radius: f64| {
        sphere.start == sphere.end
            && (sphere.start - end).norm() <= CAP_TOLERANCE
            && (sphere.radius - radius).abs() <= CAP_TOLERANCE
    };
    let cylinders: Vec<&ReferenceCapsule> = elements
        .iter()
        .filter(|(_, c)| *c)
        .map(|(e, _)| e)
        .collect();
    let spheres: Vec<&ReferenceCapsule> = elements
        .iter()
        .filter(|(_, c)| !*c)
        .map(|(e, _)| e)
        .collect();
    for cylinder in &cylinders {
        for end in [&cylinder.start, &cylinder.end] {
            if !spheres.iter().any(|s| on_end(s, end, cylinder.radius)) {
                return Err(ModelError::UncappedCylinder(link.to_string()));
            }
        }
    }
    let is_cap = |element: &ReferenceCapsule| {
        cylinders
            .iter()
            .any(|c| on_end(element, &c.start, c.radius) || on_end(element, &c.end, c.radius))
    };
    let keep: Vec<bool> = elements
        .iter()
        .map(|(element, cylinder)| *cylinder || !is_cap(element))
        .collect();
    Ok(elements
        .into_iter()
        .zip(keep)
        .filter_map(|((element, _), keep)| keep.then_some(element))
        .collect())
}

#[cfg(test)]
mod tests {
    //! The pruned measures against the exhaustive loops they replace, bit for bit, on the
    //! shipped arms in random configurations among obstacles placed on and around the arm.

    use super::*;
    use crate::record::{Obstacle, Surface};

    /// The shipped arms' checkers.
    fn arms() -> Vec<ReferenceModel> {
        let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots");
        [
            ("fr3_pen.urdf", "link0"),
            ("iiwa14_pen.urdf", "iiwa_link_0"),
            ("ur5e_pen.urdf", "base_link"),
        ]
        .iter()
        .map(|(file, base)| {
            ReferenceModel::from_urdf_file(&data.join(file), base, "pen_tip").expect("arm")
        })
        .collect()
    }

    /// A small deterministic stream of numbers in [0, 1) (xorshift64*).
    struct Stream(u64);

    impl Stream {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        }

        fn between(&mut self, low: f64, high: f64) -> f64 {
            low + (high - low) * self.next()
        }

        /// A rotation about a random axis by up to half a turn (the checker's own
        /// construction, on `libm`).
        fn rotation(&mut self) -> Rotation3<f64> {
            let axis = Unit::new_normalize(self.vector(1.0));
            axis_rotation(&axis, self.between(-3.0, 3.0))
        }

        fn vector(&mut self, half: f64) -> Vector3<f64> {
            Vector3::new(
                self.between(-half, half),
                self.between(-half, half),
                self.between(-half, half),
            )
        }
    }

    /// A configuration within the limits.
    fn configuration(model: &ReferenceModel, stream: &mut Stream) -> Joints {
        let mut q = Joints::zeros();
        for (i, (lo, hi)) in model.limits().iter().enumerate() {
            q[i] = stream.between(*lo, *hi);
        }
        q
    }

    #[test]
    fn the_tcp_frame_holds_the_tcp_pose_and_a_rotation() {
        let mut stream = Stream(0x5EED_F4A3);
        for model in arms() {
            for _ in 0..50 {
                let q = configuration(&model, &mut stream);
                let (tcp, axis) = model.tcp_pose(&q);
                let (position, rotation) = model.tcp_frame(&q);
                assert_eq!(position, tcp);
                assert_eq!(rotation.column(2).into_owned(), axis);
                assert!((rotation.transpose() * rotation - Matrix3::identity()).amax() < 1e-12);
                assert!((rotation.determinant() - 1.0).abs() < 1e-12);
            }
        }
    }

    /// The exhaustive loop `min_clearance` ran before the pruning.
    fn exhaustive_clearance(model: &ReferenceModel, q: &Joints) -> (f64, String, String) {
        let frames = model.link_frames(q);
        let world = |c: &ReferenceCapsule, v: &Vector3<f64>| {
            (frames[c.chain_index] * Vector4::new(v.x, v.y, v.z, 1.0)).xyz()
        };
        let mut best = (f64::INFINITY, String::new(), String::new());
        for (i, a) in model.capsules.iter().enumerate() {
            for b in &model.capsules[i + 1..] {
                if !model.checked(a, b) {
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

    /// The exhaustive loop `scene_margin` ran before the pruning.
    fn exhaustive_margin(
        model: &ReferenceModel,
        q: &Joints,
        line: &Line,
        bounds: &Bounds,
    ) -> Option<(f64, String, String)> {
        let frames = model.link_frames(q);
        let surface = bounds.work_surface.map(|surface| surface.solid(line));
        let surface = surface
            .as_ref()
            .map(|solid| (solid, 0.0, WORK_SURFACE, true));
        let obstacles = bounds
            .obstacles
            .iter()
            .map(|o| (&o.solid, o.clearance_m, o.name.as_str(), o.tool_may_touch));
        let mut worst: Option<(f64, String, String)> = None;
        for (solid, clearance, name, tool_may_touch) in surface.into_iter().chain(obstacles) {
            for capsule in &model.capsules {
                if tool_may_touch && Some(capsule.chain_index) == model.tool_link {
                    continue;
                }
                let frame = &frames[capsule.chain_index];
                let world = |v: &Vector3<f64>| (frame * Vector4::new(v.x, v.y, v.z, 1.0)).xyz();
                let margin = axis_depth(solid, &world(&capsule.start), &world(&capsule.end))
                    - capsule.radius
                    - clearance;
                if worst
                    .as_ref()
                    .is_none_or(|w| margin.is_nan() || margin < w.0)
                {
                    worst = Some((margin, capsule.link.clone(), name.to_string()));
                }
            }
        }
        worst
    }

    /// Obstacles of every kind near the arm in `q`: centred on points of its capsules (so
    /// that some overlap them) or a little off them.
    fn obstacles_around(model: &ReferenceModel, q: &Joints, stream: &mut Stream) -> Vec<Obstacle> {
        let mut placement = model.placement();
        model.place(q, &mut placement);
        let mut obstacles = Vec::new();
        for k in 0..6 {
            let c = (stream.next() * placement.ends.len() as f64) as usize;
            let [a, b] = placement.ends[c];
            let on_arm = a + (b - a) * stream.next() + stream.vector(0.12);
            let direction = stream.vector(1.0).normalize();
            let solid = match k % 4 {
                0 => Solid::Box {
                    centre: on_arm,
                    axes: *stream.rotation().matrix(),
                    half_extents: Vector3::new(
                        stream.between(0.005, 0.2),
                        stream.between(0.005, 0.2),
                        stream.between(0.005, 0.2),
                    ),
                },
                1 => Solid::Ball {
                    centre: on_arm,
                    radius: stream.between(0.0, 0.08),
                },
                2 => Solid::Capsule {
                    a: on_arm,
                    b: on_arm + direction * 0.2,
                    radius: stream.between(0.0, 0.05),
                },
                _ => Solid::HalfSpace {
                    point: on_arm,
                    outward: direction,
                },
            };
            obstacles.push(Obstacle {
                name: format!("obstacle {k}"),
                solid,
                clearance_m: stream.between(0.0, 0.02),
                tool_may_touch: stream.next() < 0.5,
            });
        }
        obstacles
    }

    #[test]
    fn pruned_clearances_and_margins_are_the_exhaustive_loops_bit_for_bit() {
        let mut stream = Stream(0x9E37_79B9_7F4A_7C15);
        let (mut colliding, mut touching) = (0, 0);
        for model in arms() {
            for _ in 0..400 {
                let q = configuration(&model, &mut stream);
                let clearance = model.min_clearance(&q);
                assert_eq!(clearance, exhaustive_clearance(&model, &q), "q = {q}");
                colliding += usize::from(clearance.0 < 0.0);
                let (tcp, axis) = model.tcp_pose(&q);
                let line = Line::straight(tcp, axis.cross(&Vector3::x()).normalize(), axis);
                let bounds = Bounds {
                    line_tolerance_m: 1.0,
                    theta_max_deg: 180.0,
                    collision_margin_m: 0.0,
                    velocity_limit_fraction: None,
                    work_surface: Some(if stream.next() < 0.5 {
                        Surface::HalfSpace
                    } else {
                        Surface::Plate {
                            half_width_m: 0.1,
                            behind_m: 0.05,
                            ahead_m: 0.3,
                            thickness_m: 0.05,
                        }
                    }),
                    obstacles: obstacles_around(&model, &q, &mut stream),
                };
                let margin = model.scene_margin(&q, &line, &bounds);
                assert_eq!(
                    margin,
                    exhaustive_margin(&model, &q, &line, &bounds),
                    "q = {q}"
                );
                let mut placement = model.placement();
                model.place(&q, &mut placement);
                let scene = Scene::new(&line, &bounds);
                let worst = margin.expect("a scene").0;
                touching += usize::from(worst < 0.0);
                // Clear by the bounds only where the margins are.
                if model.scene_clear(&placement, &scene) {
                    assert!(worst >= -1e-12, "clear by the bounds, yet {worst} m");
                }
                // Without obstacles: nothing to keep away from.
                let empty = Bounds {
                    work_surface: None,
                    obstacles: Vec::new(),
                    ..bounds
                };
                assert_eq!(model.scene_margin(&q, &line, &empty), None);
            }
        }
        // The configurations cover both sides of every measure.
        assert!(colliding > 20 && touching > 200, "{colliding} {touching}");
    }

    #[test]
    fn ties_go_to_the_first_pair_and_a_configuration_not_finite_is_measured_in_full() {
        let model = &arms()[0];
        // A configuration that is not a number: every measure NaN, as the exhaustive loops
        // give them (no clearance below infinity; the last NaN margin).
        let q = Joints::from_element(f64::NAN);
        assert_eq!(model.min_clearance(&q), exhaustive_clearance(model, &q));
        let line = Line::straight(Vector3::zeros(), Vector3::x(), Vector3::z());
        let bounds = Bounds {
            line_tolerance_m: 1.0,
            theta_max_deg: 180.0,
            collision_margin_m: 0.0,
            velocity_limit_fraction: None,
            work_surface: Some(Surface::HalfSpace),
            obstacles: Vec::new(),
        };
        let margin = model.scene_margin(&q, &line, &bounds).expect("a surface");
        let exhaustive = exhaustive_margin(model, &q, &line, &bounds).expect("a surface");
        assert!(margin.0.is_nan() && exhaustive.0.is_nan());
        assert_eq!((margin.1, margin.2), (exhaustive.1, exhaustive.2));
        // Two identical balls: the same smallest margin twice, the first one named.
        let mut stream = Stream(7);
        let q = configuration(model, &mut stream);
        let ball = |name: &str| Obstacle {
            name: name.to_string(),
            solid: Solid::Ball {
                centre: Vector3::new(0.3, 0.1, 0.4),
                radius: 0.05,
            },
            clearance_m: 0.0,
            tool_may_touch: false,
        };
        let bounds = Bounds {
            work_surface: None,
            obstacles: vec![ball("first"), ball("second")],
            ..bounds
        };
        let margin = model.scene_margin(&q, &line, &bounds).expect("balls");
        assert_eq!(margin.2, "first");
        assert_eq!(Some(margin), exhaustive_margin(model, &q, &line, &bounds));
    }

    #[test]
    fn a_box_bound_is_below_the_box_depth_of_every_segment() {
        let mut stream = Stream(0xDEAD_BEEF);
        for _ in 0..20_000 {
            let solid = Solid::Box {
                centre: stream.vector(0.2),
                axes: *stream.rotation().matrix(),
                half_extents: Vector3::new(
                    stream.between(0.001, 0.3),
                    stream.between(0.001, 0.3),
                    stream.between(0.001, 0.3),
                ),
            };
            let a = stream.vector(0.6);
            let b = if stream.next() < 0.1 {
                a
            } else {
                a + stream.vector(0.4)
            };
            let bound = depth_lower_bound(&solid, &a, &b);
            let depth = axis_depth(&solid, &a, &b);
            assert!(bound <= depth + 1e-12, "{bound} > {depth}");
        }
        let solid = Solid::Box {
            centre: Vector3::zeros(),
            axes: Matrix3::identity(),
            half_extents: Vector3::new(1.0, 1.0, 1.0),
        };
        let nan = Vector3::new(f64::NAN, 0.0, 0.0);
        assert!(depth_lower_bound(&solid, &nan, &Vector3::zeros()).is_nan());
    }
}
