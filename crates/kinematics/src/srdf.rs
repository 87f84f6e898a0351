//! Which capsule pairs a robot checks for self-collision: the shipped robots' link-separation
//! rule, or every pair but those an SRDF file beside the robot file disables.

use std::path::{Path, PathBuf};

use crate::error::{RobotError, read_text};

/// Smallest chain-index separation of two bodies whose capsules are checked against each other
/// under [`PairRule::LinkSeparation`] (adjacent links always touch at their joint).
pub const MIN_LINK_SEPARATION: usize = 3;

/// Which capsule pairs are checked for self-collision; bodies that do not move relative to each
/// other (no joint turns between them) are never checked.
#[derive(Clone, Debug, PartialEq)]
pub enum PairRule {
    /// Bodies at least [`MIN_LINK_SEPARATION`] links apart (the shipped robots).
    LinkSeparation,
    /// Every two bodies except the link pairs listed (an SRDF file's `disable_collisions`).
    AllExcept(Vec<(String, String)>),
}

impl PairRule {
    /// The rule of the robot file at `urdf`: [`PairRule::AllExcept`] the pairs of the SRDF file
    /// beside it (same stem, `.srdf`) when there is one, else [`PairRule::LinkSeparation`].
    pub fn for_robot_file(urdf: &Path) -> Result<Self, RobotError> {
        let srdf = srdf_beside(urdf);
        if !srdf.is_file() {
            return Ok(Self::LinkSeparation);
        }
        let text = read_text(&srdf)?;
        disabled_pairs(&text)
            .map(Self::AllExcept)
            .map_err(|problem| RobotError::Srdf {
                path: srdf.display().to_string(),
                problem,
            })
    }

    /// Whether capsules of links `a` and `b` (chain indices `ia`, `ib`) are checked.
    pub fn checks(&self, a: &str, ia: usize, b: &str, ib: usize) -> bool {
        match self {
            Self::LinkSeparation => ia.abs_diff(ib) >= MIN_LINK_SEPARATION,
            Self::AllExcept(pairs) => !pairs
                .iter()
                .any(|(x, y)| (x == a && y == b) || (x == b && y == a)),
        }
    }
}

/// The SRDF file that goes with the robot file at `urdf`: same directory and stem, `.srdf`.
pub fn srdf_beside(urdf: &Path) -> PathBuf {
    urdf.with_extension("srdf")
}

/// The link pairs of an SRDF document's `<disable_collisions link1=".." link2=".."/>` elements.
pub fn disabled_pairs(text: &str) -> Result<Vec<(String, String)>, String> {
    let document = roxmltree::Document::parse(text).map_err(|e| e.to_string())?;
    document
        .descendants()
        .filter(|node| node.has_tag_name("disable_collisions"))
        .map(|node| {
            let link = |name: &str| {
                node.attribute(name).map(str::to_string).ok_or_else(|| {
                    format!(
                        "a disable_collisions element at byte {} has no '{name}'",
                        node.range().start
                    )
                })
            };
            Ok((link("link1")?, link("link2")?))
        })
        .collect()
}
