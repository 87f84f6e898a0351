//! Why a robot file could not be read.

use crate::capsule::MAX_CAPSULES;
use crate::vectors::{MAX_DOF, MIN_DOF};

/// Why a robot file could not be turned into a [`Robot`](crate::Robot).
#[derive(Debug, thiserror::Error)]
pub enum RobotError {
    /// The file could not be read from disk.
    #[error("cannot read robot file {path}: {source}")]
    Io {
        /// File that was asked for.
        path: String,
        /// Underlying I/O error.
        source: std::io::Error,
    },
    /// The text is not well-formed URDF.
    #[error("malformed URDF: {0}")]
    Malformed(String),
    /// A link named as the chain's base or tip does not exist.
    #[error("{role} link '{name}' is not in the robot file (links: {available})")]
    MissingLink {
        /// `"base"`, `"tip"`, or `"joint parent"` for a link a joint of the chain names.
        role: &'static str,
        /// Requested link name.
        name: String,
        /// Comma-separated names the file does define.
        available: String,
    },
    /// The tip link is not a descendant of the base link.
    #[error("tip link '{tip}' is not below base link '{base}' in the kinematic tree")]
    NotAChain {
        /// Base link name.
        base: String,
        /// Tip link name.
        tip: String,
    },
    /// A link inside the chain has more than one child joint.
    #[error(
        "link '{link}' branches into {count} child joints ({joints}); a serial chain is required"
    )]
    Branching {
        /// The branching link.
        link: String,
        /// How many child joints it has.
        count: usize,
        /// Their names.
        joints: String,
    },
    /// A joint of the chain is neither revolute (or continuous) nor fixed.
    #[error("joint '{joint}' is {kind}; only revolute, continuous and fixed joints are supported")]
    UnsupportedJoint {
        /// Joint name.
        joint: String,
        /// Its URDF type.
        kind: String,
    },
    /// The file's links do not form one unbranched chain, so its base and tip must be named.
    #[error(
        "cannot tell the chain's ends: the file has root links [{roots}] and leaf links [{leaves}]; name the base and tip links"
    )]
    AmbiguousChain {
        /// Links that are no joint's child.
        roots: String,
        /// Links that are no joint's parent.
        leaves: String,
    },
    /// The chain has fewer than [`MIN_DOF`] or more than [`MAX_DOF`] revolute joints.
    #[error(
        "the chain from '{base}' to '{tip}' has {found} revolute joints; arms of {MIN_DOF} or \
         {MAX_DOF} are supported ({reason})"
    )]
    WrongDof {
        /// Base link name.
        base: String,
        /// Tip link name.
        tip: String,
        /// Revolute joints found.
        found: usize,
        /// Why that count cannot be planned.
        reason: &'static str,
    },
    /// A joint has an unusable axis, limit or velocity limit.
    #[error("joint '{joint}': {field} {problem}")]
    BadJoint {
        /// Joint name.
        joint: String,
        /// Offending field (`origin`, `axis`, `limit`, `velocity`).
        field: &'static str,
        /// What is wrong with it.
        problem: String,
    },
    /// A collision element has a position, a radius or a length that is not a usable number.
    #[error("link '{link}': collision {field} {problem}")]
    BadGeometry {
        /// Link carrying the geometry.
        link: String,
        /// Offending field (`origin`, `radius`, `length`).
        field: &'static str,
        /// What is wrong with it.
        problem: String,
    },
    /// The chain carries more collision capsules than a check places on the stack.
    #[error("the chain has {found} collision capsules; at most {MAX_CAPSULES} are supported")]
    TooManyCapsules {
        /// Capsules found along the chain.
        found: usize,
    },
    /// A `<cylinder>` lacks a sphere of its radius on one of its ends.
    #[error(
        "link '{link}': a collision cylinder needs a sphere of its radius on each end (a capsule \
         is written as a cylinder plus two sphere caps)"
    )]
    UncappedCylinder {
        /// Link carrying the cylinder.
        link: String,
    },
    /// The SRDF file beside the robot file cannot be read.
    #[error("SRDF file {path}: {problem}")]
    Srdf {
        /// The file.
        path: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A collision element uses geometry other than a capsule, a capped cylinder or a sphere.
    #[error(
        "link '{link}': collision geometry {kind} is not supported; use a cylinder with a \
         sphere cap on each end, a <capsule> or a <sphere>"
    )]
    UnsupportedGeometry {
        /// Link carrying the geometry.
        link: String,
        /// Geometry kind found.
        kind: &'static str,
    },
}

/// The text of the file at `path` (a robot file or the SRDF file beside it); a failure to
/// read it is a [`RobotError::Io`] naming the file.
pub(crate) fn read_text(path: &std::path::Path) -> Result<String, RobotError> {
    std::fs::read_to_string(path).map_err(|source| RobotError::Io {
        path: path.display().to_string(),
        source,
    })
}
