//! Vendor robot descriptions made usable: the chain from the base link to the tool link is kept
//! (links hanging off it give it their collision geometry, joints other than fixed ones held at
//! position 0, e.g. a gripper's fingers; frames without any geometry are dropped), every link's collision geometry (boxes, cylinders, spheres, capsules and
//! STL/OBJ meshes, wherever `package://` or a relative path puts them) is replaced by fitted
//! bounding capsules, a pen is attached to the tool link, and the result is written as a
//! standard URDF (each capsule a cylinder plus two sphere caps) that the planners and the
//! independent checker read like the shipped robot files.

use std::path::{Path, PathBuf};
use std::str::FromStr;

use emg_kinematics::{
    Ball, Covered, FittedCapsule, PairRule, Robot, Vec3, disabled_pairs, fit_capsules,
    rotation_from_rpy, rotation_onto, rpy_of, segment_distance,
};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

use crate::mesh::{MeshError, mesh_volume, read_mesh};

/// Sides of the prism that stands in for a cylinder (circumscribed, so it contains it).
const PRISM_SIDES: usize = 32;

/// Name of the link the attached pen ends in (the TCP).
pub const PEN_LINK: &str = "pen_tip";

/// Where the files of `package://NAME/...` are found.
#[derive(Clone, Debug, PartialEq)]
pub enum PackagePath {
    /// A directory of packages: `DIR/NAME/...`, or a directory below `DIR` whose `package.xml`
    /// names the package.
    Search(PathBuf),
    /// The directory of one package (`NAME=DIR` on the command line).
    Named {
        /// The package.
        name: String,
        /// Its directory.
        dir: PathBuf,
    },
}

impl FromStr for PackagePath {
    type Err = std::convert::Infallible;

    /// `NAME=DIR` names one package's directory; anything else is a directory of packages.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Ok(match text.split_once('=') {
            Some((name, dir)) if !name.is_empty() && !name.contains('/') => Self::Named {
                name: name.to_string(),
                dir: PathBuf::from(dir),
            },
            _ => Self::Search(PathBuf::from(text)),
        })
    }
}

/// The pen attached to the tool link: a capsule along the link's z axis ending at the TCP.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pen {
    /// From the tool link's origin to the tip (m).
    pub length_m: f64,
    /// Radius (m).
    pub radius_m: f64,
}

impl Default for Pen {
    /// The shipped robots' pen: 10 cm long, 5 mm in radius.
    fn default() -> Self {
        Self {
            length_m: 0.1,
            radius_m: 0.005,
        }
    }
}

/// How a vendor description is imported.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportOptions {
    /// Where `package://` files are looked for.
    pub package_paths: Vec<PackagePath>,
    /// The link the pen attaches to (default: the file's only leaf link).
    pub tool_link: Option<String>,
    /// The chain's base link (default: the file's only root link).
    pub base_link: Option<String>,
    /// The pen.
    pub pen: Pen,
    /// Most capsules fitted to one link (1 to 3).
    pub max_capsules_per_link: usize,
    /// An SRDF file whose `disable_collisions` pairs are not checked either.
    pub srdf: Option<PathBuf>,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            package_paths: Vec::new(),
            tool_link: None,
            base_link: None,
            pen: Pen::default(),
            max_capsules_per_link: 3,
            srdf: None,
        }
    }
}

/// What was fitted to one link.
#[derive(Clone, Debug, PartialEq)]
pub struct LinkFit {
    /// The link.
    pub link: String,
    /// Its collision elements as read (`mesh link_1.stl (1,240 triangles)`, `box`, ...).
    pub elements: Vec<String>,
    /// The capsules fitted around them, in the link frame.
    pub capsules: Vec<FittedCapsule>,
    /// Volume of the elements (m³; overlaps counted twice, an open mesh's as if closed).
    pub source_volume_m3: f64,
}

impl LinkFit {
    /// Volume of the capsules (m³; overlaps counted twice).
    pub fn capsule_volume_m3(&self) -> f64 {
        self.capsules.iter().map(FittedCapsule::volume).sum()
    }
}

/// Why two links are not checked against each other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DisabledBecause {
    /// A joint connects them.
    Adjacent,
    /// Their capsules overlap at the mid-range configuration.
    CollidingAtMidRange,
    /// The given SRDF file disables them.
    Given,
}

impl DisabledBecause {
    /// The SRDF `reason` attribute (MoveIt's words).
    pub fn srdf_reason(self) -> &'static str {
        match self {
            Self::Adjacent => "Adjacent",
            Self::CollidingAtMidRange => "Default",
            Self::Given => "User",
        }
    }
}

/// A description with capsule collision geometry and a pen, ready to plan with.
#[derive(Clone, Debug)]
pub struct ImportedRobot {
    /// The standard URDF text.
    pub urdf: String,
    /// The SRDF text listing the link pairs not checked for self-collision (written beside the
    /// URDF, where the planners' and the checker's loaders find it).
    pub srdf: String,
    /// Those pairs, with why.
    pub disabled: Vec<(String, String, DisabledBecause)>,
    /// The chain's base link.
    pub base_link: String,
    /// The link the pen was attached to.
    pub tool_link: String,
    /// Moving joints off the chain whose links' geometry was merged with them held at 0.
    pub held_joints: Vec<String>,
    /// What was fitted, link by link (links without collision geometry are left out).
    pub fits: Vec<LinkFit>,
}

/// Why a description cannot be imported.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The description cannot be read.
    #[error("cannot read robot file {path}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The text is not URDF.
    #[error("malformed URDF: {0}")]
    Malformed(String),
    /// A mesh file named by the description cannot be found.
    #[error(
        "link '{link}': mesh '{filename}' not found (looked in: {tried}); give the directory of \
         its package with --package-path DIR or --package-path NAME=DIR"
    )]
    MeshNotFound {
        /// The link.
        link: String,
        /// The file name as written in the description.
        filename: String,
        /// The places looked in.
        tried: String,
    },
    /// A mesh file cannot be read.
    #[error("link '{link}': {source}")]
    Mesh {
        /// The link.
        link: String,
        /// The cause.
        #[source]
        source: MeshError,
    },
    /// A geometry value is not usable.
    #[error("link '{link}': collision {field} {problem}")]
    BadGeometry {
        /// The link.
        link: String,
        /// The field.
        field: &'static str,
        /// What is wrong with it.
        problem: String,
    },
    /// The chain's ends cannot be told, or the chain is not serial.
    #[error("{0}")]
    Chain(String),
    /// The pen does not fit.
    #[error("pen: {0}")]
    Pen(String),
    /// The result cannot be written as URDF.
    #[error("cannot write the URDF: {0}")]
    Write(String),
}

/// Reads the description at `path` and replaces its collision geometry as the module says.
pub fn import_robot(path: &Path, options: &ImportOptions) -> Result<ImportedRobot, ImportError> {
    let text = std::fs::read_to_string(path).map_err(|source| ImportError::Io {
        path: path.display().to_string(),
        source,
    })?;
    let mut robot =
        urdf_rs::read_from_string(&text).map_err(|e| ImportError::Malformed(e.to_string()))?;
    let base_dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let pen = options.pen;
    if !(pen.length_m.is_finite()
        && pen.length_m > 0.0
        && pen.radius_m.is_finite()
        && pen.radius_m > 0.0)
    {
        return Err(ImportError::Pen(format!(
            "length {} m and radius {} m must be positive",
            pen.length_m, pen.radius_m
        )));
    }
    if robot.links.iter().any(|l| l.name == PEN_LINK) {
        return Err(ImportError::Pen(format!(
            "the file already has a link '{PEN_LINK}'; it is the pen's"
        )));
    }
    let tool_link = chain_end(&robot, options.tool_link.as_deref(), End::Leaf)?;
    let base_link = chain_end(&robot, options.base_link.as_deref(), End::Root)?;
    let held_joints = keep_chain(&mut robot, &base_link, &tool_link)?;
    let mut fits = Vec::new();
    for link in &mut robot.links {
        if link.collision.is_empty() {
            continue;
        }
        let fit = fit_link(link, &base_dir, options)?;
        link.collision = fit.capsules.iter().flat_map(capsule_elements).collect();
        fits.push(fit);
    }
    let pen_capsule = FittedCapsule {
        start: Vec3::new(0.0, 0.0, -pen.length_m),
        end: Vec3::zeros(),
        radius: pen.radius_m,
    };
    robot.links.push(urdf_rs::Link {
        name: PEN_LINK.to_string(),
        inertial: urdf_rs::Inertial::default(),
        visual: Vec::new(),
        collision: capsule_elements(&pen_capsule),
    });
    robot.joints.push(urdf_rs::Joint {
        name: format!("{tool_link}_to_{PEN_LINK}"),
        joint_type: urdf_rs::JointType::Fixed,
        origin: urdf_rs::Pose {
            xyz: urdf_rs::Vec3([0.0, 0.0, pen.length_m]),
            rpy: urdf_rs::Vec3([0.0, 0.0, 0.0]),
        },
        parent: urdf_rs::LinkName {
            link: tool_link.clone(),
        },
        child: urdf_rs::LinkName {
            link: PEN_LINK.to_string(),
        },
        axis: urdf_rs::Axis::default(),
        limit: urdf_rs::JointLimit::default(),
        calibration: None,
        dynamics: None,
        mimic: None,
        safety_controller: None,
    });
    let urdf = urdf_rs::write_to_string(&robot).map_err(|e| ImportError::Write(e.to_string()))?;
    let mut disabled: Vec<(String, String, DisabledBecause)> = robot
        .joints
        .iter()
        .map(|j| {
            (
                j.parent.link.clone(),
                j.child.link.clone(),
                DisabledBecause::Adjacent,
            )
        })
        .collect();
    if let Some(path) = &options.srdf {
        let text = std::fs::read_to_string(path).map_err(|source| ImportError::Io {
            path: path.display().to_string(),
            source,
        })?;
        let given = disabled_pairs(&text)
            .map_err(|e| ImportError::Malformed(format!("{}: {e}", path.display())))?;
        disabled.extend(
            given
                .into_iter()
                .map(|(a, b)| (a, b, DisabledBecause::Given)),
        );
    }
    let chain =
        Robot::from_urdf_str_with_rule(&urdf, &base_link, PEN_LINK, PairRule::LinkSeparation)
            .map_err(|e| {
                ImportError::Chain(format!("the chain '{base_link}' → '{PEN_LINK}': {e}"))
            })?;
    for (a, b) in colliding_at_mid_range(&chain) {
        let listed = disabled
            .iter()
            .any(|(x, y, _)| (*x == a && *y == b) || (*x == b && *y == a));
        if !listed {
            disabled.push((a, b, DisabledBecause::CollidingAtMidRange));
        }
    }
    let mut srdf = format!("<?xml version=\"1.0\"?>\n<robot name=\"{}\">\n", robot.name);
    for (a, b, why) in &disabled {
        srdf += &format!(
            "  <disable_collisions link1=\"{a}\" link2=\"{b}\" reason=\"{}\"/>\n",
            why.srdf_reason()
        );
    }
    srdf += "</robot>\n";
    Ok(ImportedRobot {
        urdf,
        srdf,
        disabled,
        base_link,
        tool_link,
        held_joints,
        fits,
    })
}

/// The link pairs (distinct links, any two) whose capsules overlap at the mid-range
/// configuration.
fn colliding_at_mid_range(robot: &Robot) -> Vec<(String, String)> {
    let kin = robot.forward(&robot.mid_range());
    let placed: Vec<(&str, Vec3, Vec3, f64)> = robot
        .capsules()
        .iter()
        .map(|c| {
            (
                c.link.as_str(),
                kin.segment_point(c.segment, &c.start),
                kin.segment_point(c.segment, &c.end),
                c.radius,
            )
        })
        .collect();
    let mut pairs: Vec<(String, String)> = Vec::new();
    for (i, a) in placed.iter().enumerate() {
        for b in &placed[i + 1..] {
            let overlap = segment_distance(&a.1, &a.2, &b.1, &b.2) < a.3 + b.3;
            let known = pairs
                .iter()
                .any(|(x, y)| (x == a.0 && y == b.0) || (x == b.0 && y == a.0));
            if a.0 != b.0 && overlap && !known {
                pairs.push((a.0.to_string(), b.0.to_string()));
            }
        }
    }
    pairs
}

/// Which end of the chain a link is.
#[derive(Clone, Copy)]
enum End {
    /// The base: no joint leads to it.
    Root,
    /// The tool: no joint leaves it.
    Leaf,
}

/// The link named, checked to exist, or the file's only root (leaf) link.
fn chain_end(robot: &urdf_rs::Robot, named: Option<&str>, end: End) -> Result<String, ImportError> {
    let (role, option) = match end {
        End::Root => ("base", "--base-link"),
        End::Leaf => ("tool", "--tool-link"),
    };
    if let Some(name) = named {
        return if robot.links.iter().any(|l| l.name == name) {
            Ok(name.to_string())
        } else {
            let names: Vec<&str> = robot.links.iter().map(|l| l.name.as_str()).collect();
            Err(ImportError::Chain(format!(
                "{role} link '{name}' is not in the robot file (links: {})",
                names.join(", ")
            )))
        };
    }
    let ends: Vec<&str> = robot
        .links
        .iter()
        .map(|l| l.name.as_str())
        .filter(|name| {
            !robot.joints.iter().any(|j| match end {
                End::Root => j.child.link == *name,
                End::Leaf => j.parent.link == *name,
            })
        })
        .collect();
    match ends.as_slice() {
        [only] => Ok(only.to_string()),
        _ => Err(ImportError::Chain(format!(
            "the robot file has {} links [{}]; name the {role} link ({option})",
            match end {
                End::Root => "root",
                End::Leaf => "leaf",
            },
            ends.join(", ")
        ))),
    }
}

/// Keeps the links and joints from `base` to `tool`; the collision elements of a link hanging
/// off that chain move to the chain link it hangs from, with the joints on the way at position 0
/// (the planners move one serial chain). Returns the moving joints so held.
fn keep_chain(
    robot: &mut urdf_rs::Robot,
    base: &str,
    tool: &str,
) -> Result<Vec<String>, ImportError> {
    let parent_joint = |link: &str| robot.joints.iter().position(|j| j.child.link == link);
    let mut chain = vec![tool.to_string()];
    while chain.last().map(String::as_str) != Some(base) {
        let link = chain.last().expect("the chain starts at the tool");
        let joint = parent_joint(link).ok_or_else(|| {
            ImportError::Chain(format!(
                "tool link '{tool}' is not below base link '{base}'"
            ))
        })?;
        if chain.len() > robot.joints.len() {
            return Err(ImportError::Chain(format!(
                "the joints above '{tool}' form a loop"
            )));
        }
        chain.push(robot.joints[joint].parent.link.clone());
    }
    let on_chain = |link: &str| chain.iter().any(|c| c == link);
    let mut moved: Vec<(String, urdf_rs::Collision)> = Vec::new();
    let mut held = Vec::new();
    for link in robot.links.iter().filter(|l| !on_chain(&l.name)) {
        if link.collision.is_empty() {
            continue;
        }
        // Walk up to the chain, composing the fixed joints' origins.
        let mut pose = Isometry3::identity();
        let mut current = link.name.clone();
        while !on_chain(&current) {
            let joint = parent_joint(&current)
                .map(|j| &robot.joints[j])
                .filter(|j| j.child.link != base)
                .ok_or_else(|| {
                    ImportError::Chain(format!(
                        "link '{}' has collision geometry but does not hang off the chain \
                         '{base}' → '{tool}'",
                        link.name
                    ))
                })?;
            if joint.joint_type != urdf_rs::JointType::Fixed && !held.contains(&joint.name) {
                held.push(joint.name.clone());
            }
            pose = isometry(&joint.origin) * pose;
            current = joint.parent.link.clone();
        }
        for collision in &link.collision {
            let mut collision = collision.clone();
            collision.origin = urdf_pose(&(pose * isometry(&collision.origin)));
            moved.push((current.clone(), collision));
        }
    }
    for (link, collision) in moved {
        if let Some(target) = robot.links.iter_mut().find(|l| l.name == link) {
            target.collision.push(collision);
        }
    }
    robot.links.retain(|l| on_chain(&l.name));
    robot
        .joints
        .retain(|j| on_chain(&j.child.link) && on_chain(&j.parent.link));
    Ok(held)
}

/// A URDF pose as a rigid transform (the origin's `xyz`, then its roll–pitch–yaw).
fn isometry(pose: &urdf_rs::Pose) -> Isometry3<f64> {
    let [x, y, z] = pose.xyz.0;
    let [roll, pitch, yaw] = pose.rpy.0;
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_rotation_matrix(&rotation_from_rpy(roll, pitch, yaw)),
    )
}

/// A rigid transform as a URDF pose.
fn urdf_pose(pose: &Isometry3<f64>) -> urdf_rs::Pose {
    let t = pose.translation.vector;
    let (roll, pitch, yaw) = rpy_of(&pose.rotation.to_rotation_matrix());
    urdf_rs::Pose {
        xyz: urdf_rs::Vec3([t.x, t.y, t.z]),
        rpy: urdf_rs::Vec3([roll, pitch, yaw]),
    }
}

/// The capsules fitted to `link`'s collision elements, in the link frame.
fn fit_link(
    link: &urdf_rs::Link,
    base_dir: &Path,
    options: &ImportOptions,
) -> Result<LinkFit, ImportError> {
    let bad = |field: &'static str, problem: String| ImportError::BadGeometry {
        link: link.name.clone(),
        field,
        problem,
    };
    let mut covered = Covered::default();
    let mut elements = Vec::new();
    let mut source_volume_m3 = 0.0;
    for collision in &link.collision {
        let [x, y, z] = collision.origin.xyz.0;
        let [roll, pitch, yaw] = collision.origin.rpy.0;
        if ![x, y, z, roll, pitch, yaw].iter().all(|v| v.is_finite()) {
            return Err(bad("origin", "must hold finite numbers".into()));
        }
        let pose = isometry(&collision.origin);
        let place = |p: Vec3| pose.transform_point(&p.into()).coords;
        let positive = |field: &'static str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(v)
            } else {
                Err(bad(field, format!("{v} must be a number ≥ 0")))
            }
        };
        match &collision.geometry {
            urdf_rs::Geometry::Box { size } => {
                let [sx, sy, sz] = size.0;
                let half = Vec3::new(
                    positive("box size", sx)?,
                    positive("box size", sy)?,
                    positive("box size", sz)?,
                ) * 0.5;
                covered
                    .triangles
                    .extend(box_triangles(&half).into_iter().map(|t| t.map(place)));
                source_volume_m3 += 8.0 * half.x * half.y * half.z;
                elements.push(format!("box {sx}×{sy}×{sz} m"));
            }
            urdf_rs::Geometry::Cylinder { radius, length } => {
                let (r, l) = (positive("radius", *radius)?, positive("length", *length)?);
                covered
                    .triangles
                    .extend(prism_triangles(r, l).into_iter().map(|t| t.map(place)));
                source_volume_m3 += std::f64::consts::PI * r * r * l;
                elements.push(format!("cylinder r {r} m, length {l} m"));
            }
            urdf_rs::Geometry::Capsule { radius, length } => {
                let (r, l) = (positive("radius", *radius)?, positive("length", *length)?);
                covered
                    .triangles
                    .extend(prism_triangles(r, l).into_iter().map(|t| t.map(place)));
                for end in [-0.5 * l, 0.5 * l] {
                    covered.balls.push(Ball {
                        centre: place(Vec3::new(0.0, 0.0, end)),
                        radius: r,
                    });
                }
                source_volume_m3 += std::f64::consts::PI * r * r * (l + 4.0 / 3.0 * r);
                elements.push(format!("capsule r {r} m, length {l} m"));
            }
            urdf_rs::Geometry::Sphere { radius } => {
                let r = positive("radius", *radius)?;
                covered.balls.push(Ball {
                    centre: place(Vec3::zeros()),
                    radius: r,
                });
                source_volume_m3 += 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
                elements.push(format!("sphere r {r} m"));
            }
            urdf_rs::Geometry::Mesh { filename, scale } => {
                let file =
                    resolve(filename, base_dir, &options.package_paths).map_err(|tried| {
                        ImportError::MeshNotFound {
                            link: link.name.clone(),
                            filename: filename.clone(),
                            tried,
                        }
                    })?;
                let scale = scale.map_or([1.0; 3], |s| s.0);
                if !scale.iter().all(|s| s.is_finite() && *s != 0.0) {
                    return Err(bad(
                        "mesh scale",
                        format!("{scale:?} must be finite and non-zero"),
                    ));
                }
                let triangles: Vec<[Vec3; 3]> = read_mesh(&file)
                    .map_err(|source| ImportError::Mesh {
                        link: link.name.clone(),
                        source,
                    })?
                    .into_iter()
                    .map(|t| t.map(|p| place(p.component_mul(&Vec3::from(scale)))))
                    .collect();
                source_volume_m3 += mesh_volume(&triangles);
                elements.push(format!(
                    "mesh {} ({} triangles)",
                    file.file_name()
                        .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
                    triangles.len()
                ));
                covered.triangles.extend(triangles);
            }
        }
    }
    let capsules = fit_capsules(&covered, options.max_capsules_per_link.clamp(1, 3))
        .ok_or_else(|| bad("geometry", "is empty (a mesh without triangles?)".into()))?;
    Ok(LinkFit {
        link: link.name.clone(),
        elements,
        capsules,
        source_volume_m3,
    })
}

/// The file a mesh `filename` names: `package://NAME/REST` through the package paths, else (as
/// pybullet reads it) `NAME/REST` beside the description; `file://` and absolute paths as they
/// are, others relative to the description's directory. `Err` lists the places looked in.
fn resolve(filename: &str, base_dir: &Path, packages: &[PackagePath]) -> Result<PathBuf, String> {
    let mut tried = Vec::new();
    let found = |candidate: PathBuf, tried: &mut Vec<String>| {
        if candidate.is_file() {
            Some(candidate)
        } else {
            tried.push(candidate.display().to_string());
            None
        }
    };
    if let Some(rest) = filename.strip_prefix("package://") {
        let (name, inner) = rest.split_once('/').unwrap_or((rest, ""));
        for package in packages {
            let candidate = match package {
                PackagePath::Named { name: named, dir } if named == name => Some(dir.join(inner)),
                PackagePath::Named { .. } => None,
                PackagePath::Search(dir) => Some(
                    package_dir(dir, name, 4)
                        .unwrap_or_else(|| dir.join(name))
                        .join(inner),
                ),
            };
            if let Some(file) = candidate.and_then(|c| found(c, &mut tried)) {
                return Ok(file);
            }
        }
        if let Some(file) = found(base_dir.join(rest), &mut tried) {
            return Ok(file);
        }
        return Err(tried.join(", "));
    }
    let plain = filename.strip_prefix("file://").unwrap_or(filename);
    let candidate = if Path::new(plain).is_absolute() {
        PathBuf::from(plain)
    } else {
        base_dir.join(plain)
    };
    found(candidate, &mut tried).ok_or_else(|| tried.join(", "))
}

/// The directory below `dir` (within `depth` levels) named `name` or whose `package.xml`
/// names package `name`.
fn package_dir(dir: &Path, name: &str, depth: usize) -> Option<PathBuf> {
    let direct = dir.join(name);
    if direct.is_dir() {
        return Some(direct);
    }
    let manifest = dir.join("package.xml");
    if let Ok(text) = std::fs::read_to_string(&manifest)
        && text.contains(&format!("<name>{name}</name>"))
    {
        return Some(dir.to_path_buf());
    }
    if depth == 0 {
        return None;
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    entries.sort();
    entries
        .iter()
        .find_map(|sub| package_dir(sub, name, depth - 1))
}

/// The twelve triangles of the box `|x_i| ≤ half_i`.
fn box_triangles(half: &Vec3) -> Vec<[Vec3; 3]> {
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 != 0 { half.x } else { -half.x },
            if i & 2 != 0 { half.y } else { -half.y },
            if i & 4 != 0 { half.z } else { -half.z },
        )
    };
    let faces = [
        [0, 1, 3, 2],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 3, 7, 5],
    ];
    faces
        .iter()
        .flat_map(|f| {
            [
                [corner(f[0]), corner(f[1]), corner(f[2])],
                [corner(f[0]), corner(f[2]), corner(f[3])],
            ]
        })
        .collect()
}

/// Triangles of a prism circumscribing the cylinder of `radius` and `length` along z, centred
/// at the origin (its side faces touch the cylinder, so it contains it).
fn prism_triangles(radius: f64, length: f64) -> Vec<[Vec3; 3]> {
    let circumradius = radius / libm::cos(std::f64::consts::PI / PRISM_SIDES as f64);
    let corner = |k: usize, z: f64| {
        let angle = std::f64::consts::TAU * k as f64 / PRISM_SIDES as f64;
        let (sin, cos) = libm::sincos(angle);
        Vec3::new(circumradius * cos, circumradius * sin, z)
    };
    let (bottom, top) = (-0.5 * length, 0.5 * length);
    (0..PRISM_SIDES)
        .flat_map(|k| {
            let (a, b) = (corner(k, bottom), corner(k + 1, bottom));
            let (c, d) = (corner(k, top), corner(k + 1, top));
            [
                [a, b, d],
                [a, d, c],
                [Vec3::new(0.0, 0.0, bottom), b, a],
                [Vec3::new(0.0, 0.0, top), c, d],
            ]
        })
        .collect()
}

/// A capsule as standard URDF collision elements: a cylinder along its axis and a sphere of its
/// radius on each end (one sphere for a capsule of length 0).
fn capsule_elements(capsule: &FittedCapsule) -> Vec<urdf_rs::Collision> {
    let element = |origin: Vec3, rpy: [f64; 3], geometry: urdf_rs::Geometry| urdf_rs::Collision {
        name: None,
        origin: urdf_rs::Pose {
            xyz: urdf_rs::Vec3([origin.x, origin.y, origin.z]),
            rpy: urdf_rs::Vec3(rpy),
        },
        geometry,
    };
    let sphere = |centre: Vec3| {
        element(
            centre,
            [0.0; 3],
            urdf_rs::Geometry::Sphere {
                radius: capsule.radius,
            },
        )
    };
    let axis = capsule.end - capsule.start;
    let length = axis.norm();
    if length < 1e-9 {
        return vec![sphere(0.5 * (capsule.start + capsule.end))];
    }
    let turn = rotation_onto(&Vec3::z(), &(axis / length));
    let (roll, pitch, yaw) = rpy_of(&turn);
    // The caps sit where the loaders put the cylinder's ends: the centre ± half the length
    // along the turned z axis.
    let centre = 0.5 * (capsule.start + capsule.end);
    let half = turn * Vec3::z() * (0.5 * length);
    vec![
        element(
            centre,
            [roll, pitch, yaw],
            urdf_rs::Geometry::Cylinder {
                radius: capsule.radius,
                length,
            },
        ),
        sphere(centre - half),
        sphere(centre + half),
    ]
}
