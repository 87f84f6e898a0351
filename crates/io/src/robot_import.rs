//! Vendor robot descriptions made usable: the chain from the base link to the tool link is kept
//! (links hanging off it give it their collision geometry, joints other than fixed ones held at
//! position 0, e.g. a gripper's fingers; frames without any geometry are dropped), every link's collision geometry (boxes, cylinders, spheres, capsules and
//! STL/OBJ meshes, wherever `package://` or a relative path puts them) is replaced by fitted
//! bounding capsules, a pen is attached to the tool link (by default reaching
//! [`PEN_PROTRUSION_M`] beyond the tool's own geometry), and the result is written as a
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

/// How far the default pen's tip lies beyond the tool's collision geometry along the pen axis
/// (m): the free length of the shipped robots' pen, 0.1 m ahead of their flange.
pub const PEN_PROTRUSION_M: f64 = 0.1;

/// Tool geometry reaching less than this ahead of the tool link's origin (m) counts as none
/// for the default pen: a flange face drawn at the origin, as meshes give it to within a few
/// hundredths of a millimetre (rtb-data's iiwa) or tenths (pybullet's xArm 6).
pub const PEN_REACH_TOLERANCE_M: f64 = 0.001;

/// The tool links REP 199 names, in the order a default is taken from them when a description
/// has several leaf links: `tool0` (the tool frame, ROS-Industrial's name), else `flange`.
pub const REP_199_TOOL_LINKS: [&str; 2] = ["tool0", "flange"];

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

impl Pen {
    /// The default pen's length for a tool whose collision geometry reaches `reach_m` ahead of
    /// the tool link's origin along its z axis: [`PEN_PROTRUSION_M`] beyond that geometry, and
    /// the default 0.1 m when nothing lies ahead of the origin (by more than
    /// [`PEN_REACH_TOLERANCE_M`]).
    pub fn default_length_m(reach_m: f64) -> f64 {
        if reach_m < PEN_REACH_TOLERANCE_M {
            Self::default().length_m
        } else {
            reach_m + PEN_PROTRUSION_M
        }
    }
}

/// How far the tool's collision geometry reaches along the pen axis.
#[derive(Clone, Debug, PartialEq)]
pub struct ToolReach {
    /// The largest z, in the tool link's frame, of the collision elements of the tool link and
    /// of the chain links rigidly fixed to it (m; negative when all of it lies behind the
    /// origin, `-inf` when there is none): mesh and box corners, cylinders as their
    /// circumscribed prism, spheres and capsules with their caps. Links hanging off them, held
    /// at position 0 when on a moving joint (a gripper's fingers), count with the link they hang
    /// from.
    pub reach_m: f64,
    /// The same of the capsules fitted around those elements (m; at least `reach_m`): what the
    /// planners and the checker test against the work surface.
    pub capsule_reach_m: f64,
    /// Those links, the tool link first, each with the links merged into it (capsules or not).
    pub links: Vec<String>,
}

/// How the tool link was chosen.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ToolLinkChoice {
    /// Named in the options (`--tool-link`).
    Named,
    /// The file's only leaf link.
    OnlyLeaf,
    /// Of several leaf links (these), the first of [`REP_199_TOOL_LINKS`] the file has.
    Rep199 {
        /// The file's leaf links.
        leaves: Vec<String>,
    },
}

/// How a vendor description is imported.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportOptions {
    /// Where `package://` files are looked for.
    pub package_paths: Vec<PackagePath>,
    /// The link the pen attaches to (default: the file's only leaf link; of several,
    /// `tool0`, else `flange`, per REP 199).
    pub tool_link: Option<String>,
    /// The chain's base link (default: the file's only root link).
    pub base_link: Option<String>,
    /// The pen's length from the tool link's origin to the tip (m); `None`:
    /// [`Pen::default_length_m`] of the tool's reach, [`PEN_PROTRUSION_M`] beyond its geometry.
    pub pen_length_m: Option<f64>,
    /// The pen's radius (m).
    pub pen_radius_m: f64,
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
            pen_length_m: None,
            pen_radius_m: Pen::default().radius_m,
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
    /// How it was chosen.
    pub tool_link_choice: ToolLinkChoice,
    /// The pen attached.
    pub pen: Pen,
    /// Whether its length was given (else it is [`Pen::default_length_m`] of the reach).
    pub pen_length_given: bool,
    /// How far the tool's geometry reaches along the pen axis.
    pub tool_reach: ToolReach,
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

impl ImportedRobot {
    /// Whether the pen's tip lies beyond the tool's collision geometry along the pen axis (else
    /// the tool touches the work surface before the tip does).
    pub fn pen_protrudes(&self) -> bool {
        self.pen.length_m > self.tool_reach.reach_m
    }

    /// Whether the pen's tip lies beyond the capsules fitted to the tool's geometry too (else
    /// the planners and the checker see the tool's capsules touch the work surface first).
    pub fn pen_clears_capsules(&self) -> bool {
        self.pen.length_m > self.tool_reach.capsule_reach_m
    }
}

/// Reads the description at `path` and replaces its collision geometry as the module says.
pub fn import_robot(path: &Path, options: &ImportOptions) -> Result<ImportedRobot, ImportError> {
    let text = std::fs::read_to_string(path).map_err(|source| ImportError::Io {
        path: path.display().to_string(),
        source,
    })?;
    import_text(&text, path.parent().unwrap_or(Path::new(".")), options)
}

/// [`import_robot`] of a description's text, its relative file names read from `base_dir`.
fn import_text(
    text: &str,
    base_dir: &Path,
    options: &ImportOptions,
) -> Result<ImportedRobot, ImportError> {
    let mut robot =
        urdf_rs::read_from_string(text).map_err(|e| ImportError::Malformed(e.to_string()))?;
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if !(options.pen_length_m.is_none_or(positive) && positive(options.pen_radius_m)) {
        return Err(ImportError::Pen(format!(
            "length {} m and radius {} m must be positive",
            options
                .pen_length_m
                .map_or_else(|| "(default)".to_string(), |l| l.to_string()),
            options.pen_radius_m
        )));
    }
    if robot.links.iter().any(|l| l.name == PEN_LINK) {
        return Err(ImportError::Pen(format!(
            "the file already has a link '{PEN_LINK}'; it is the pen's"
        )));
    }
    let (tool_link, tool_link_choice) = tool_end(&robot, options.tool_link.as_deref())?;
    let base_link = chain_end(&robot, options.base_link.as_deref(), End::Root)?;
    let KeptChain {
        held: held_joints,
        merged,
    } = keep_chain(&mut robot, &base_link, &tool_link)?;
    let mut fits = Vec::new();
    let mut elements = Vec::new();
    for link in &mut robot.links {
        if link.collision.is_empty() {
            continue;
        }
        let (fit, covered) = fit_link(link, base_dir, options)?;
        link.collision = fit.capsules.iter().flat_map(capsule_elements).collect();
        fits.push(fit);
        elements.push((link.name.clone(), covered));
    }
    let tool_reach = tool_reach(&robot, &fits, &elements, &merged, &tool_link);
    let pen = Pen {
        length_m: options
            .pen_length_m
            .unwrap_or_else(|| Pen::default_length_m(tool_reach.reach_m)),
        radius_m: options.pen_radius_m,
    };
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
        tool_link_choice,
        pen,
        pen_length_given: options.pen_length_m.is_some(),
        tool_reach,
        held_joints,
        fits,
    })
}

/// How far the collision elements (and the capsules fitted to them) of `tool` and of the chain
/// links rigidly fixed to it (walking up the kept chain through fixed joints) reach along
/// `tool`'s z axis; `elements` holds each link's elements, `merged` names, per chain link, the
/// links off the chain whose geometry it took.
fn tool_reach(
    robot: &urdf_rs::Robot,
    fits: &[LinkFit],
    elements: &[(String, Covered)],
    merged: &[(String, String)],
    tool: &str,
) -> ToolReach {
    let mut reach_m = f64::NEG_INFINITY;
    let mut capsule_reach_m = f64::NEG_INFINITY;
    let mut links = Vec::new();
    // The pose of `current` in the tool link's frame.
    let mut tool_from_link = Isometry3::identity();
    let mut current = tool.to_string();
    loop {
        links.push(current.clone());
        links.extend(
            merged
                .iter()
                .filter(|(onto, _)| *onto == current)
                .map(|(_, from)| from.clone()),
        );
        let z = |p: &Vec3| tool_from_link.transform_point(&(*p).into()).z;
        for capsule in fits
            .iter()
            .filter(|f| f.link == current)
            .flat_map(|f| &f.capsules)
        {
            for end in [capsule.start, capsule.end] {
                capsule_reach_m = capsule_reach_m.max(z(&end) + capsule.radius);
            }
        }
        for (_, covered) in elements.iter().filter(|(link, _)| *link == current) {
            for corner in covered.triangles.iter().flatten() {
                reach_m = reach_m.max(z(corner));
            }
            for ball in &covered.balls {
                reach_m = reach_m.max(z(&ball.centre) + ball.radius);
            }
        }
        let Some(joint) = robot
            .joints
            .iter()
            .find(|j| j.child.link == current && j.joint_type == urdf_rs::JointType::Fixed)
        else {
            break;
        };
        if links.contains(&joint.parent.link) {
            break;
        }
        tool_from_link *= isometry(&joint.origin).inverse();
        current = joint.parent.link.clone();
    }
    ToolReach {
        reach_m,
        capsule_reach_m,
        links,
    }
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

/// The tool link: the one named, checked to exist; else the file's only leaf link; else, of
/// several leaf links, `tool0` or failing it `flange` (REP 199), when the file has one.
fn tool_end(
    robot: &urdf_rs::Robot,
    named: Option<&str>,
) -> Result<(String, ToolLinkChoice), ImportError> {
    match chain_end(robot, named, End::Leaf) {
        Ok(link) if named.is_some() => Ok((link, ToolLinkChoice::Named)),
        Ok(link) => Ok((link, ToolLinkChoice::OnlyLeaf)),
        Err(error) if named.is_some() => Err(error),
        Err(error) => {
            let Some(tool) = REP_199_TOOL_LINKS
                .iter()
                .find(|name| robot.links.iter().any(|l| l.name == **name))
            else {
                return Err(error);
            };
            let leaves = robot
                .links
                .iter()
                .filter(|l| !robot.joints.iter().any(|j| j.parent.link == l.name))
                .map(|l| l.name.clone())
                .collect();
            Ok((tool.to_string(), ToolLinkChoice::Rep199 { leaves }))
        }
    }
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

/// What [`keep_chain`] merged.
struct KeptChain {
    /// The moving joints held at position 0.
    held: Vec<String>,
    /// Which chain link took the geometry of which link off the chain.
    merged: Vec<(String, String)>,
}

/// Keeps the links and joints from `base` to `tool`; the collision elements of a link hanging
/// off that chain move to the chain link it hangs from, with the joints on the way at position 0
/// (the planners move one serial chain).
fn keep_chain(
    robot: &mut urdf_rs::Robot,
    base: &str,
    tool: &str,
) -> Result<KeptChain, ImportError> {
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
    let mut merged = Vec::new();
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
        merged.push((current, link.name.clone()));
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
    Ok(KeptChain { held, merged })
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

/// The capsules fitted to `link`'s collision elements, and those elements, in the link frame.
fn fit_link(
    link: &urdf_rs::Link,
    base_dir: &Path,
    options: &ImportOptions,
) -> Result<(LinkFit, Covered), ImportError> {
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
    let fit = LinkFit {
        link: link.name.clone(),
        elements,
        capsules,
        source_volume_m3,
    };
    Ok((fit, covered))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A six-joint arm `l0`..`l6` (each joint 0.2 m along the previous z) with `extra` links and
    /// joints appended: `(parent, child, type, origin xyz, child's collision element)`.
    fn arm(extra: &[(&str, &str, &str, &str, &str)]) -> String {
        let mut text = String::from("<robot name=\"arm\">\n");
        let element = |geometry: &str| {
            if geometry.is_empty() {
                String::new()
            } else {
                format!("<collision>{geometry}</collision>")
            }
        };
        for k in 0..=6 {
            text += &format!(
                "<link name=\"l{k}\">{}</link>\n",
                element("<geometry><cylinder radius=\"0.04\" length=\"0.1\"/></geometry>")
            );
        }
        for k in 1..=6 {
            let turn = if k % 2 == 0 {
                "1.5707963"
            } else {
                "-1.5707963"
            };
            text += &format!(
                "<joint name=\"j{k}\" type=\"revolute\"><parent link=\"l{}\"/><child \
                 link=\"l{k}\"/><origin xyz=\"0 0 0.2\" rpy=\"{turn} 0 0\"/><axis xyz=\"0 0 1\"/>\
                 <limit lower=\"-2.8\" upper=\"2.8\" effort=\"1\" velocity=\"2\"/></joint>\n",
                k - 1
            );
        }
        for (parent, child, kind, xyz, geometry) in extra {
            text += &format!(
                "<link name=\"{child}\">{}</link>\n<joint name=\"{parent}_{child}\" \
                 type=\"{kind}\"><parent link=\"{parent}\"/><child link=\"{child}\"/><origin \
                 xyz=\"{xyz}\"/><axis xyz=\"0 1 0\"/><limit lower=\"0\" upper=\"0.04\" \
                 effort=\"1\" velocity=\"1\"/></joint>\n",
                element(geometry)
            );
        }
        text + "</robot>\n"
    }

    fn import(text: &str, tool: Option<&str>, pen_length_m: Option<f64>) -> ImportedRobot {
        let options = ImportOptions {
            tool_link: tool.map(str::to_string),
            pen_length_m,
            ..ImportOptions::default()
        };
        import_text(text, Path::new("."), &options).expect("imports")
    }

    /// The z of the pen's tip in the tool link's frame, as written.
    fn written_pen_length(imported: &ImportedRobot) -> f64 {
        let robot = urdf_rs::read_from_string(&imported.urdf).unwrap();
        let joint = robot
            .joints
            .iter()
            .find(|j| j.child.link == PEN_LINK)
            .unwrap();
        assert_eq!(joint.parent.link, imported.tool_link);
        joint.origin.xyz.0[2]
    }

    /// A UR-like end: `ee_link` (a small box behind `tool0`), `base` and `tool0` are leaves.
    const UR_LEAVES: [(&str, &str, &str, &str, &str); 3] = [
        (
            "l6",
            "ee_link",
            "fixed",
            "0 0 0.1",
            "<origin xyz=\"0 0 -0.02\"/><geometry><box size=\"0.01 0.01 0.01\"/></geometry>",
        ),
        ("l0", "base", "fixed", "0 0 0", ""),
        ("l6", "tool0", "fixed", "0 0 0.1", ""),
    ];

    #[test]
    fn of_several_leaves_tool0_is_the_tool_link_else_flange() {
        let imported = import(&arm(&UR_LEAVES), None, None);
        assert_eq!(imported.tool_link, "tool0");
        assert_eq!(
            imported.tool_link_choice,
            ToolLinkChoice::Rep199 {
                leaves: vec!["ee_link".into(), "base".into(), "tool0".into()]
            }
        );
        // REP 199's chain flange → tool0: tool0 is still the tool link.
        let flange_tool0 = [
            ("l6", "flange", "fixed", "0 0 0.08", ""),
            ("flange", "tool0", "fixed", "0 0 0", ""),
            ("l0", "base", "fixed", "0 0 0", ""),
        ];
        assert_eq!(import(&arm(&flange_tool0), None, None).tool_link, "tool0");
        // Without tool0, flange.
        let flange = [
            ("l6", "flange", "fixed", "0 0 0.08", ""),
            ("l0", "base", "fixed", "0 0 0", ""),
        ];
        let imported = import(&arm(&flange), None, None);
        assert_eq!(imported.tool_link, "flange");
        assert!(matches!(
            imported.tool_link_choice,
            ToolLinkChoice::Rep199 { .. }
        ));
        // A named link is taken as it is, an only leaf as before.
        let named = import(&arm(&UR_LEAVES), Some("ee_link"), None);
        assert_eq!(
            (named.tool_link.as_str(), named.tool_link_choice),
            ("ee_link", ToolLinkChoice::Named)
        );
        let only = import(&arm(&[]), None, None);
        assert_eq!(
            (only.tool_link.as_str(), only.tool_link_choice),
            ("l6", ToolLinkChoice::OnlyLeaf)
        );
        // Neither: the leaves are listed, as before.
        let neither = [
            ("l6", "ee_link", "fixed", "0 0 0.08", ""),
            ("l0", "base", "fixed", "0 0 0", ""),
        ];
        let options = ImportOptions::default();
        let error = import_text(&arm(&neither), Path::new("."), &options)
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("leaf links [ee_link, base]") && error.contains("--tool-link"),
            "{error}"
        );
        // A named link that is not there is refused, not replaced by tool0.
        let options = ImportOptions {
            tool_link: Some("hand".into()),
            ..ImportOptions::default()
        };
        let error = import_text(&arm(&UR_LEAVES), Path::new("."), &options)
            .unwrap_err()
            .to_string();
        assert!(error.contains("tool link 'hand' is not in"), "{error}");
    }

    /// A hand fixed 0.05 m past `l6` (a box 0.06 m deep, 0.16 m wide), with two fingers on
    /// prismatic joints reaching 0.11 m ahead of the hand's origin.
    const HAND: [(&str, &str, &str, &str, &str); 3] = [
        (
            "l6",
            "hand",
            "fixed",
            "0 0 0.05",
            "<origin xyz=\"0 0 0.03\"/><geometry><box size=\"0.04 0.16 0.06\"/></geometry>",
        ),
        (
            "hand",
            "left",
            "prismatic",
            "0 0.01 0.06",
            "<origin xyz=\"0 0 0.025\"/><geometry><box size=\"0.02 0.02 0.05\"/></geometry>",
        ),
        (
            "hand",
            "right",
            "prismatic",
            "0 -0.01 0.06",
            "<origin xyz=\"0 0 0.025\"/><geometry><box size=\"0.02 0.02 0.05\"/></geometry>",
        ),
    ];

    #[test]
    fn the_default_pen_reaches_beyond_the_hand_and_its_fingers() {
        let imported = import(&arm(&HAND), Some("hand"), None);
        let reach = &imported.tool_reach;
        // The fingers' tips lie 0.11 m ahead; the capsules around them reach a little further.
        assert!((reach.reach_m - 0.11).abs() < 1e-12, "{reach:?}");
        assert!(
            reach.capsule_reach_m >= reach.reach_m && reach.capsule_reach_m < 0.16,
            "{reach:?}"
        );
        assert_eq!(reach.links, ["hand", "left", "right", "l6"]);
        assert!(!imported.pen_length_given);
        assert!((imported.pen.length_m - (0.11 + PEN_PROTRUSION_M)).abs() < 1e-12);
        assert!((written_pen_length(&imported) - imported.pen.length_m).abs() < 1e-12);
        assert!(imported.pen_protrudes() && imported.pen_clears_capsules());
        // The fingers count although their joints move: without them, the palm's 0.06 m.
        let palm = import(&arm(&HAND[..1]), Some("hand"), None);
        assert!((palm.tool_reach.reach_m - 0.06).abs() < 1e-12);
        assert!((palm.pen.length_m - 0.16).abs() < 1e-12);
    }

    #[test]
    fn a_link_fixed_above_the_tool_link_counts_and_a_given_pen_is_checked() {
        // tool0 holds nothing, but l6's cylinder (0.05 m half length) lies 0.02 m ahead of it.
        let tool0 = [("l6", "tool0", "fixed", "0 0 0.03", "")];
        let imported = import(&arm(&tool0), None, None);
        assert_eq!(imported.tool_reach.links, ["tool0", "l6"]);
        let reach = imported.tool_reach.reach_m;
        assert!((reach - 0.02).abs() < 1e-12, "{reach}");
        assert!((imported.pen.length_m - (reach + PEN_PROTRUSION_M)).abs() < 1e-12);
        // A pen given too short is kept, and said not to protrude.
        let short = import(&arm(&tool0), None, Some(0.01));
        assert!(short.pen_length_given);
        assert_eq!(short.pen.length_m, 0.01);
        assert_eq!(written_pen_length(&short), 0.01);
        assert!(!short.pen_protrudes() && !short.pen_clears_capsules());
        // Beyond the cylinder but inside the capsule's cap around it.
        let capsule = imported.tool_reach.capsule_reach_m;
        assert!(capsule > reach + 0.01, "{capsule}");
        let within = import(&arm(&tool0), None, Some(reach + 0.005));
        assert!(within.pen_protrudes() && !within.pen_clears_capsules());
        let beyond = import(&arm(&tool0), None, Some(capsule + 0.001));
        assert!(beyond.pen_protrudes() && beyond.pen_clears_capsules());
    }

    #[test]
    fn with_nothing_ahead_of_the_tool_link_the_pen_stays_0_1_m() {
        // UR-like: tool0 0.1 m past l6, whose cylinder ends 0.05 m past it, ee_link's box
        // 0.015 m behind tool0.
        let imported = import(&arm(&UR_LEAVES), None, None);
        let reach = &imported.tool_reach;
        assert!((reach.reach_m + 0.015).abs() < 1e-12, "{reach:?}");
        assert_eq!(reach.links, ["tool0", "l6", "ee_link"]);
        assert_eq!(imported.pen.length_m, Pen::default().length_m);
        assert_eq!(written_pen_length(&imported), 0.1);
        // A flange face drawn half a millimetre ahead of the origin counts as at it.
        let face = [("l6", "tool0", "fixed", "0 0 0.0495", "")];
        let imported = import(&arm(&face), None, None);
        assert!((imported.tool_reach.reach_m - 0.0005).abs() < 1e-12);
        assert_eq!(imported.pen.length_m, 0.1);
        // No geometry at all on the tool's rigid body (a seventh joint leads to it).
        let bare = [("l6", "tool", "revolute", "0 0 0.08", "")];
        let imported = import(&arm(&bare), None, None);
        assert_eq!(imported.tool_reach.reach_m, f64::NEG_INFINITY);
        assert_eq!(imported.tool_reach.capsule_reach_m, f64::NEG_INFINITY);
        assert_eq!(imported.tool_reach.links, ["tool"]);
        assert_eq!(imported.pen.length_m, 0.1);
    }
}
