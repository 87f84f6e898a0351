//! The cell around the arm: obstacles (half-spaces, boxes, spheres, capsules in the base frame,
//! each with the clearance it asks for) and the clearance of the arm's capsules from them.

use nalgebra::{Isometry3, Rotation3};
use serde::{Deserialize, Serialize};

use crate::capsule::segment_distance;
use crate::fk::Kinematics;
use crate::robot::Robot;
use crate::rotation::{Transform, rotation_from_rpy, rpy_of};
use crate::vectors::Vec3;

/// A solid the arm keeps clear of, in the base frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Everything behind a plane: the points `x` with `(x − point)·normal < 0`; the unit
    /// `normal` points out of the solid, into free space (a floor at height 0 has `point`
    /// `(0, 0, 0)` and `normal` `(0, 0, 1)`).
    HalfSpace {
        /// A point of the plane (m).
        point: Vec3,
        /// Unit normal pointing into free space.
        normal: Vec3,
    },
    /// A box: `centre + rotation·x` for `|x_i| ≤ half_extents_i`.
    Cuboid {
        /// Centre (m).
        centre: Vec3,
        /// Orientation of the box's axes in the base frame.
        rotation: Rotation3<f64>,
        /// Half the edge lengths along the box's own axes (m).
        half_extents: Vec3,
    },
    /// A ball.
    Sphere {
        /// Centre (m).
        centre: Vec3,
        /// Radius (m).
        radius: f64,
    },
    /// The segment `start`–`end` swept by `radius`.
    Capsule {
        /// First end of the axis (m).
        start: Vec3,
        /// Second end of the axis (m).
        end: Vec3,
        /// Radius (m).
        radius: f64,
    },
}

impl Shape {
    /// The solid moved rigidly by `motion`.
    pub fn moved(&self, motion: &Isometry3<f64>) -> Self {
        let point = |p: &Vec3| (motion * nalgebra::Point3::from(*p)).coords;
        match self {
            Self::HalfSpace { point: p, normal } => Self::HalfSpace {
                point: point(p),
                normal: motion.rotation * normal,
            },
            Self::Cuboid {
                centre,
                rotation,
                half_extents,
            } => Self::Cuboid {
                centre: point(centre),
                rotation: motion.rotation.to_rotation_matrix() * rotation,
                half_extents: *half_extents,
            },
            Self::Sphere { centre, radius } => Self::Sphere {
                centre: point(centre),
                radius: *radius,
            },
            Self::Capsule { start, end, radius } => Self::Capsule {
                start: point(start),
                end: point(end),
                radius: *radius,
            },
        }
    }

    /// The work surface of a task (SPEC §9): the plane through `p0` with normal `n`, the
    /// material on the side `(x − p0)·n > 0` (`n` points from the tool into the surface).
    pub fn work_surface(p0: &Vec3, n: &Vec3) -> Self {
        Self::HalfSpace {
            point: *p0,
            normal: -n,
        }
    }

    /// The work plate of a task: the box [`Plate`] describes, its top face in the plane through
    /// `p0` with normal `n`, its length along the unit direction `d`, its material on the side
    /// `(x − p0)·n > 0`.
    pub fn work_plate(p0: &Vec3, d: &Vec3, n: &Vec3, plate: &Plate) -> Self {
        let across = n.cross(d);
        let centre =
            p0 + d * (0.5 * (plate.ahead_m - plate.behind_m)) + n * (0.5 * plate.thickness_m);
        Self::Cuboid {
            centre,
            rotation: Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[
                *d, across, *n,
            ])),
            half_extents: Vec3::new(
                0.5 * (plate.ahead_m + plate.behind_m),
                plate.half_width_m,
                0.5 * plate.thickness_m,
            ),
        }
    }

    /// A lower bound (m) on [`Shape::segment_distance`] that costs a few dot products: for a box
    /// the largest gap between the segment and one of the six slabs' half-spaces holding it
    /// (the box lies inside each), else the distance itself.
    pub fn segment_distance_lower_bound(&self, a: &Vec3, b: &Vec3) -> f64 {
        match self {
            Self::Cuboid {
                centre,
                rotation,
                half_extents,
            } => {
                let la = rotation.inverse_transform_vector(&(a - centre));
                let lb = rotation.inverse_transform_vector(&(b - centre));
                (0..3)
                    .map(|i| {
                        let above = la[i].min(lb[i]) - half_extents[i];
                        let below = -la[i].max(lb[i]) - half_extents[i];
                        above.max(below)
                    })
                    .fold(f64::NEG_INFINITY, f64::max)
            }
            _ => self.segment_distance(a, b),
        }
    }

    /// Signed distance (m) between the segment `a`–`b` and the solid: the gap between them when
    /// apart, minus the depth of the segment's deepest point when it enters the solid.
    pub fn segment_distance(&self, a: &Vec3, b: &Vec3) -> f64 {
        match self {
            Self::HalfSpace { point, normal } => {
                (a - point).dot(normal).min((b - point).dot(normal))
            }
            Self::Cuboid {
                centre,
                rotation,
                half_extents,
            } => {
                let local = |p: &Vec3| rotation.inverse_transform_vector(&(p - centre));
                cuboid_segment_distance(&local(a), &local(b), half_extents)
            }
            Self::Sphere { centre, radius } => segment_distance(a, b, centre, centre) - radius,
            Self::Capsule { start, end, radius } => segment_distance(a, b, start, end) - radius,
        }
    }
}

/// The first `s ≥ 0` at which the ray `origin + s·direction` (unit `direction`) comes
/// within `inflation` of the capsule `start`–`end` of radius `radius` (the capsule grown by
/// `inflation`): `Some(0)` when `origin` is already that near, `None` when the ray never
/// is. Closed form: the first root over the two end spheres and the cylinder between them.
pub fn capsule_ray_entry(
    start: &Vec3,
    end: &Vec3,
    radius: f64,
    inflation: f64,
    origin: &Vec3,
    direction: &Vec3,
) -> Option<f64> {
    let r = radius + inflation;
    if segment_distance(origin, origin, start, end) <= r {
        return Some(0.0);
    }
    // Smallest root s ≥ 0 of a·s² + 2b·s + c = 0 (c > 0: the origin is outside).
    let first_root = |a: f64, b: f64, c: f64| {
        let discriminant = b * b - a * c;
        (a > 0.0 && discriminant >= 0.0)
            .then(|| (-b - discriminant.sqrt()) / a)
            .filter(|s| *s >= 0.0)
    };
    let sphere = |centre: &Vec3| {
        let w = origin - centre;
        first_root(1.0, direction.dot(&w), w.norm_squared() - r * r)
    };
    let axis = end - start;
    let length = axis.norm();
    let cylinder = (length > 0.0).then(|| {
        let v = axis / length;
        let w = origin - start;
        let u_across = direction - v * direction.dot(&v);
        let w_across = w - v * w.dot(&v);
        first_root(
            u_across.norm_squared(),
            u_across.dot(&w_across),
            w_across.norm_squared() - r * r,
        )
        .filter(|s| (0.0..=length).contains(&(w + direction * *s).dot(&v)))
    });
    [sphere(start), sphere(end), cylinder.flatten()]
        .into_iter()
        .flatten()
        .reduce(f64::min)
}

/// Signed distance between the segment `a`–`b` and the box `|x_i| ≤ h_i` (all in the box's
/// frame). Inside, the depth `min_i (h_i − |x_i|)` is the minimum of six functions linear along
/// the segment, so its largest value lies at an end or where two of them cross; outside, the
/// nearest box point of a nearest pair lies on an edge unless a segment end is nearest.
fn cuboid_segment_distance(a: &Vec3, b: &Vec3, h: &Vec3) -> f64 {
    let u = b - a;
    // depth(t) = min_k (offset_k + slope_k·t), t ∈ [0, 1].
    let mut lines = [(0.0, 0.0); 6];
    for i in 0..3 {
        lines[2 * i] = (h[i] - a[i], -u[i]);
        lines[2 * i + 1] = (h[i] + a[i], u[i]);
    }
    let depth = |t: f64| {
        lines
            .iter()
            .map(|(offset, slope)| offset + slope * t)
            .fold(f64::INFINITY, f64::min)
    };
    let mut deepest = depth(0.0).max(depth(1.0));
    for (j, (offset_j, slope_j)) in lines.iter().enumerate() {
        for (offset_k, slope_k) in &lines[j + 1..] {
            if slope_j != slope_k {
                let t = (offset_k - offset_j) / (slope_j - slope_k);
                if t > 0.0 && t < 1.0 {
                    deepest = deepest.max(depth(t));
                }
            }
        }
    }
    if deepest > 0.0 {
        return -deepest;
    }
    let outside = |p: &Vec3| p.abs().zip_map(h, |v, half| (v - half).max(0.0)).norm();
    let mut gap = outside(a).min(outside(b));
    for axis in 0..3 {
        let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
        for (sj, sk) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
            let mut from = Vec3::zeros();
            from[j] = sj * h[j];
            from[k] = sk * h[k];
            let mut to = from;
            from[axis] = -h[axis];
            to[axis] = h[axis];
            gap = gap.min(segment_distance(a, b, &from, &to));
        }
    }
    gap
}

/// The part a task's line is drawn on, which every capsule of the arm but the tool's keeps off
/// (SPEC §9 with a finite part): JSON `"plate"` (the default [`Plate`]), `{"plate": {...}}`
/// (its fields, unset ones at their defaults), `"half_space"` (the whole half-space behind the
/// plane through `p0` with normal `n`; `true` reads as this, as files written before plates
/// existed mean it) or `"off"` (`false`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "WorkSurfaceFile", into = "WorkSurfaceFile")]
pub enum WorkSurface {
    /// No work surface: the paper's protocol.
    #[default]
    Off,
    /// A finite plate under the line.
    Plate(Plate),
    /// The infinite half-space behind the plane through `p0` with normal `n`.
    HalfSpace,
}

impl WorkSurface {
    /// The default plate.
    pub fn plate() -> Self {
        Self::Plate(Plate::default())
    }

    /// Whether there is no work surface.
    pub fn is_off(&self) -> bool {
        *self == Self::Off
    }

    /// The solid of the task `(p0, d, n)`'s work surface, if any.
    pub fn shape(&self, p0: &Vec3, d: &Vec3, n: &Vec3) -> Option<Shape> {
        match self {
            Self::Off => None,
            Self::Plate(plate) => Some(Shape::work_plate(p0, d, n, plate)),
            Self::HalfSpace => Some(Shape::work_surface(p0, n)),
        }
    }
}

impl std::fmt::Display for WorkSurface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Off => f.write_str("off"),
            Self::HalfSpace => f.write_str("half-space"),
            Self::Plate(p) => write!(
                f,
                "plate {:.2} m wide, {:.2} m behind p0 to {:.2} m ahead, {:.3} m thick",
                2.0 * p.half_width_m,
                p.behind_m,
                p.ahead_m,
                p.thickness_m
            ),
        }
    }
}

impl std::str::FromStr for WorkSurface {
    type Err = String;

    /// `plate`, `half-space` (or `half_space`) or `off`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "plate" => Ok(Self::plate()),
            "half-space" | "half_space" => Ok(Self::HalfSpace),
            "off" => Ok(Self::Off),
            other => Err(format!(
                "unknown work surface '{other}': give plate (a finite part under the line), \
                 half-space (the whole plane) or off"
            )),
        }
    }
}

/// A work plate's extent around the task line, in the line's frame: from `behind_m` before
/// `p0` to `ahead_m` beyond it along `d`, `half_width_m` to each side, `thickness_m` deep below
/// the plane through `p0` with normal `n`. The defaults (0.2 m wide, 0.05 m behind, 2 m ahead,
/// 0.05 m thick) make a strip longer than any line a 7-DoF arm of a metre's reach can draw, so
/// the plate never ends a line, and narrow enough that an arm beside it keeps clear of it. A
/// task shapes it to itself (`emg_control::Task::work_surface`): under a path it covers the path
/// with these margins, along a line it ends short of the arm's base column.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Plate {
    /// Half the plate's width across the line (m).
    pub half_width_m: f64,
    /// How far the plate reaches behind `p0`, against `d` (m).
    pub behind_m: f64,
    /// How far the plate reaches beyond `p0`, along `d` (m).
    pub ahead_m: f64,
    /// The plate's thickness below the surface (m).
    pub thickness_m: f64,
}

impl Default for Plate {
    fn default() -> Self {
        Self {
            half_width_m: 0.1,
            behind_m: 0.05,
            ahead_m: 2.0,
            thickness_m: 0.05,
        }
    }
}

/// The serialised form of a [`WorkSurface`].
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged)]
enum WorkSurfaceFile {
    Flag(bool),
    Name(String),
    Plate { plate: Plate },
}

impl TryFrom<WorkSurfaceFile> for WorkSurface {
    type Error = String;

    fn try_from(file: WorkSurfaceFile) -> Result<Self, String> {
        let surface = match file {
            WorkSurfaceFile::Flag(true) => Self::HalfSpace,
            WorkSurfaceFile::Flag(false) => Self::Off,
            WorkSurfaceFile::Name(name) => name.parse()?,
            WorkSurfaceFile::Plate { plate } => Self::Plate(plate),
        };
        if let Self::Plate(plate) = &surface {
            let sizes = [
                ("plate.half_width_m", plate.half_width_m),
                ("plate.behind_m", plate.behind_m),
                ("plate.ahead_m", plate.ahead_m),
                ("plate.thickness_m", plate.thickness_m),
            ];
            for (field, value) in sizes {
                if !(value.is_finite() && value >= 0.0) {
                    return Err(format!(
                        "work_surface.{field} must be a finite length ≥ 0, got {value}"
                    ));
                }
            }
        }
        Ok(surface)
    }
}

impl From<WorkSurface> for WorkSurfaceFile {
    fn from(surface: WorkSurface) -> Self {
        match surface {
            WorkSurface::Off => Self::Name("off".to_string()),
            WorkSurface::HalfSpace => Self::Name("half_space".to_string()),
            WorkSurface::Plate(plate) => Self::Plate { plate },
        }
    }
}

/// One obstacle of the cell: a named solid and the clearance the arm keeps from it.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// Name used in messages (the file's `name`, else `obstacles[i]`).
    pub name: String,
    /// The solid.
    pub shape: Shape,
    /// Smallest surface distance (m) every capsule of the arm keeps from it.
    pub clearance_m: f64,
    /// Whether the tool's capsules may touch it: the part the tool works on (a pen draws on
    /// it, a torch welds it), which the rest of the arm keeps clear of. Off by default.
    pub tool_may_touch: bool,
}

impl Obstacle {
    /// Which capsules of the arm the obstacle is checked against.
    pub fn tool_contact(&self) -> ToolContact {
        if self.tool_may_touch {
            ToolContact::Allowed
        } else {
            ToolContact::Forbidden
        }
    }
}

/// The obstacles of a cell, read from a scene file (JSON):
///
/// ```json
/// {"obstacles": [
///   {"name": "table", "half_space": {"point": [0, 0, 0], "normal": [0, 0, 1]}},
///   {"name": "fixture", "clearance_m": 0.01,
///    "box": {"centre": [0.5, 0.3, 0.1], "size": [0.2, 0.1, 0.2], "rpy": [0, 0, 0.3]}},
///   {"sphere": {"centre": [0.4, -0.4, 0.5], "radius": 0.05}},
///   {"capsule": {"start": [0.3, 0.5, 0], "end": [0.3, 0.5, 0.8], "radius": 0.04}}
/// ]}
/// ```
///
/// Positions are in the base frame (m); a half-space's `normal` points out of the solid; a box
/// has its full edge lengths `size` and the URDF roll–pitch–yaw `rpy` of its axes (default 0);
/// `clearance_m` defaults to 0 (not touching); `"tool_may_touch": true` marks the part the tool
/// works on, which only the rest of the arm keeps clear of.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SceneFile", into = "SceneFile")]
pub struct Scene {
    /// The obstacles, each checked against every capsule of the arm.
    pub obstacles: Vec<Obstacle>,
}

impl Scene {
    /// Whether the scene holds no obstacle.
    pub fn is_empty(&self) -> bool {
        self.obstacles.is_empty()
    }

    /// The scene with every obstacle moved rigidly by `motion`.
    pub fn moved(&self, motion: &Isometry3<f64>) -> Self {
        Self {
            obstacles: self
                .obstacles
                .iter()
                .map(|obstacle| Obstacle {
                    shape: obstacle.shape.moved(motion),
                    ..obstacle.clone()
                })
                .collect(),
        }
    }
}

/// Which capsules of the arm an obstacle may touch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolContact {
    /// The tool's capsules ([`Robot::tool_capsules`]) are not checked: the work surface, which
    /// the pen touches by design.
    Allowed,
    /// Every capsule is checked.
    Forbidden,
}

/// A capsule of the arm closer to an obstacle than its clearance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactHit {
    /// Index into [`Robot::capsules`].
    pub capsule: usize,
    /// Surface distance (m) between the capsule and the solid, negative when they overlap.
    pub clearance: f64,
}

impl Robot {
    /// The first capsule (base to tip) whose surface distance from `shape` is below `clearance`
    /// (m), skipping the tool's capsules when `tool` allows them to touch.
    pub fn first_contact(
        &self,
        kin: &Kinematics,
        shape: &Shape,
        clearance: f64,
        tool: ToolContact,
    ) -> Option<ContactHit> {
        let checked = match tool {
            ToolContact::Allowed => 0..self.tool_capsules().start,
            ToolContact::Forbidden => 0..self.capsules.len(),
        };
        checked.into_iter().find_map(|index| {
            let capsule = &self.capsules[index];
            let start = kin.segment_point(capsule.segment, &capsule.start);
            let end = kin.segment_point(capsule.segment, &capsule.end);
            if shape.segment_distance_lower_bound(&start, &end) - capsule.radius >= clearance {
                return None;
            }
            let distance = shape.segment_distance(&start, &end) - capsule.radius;
            // NaN counts as a contact.
            (distance.is_nan() || distance < clearance).then_some(ContactHit {
                capsule: index,
                clearance: distance,
            })
        })
    }
}

/// The serialised form of a [`Scene`].
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    /// A rigid motion applied to every obstacle as it is read (not written: a scene writes its
    /// obstacles where they are).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    transform: Option<Transform>,
    obstacles: Vec<ObstacleFile>,
}

impl TryFrom<SceneFile> for Scene {
    type Error = ObstacleError;

    fn try_from(file: SceneFile) -> Result<Self, ObstacleError> {
        let obstacles = file
            .obstacles
            .into_iter()
            .enumerate()
            .map(|(index, obstacle)| obstacle.into_obstacle(index))
            .collect::<Result<_, _>>()?;
        let scene = Self { obstacles };
        // JSON numbers are finite, so a transform read is one.
        Ok(match file.transform {
            Some(transform) => scene.moved(&transform.isometry()),
            None => scene,
        })
    }
}

impl From<Scene> for SceneFile {
    fn from(scene: Scene) -> Self {
        Self {
            transform: None,
            obstacles: scene
                .obstacles
                .into_iter()
                .map(ObstacleFile::from)
                .collect(),
        }
    }
}

/// The serialised form of an [`Obstacle`]: a name, a clearance and exactly one shape.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ObstacleFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    name: Option<String>,
    #[serde(default)]
    clearance_m: f64,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    tool_may_touch: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    half_space: Option<HalfSpaceFile>,
    #[serde(default, rename = "box", skip_serializing_if = "Option::is_none")]
    cuboid: Option<BoxFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    sphere: Option<SphereFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    capsule: Option<CapsuleFile>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct HalfSpaceFile {
    point: [f64; 3],
    normal: [f64; 3],
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BoxFile {
    centre: [f64; 3],
    size: [f64; 3],
    #[serde(default)]
    rpy: [f64; 3],
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereFile {
    centre: [f64; 3],
    radius: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CapsuleFile {
    start: [f64; 3],
    end: [f64; 3],
    radius: f64,
}

/// An obstacle of a scene file that cannot be used: names the obstacle, the field and what is
/// wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{obstacle}: {field} {problem}")]
pub struct ObstacleError {
    /// Where the obstacle is, with its name when it has one: `obstacles[2] ('fixture')`.
    pub obstacle: String,
    /// The field, e.g. `box.size`.
    pub field: &'static str,
    /// What is wrong with it.
    pub problem: String,
}

impl ObstacleFile {
    /// The obstacle at `index` of its file, checked: finite positions, one shape, a direction as
    /// a half-space's normal, sizes and clearance ≥ 0. Unnamed, it is called `obstacles[index]`.
    fn into_obstacle(self, index: usize) -> Result<Obstacle, ObstacleError> {
        let file = self;
        let place = format!("obstacles[{index}]");
        let obstacle = match &file.name {
            Some(name) => format!("{place} ('{name}')"),
            None => place.clone(),
        };
        let name = file.name.clone().unwrap_or(place);
        let error = |field: &'static str, problem: String| ObstacleError {
            obstacle: obstacle.clone(),
            field,
            problem,
        };
        let finite = |field: &'static str, v: [f64; 3]| {
            if v.iter().all(|x| x.is_finite()) {
                Ok(Vec3::from(v))
            } else {
                Err(error(
                    field,
                    format!("must be three finite numbers, got {v:?}"),
                ))
            }
        };
        let size = |field: &'static str, value: f64| {
            if value.is_finite() && value >= 0.0 {
                Ok(value)
            } else {
                Err(error(field, format!("must be a number ≥ 0, got {value}")))
            }
        };
        let clearance_m = size("clearance_m", file.clearance_m)?;
        let given = [
            file.half_space.is_some(),
            file.cuboid.is_some(),
            file.sphere.is_some(),
            file.capsule.is_some(),
        ];
        if given.iter().filter(|g| **g).count() != 1 {
            return Err(error(
                "shape",
                "must be exactly one of 'half_space', 'box', 'sphere' and 'capsule'".into(),
            ));
        }
        let shape = if let Some(plane) = file.half_space {
            let normal = finite("half_space.normal", plane.normal)?;
            if normal.norm() <= 1e-9 {
                return Err(error(
                    "half_space.normal",
                    format!("must be a direction, got {:?}", plane.normal),
                ));
            }
            Shape::HalfSpace {
                point: finite("half_space.point", plane.point)?,
                normal: normal.normalize(),
            }
        } else if let Some(cuboid) = file.cuboid {
            let edges = finite("box.size", cuboid.size)?;
            if edges.iter().any(|e| *e < 0.0) {
                return Err(error(
                    "box.size",
                    format!("must be three lengths ≥ 0, got {:?}", cuboid.size),
                ));
            }
            let [roll, pitch, yaw] = finite("box.rpy", cuboid.rpy)?.into();
            Shape::Cuboid {
                centre: finite("box.centre", cuboid.centre)?,
                rotation: rotation_from_rpy(roll, pitch, yaw),
                half_extents: edges * 0.5,
            }
        } else if let Some(sphere) = file.sphere {
            Shape::Sphere {
                centre: finite("sphere.centre", sphere.centre)?,
                radius: size("sphere.radius", sphere.radius)?,
            }
        } else if let Some(capsule) = file.capsule {
            Shape::Capsule {
                start: finite("capsule.start", capsule.start)?,
                end: finite("capsule.end", capsule.end)?,
                radius: size("capsule.radius", capsule.radius)?,
            }
        } else {
            unreachable!("exactly one shape is given")
        };
        Ok(Obstacle {
            name,
            shape,
            clearance_m,
            tool_may_touch: file.tool_may_touch,
        })
    }
}

impl From<Obstacle> for ObstacleFile {
    fn from(obstacle: Obstacle) -> Self {
        let array = |v: &Vec3| [v.x, v.y, v.z];
        let mut file = Self {
            name: Some(obstacle.name),
            clearance_m: obstacle.clearance_m,
            tool_may_touch: obstacle.tool_may_touch,
            half_space: None,
            cuboid: None,
            sphere: None,
            capsule: None,
        };
        match &obstacle.shape {
            Shape::HalfSpace { point, normal } => {
                file.half_space = Some(HalfSpaceFile {
                    point: array(point),
                    normal: array(normal),
                });
            }
            Shape::Cuboid {
                centre,
                rotation,
                half_extents,
            } => {
                let (roll, pitch, yaw) = rpy_of(rotation);
                file.cuboid = Some(BoxFile {
                    centre: array(centre),
                    size: array(&(half_extents * 2.0)),
                    rpy: [roll, pitch, yaw],
                });
            }
            Shape::Sphere { centre, radius } => {
                file.sphere = Some(SphereFile {
                    centre: array(centre),
                    radius: *radius,
                });
            }
            Shape::Capsule { start, end, radius } => {
                file.capsule = Some(CapsuleFile {
                    start: array(start),
                    end: array(end),
                    radius: *radius,
                });
            }
        }
        file
    }
}
