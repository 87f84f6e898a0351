//! How a written file names the robot its motion was planned for: the `robot` field of
//! `emg-trajectory/1`, `emg-joint-trajectory/2` and `emg-job/3` files, and the robot an export's
//! metadata and headers name.
//!
//! A shipped robot is recorded by its name and the SHA-256 digest of its shipped file
//! (`shipped:fr3@sha256:…`), any other robot file by its path as given and the digest of its
//! content (`file:arms/my_arm.urdf@sha256:…`). A file is so read back from any directory and
//! after the checkout moves, and refused when the robot found there is not the one it was
//! planned for. Files written before references name the robot file by its path alone, and are
//! read as before. The layout is documented in `docs/joint-trajectory-format.md`.

use std::fmt;
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use crate::error::{FormatError, field_error};

/// What comes between a reference's robot and its digest.
const DIGEST_SEPARATOR: &str = "@sha256:";
/// The prefix of a shipped robot's reference.
const SHIPPED_PREFIX: &str = "shipped:";
/// The prefix of any other robot file's reference.
const FILE_PREFIX: &str = "file:";
/// Hexadecimal digits of a SHA-256 digest.
const DIGEST_DIGITS: usize = 64;

/// The robot a written file names (its `robot` field).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RobotRef {
    /// A shipped robot (`shipped:NAME@sha256:HEX`), found through the shipped data.
    Shipped {
        /// The robot's name (`fr3`, `iiwa14`, `ur5e`).
        name: String,
        /// The SHA-256 digest of its shipped robot file, 64 lowercase hexadecimal digits.
        sha256: String,
    },
    /// Any other robot file (`file:PATH@sha256:HEX`), found at its path as given: relative to
    /// the working directory, else to the directory of the file that names it.
    File {
        /// The path as given to the planner.
        path: String,
        /// The SHA-256 digest of the robot file, 64 lowercase hexadecimal digits.
        sha256: String,
    },
    /// A file written before references: the robot file's path as recorded, no digest.
    Path(String),
}

/// Why the robot a file names cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum RobotRefError {
    /// The file names a shipped robot this build does not ship.
    #[error(
        "field 'robot' of {file} names the shipped robot '{name}', which is not shipped here; \
         pass the robot file it was planned for (--robot, or Python's robot=)"
    )]
    UnknownShipped {
        /// The file naming it.
        file: PathBuf,
        /// The name.
        name: String,
    },
    /// The robot file is in none of the places it is looked for.
    #[error(
        "field 'robot' of {file} names the robot file {path}, which is not a file here (looked \
         for {looked}); pass the robot file it was planned for (--robot, or Python's robot=)"
    )]
    Missing {
        /// The file naming it.
        file: PathBuf,
        /// The path as recorded.
        path: String,
        /// The places looked at, in words.
        looked: String,
    },
    /// The robot file found is not the one the motion was planned for.
    #[error(
        "field 'robot' of {file} names {reference}, planned with a robot file of sha256 \
         {recorded}, but {found} has sha256 {actual}: the robot has changed since; plan the \
         motion again with this robot, or pass the robot file it was planned for (--robot, or \
         Python's robot=)"
    )]
    Digest {
        /// The file naming it.
        file: PathBuf,
        /// The reference, as recorded.
        reference: String,
        /// The digest recorded.
        recorded: String,
        /// The robot file found.
        found: PathBuf,
        /// Its digest.
        actual: String,
    },
    /// The robot file found cannot be read.
    #[error("cannot read the robot file {path}: {source}")]
    Read {
        /// The robot file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
}

impl RobotRef {
    /// The reference of the shipped robot `name`, whose robot file is `file`.
    pub fn shipped(name: &str, file: &Path) -> Result<Self, RobotRefError> {
        Ok(Self::Shipped {
            name: name.to_string(),
            sha256: file_sha256(file)?,
        })
    }

    /// The reference of the robot file at `path`, recorded as given.
    pub fn file(path: &Path) -> Result<Self, RobotRefError> {
        Ok(Self::File {
            path: path.display().to_string(),
            sha256: file_sha256(path)?,
        })
    }

    /// Reads a file's `robot` field: a reference, or (any other string) a robot file's path as
    /// files written before references recorded it. The error names the field.
    pub fn parse(field: &str) -> Result<Self, FormatError> {
        let prefixed = [(SHIPPED_PREFIX, true), (FILE_PREFIX, false)]
            .into_iter()
            .find_map(|(prefix, shipped)| Some((field.strip_prefix(prefix)?, shipped)));
        let Some((rest, shipped)) = prefixed else {
            if field.is_empty() {
                return Err(field_error("robot", "is empty, expected a robot"));
            }
            return Ok(Self::Path(field.to_string()));
        };
        let malformed = || {
            field_error(
                "robot",
                format!(
                    "is {field:?}, expected {SHIPPED_PREFIX}NAME{DIGEST_SEPARATOR}HEX or \
                     {FILE_PREFIX}PATH{DIGEST_SEPARATOR}HEX ({DIGEST_DIGITS} lowercase \
                     hexadecimal digits)"
                ),
            )
        };
        let (robot, sha256) = rest.rsplit_once(DIGEST_SEPARATOR).ok_or_else(malformed)?;
        let digest_ok = sha256.len() == DIGEST_DIGITS
            && sha256
                .bytes()
                .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b));
        if robot.is_empty() || !digest_ok {
            return Err(malformed());
        }
        let (robot, sha256) = (robot.to_string(), sha256.to_string());
        Ok(if shipped {
            Self::Shipped {
                name: robot,
                sha256,
            }
        } else {
            Self::File {
                path: robot,
                sha256,
            }
        })
    }

    /// The digest recorded, `None` for a path alone.
    pub fn sha256(&self) -> Option<&str> {
        match self {
            Self::Shipped { sha256, .. } | Self::File { sha256, .. } => Some(sha256),
            Self::Path(_) => None,
        }
    }

    /// The robot file this reference names, as read back by `file` (the file holding the
    /// reference): a shipped robot's through `shipped` (its file by name, `None` when not
    /// shipped), a path relative to the working directory, else to `file`'s directory (a path
    /// alone is taken as it is). Refused when the file found is not the one recorded.
    pub fn resolve(
        &self,
        shipped: impl Fn(&str) -> Option<PathBuf>,
        file: &Path,
    ) -> Result<PathBuf, RobotRefError> {
        let found = match self {
            Self::Shipped { name, .. } => {
                shipped(name).ok_or_else(|| RobotRefError::UnknownShipped {
                    file: file.to_path_buf(),
                    name: name.clone(),
                })?
            }
            Self::File { path, .. } => {
                let given = PathBuf::from(path);
                let beside = file.parent().map(|dir| dir.join(&given));
                let candidates: Vec<PathBuf> = std::iter::once(given.clone())
                    .chain(beside.filter(|_| given.is_relative()))
                    .collect();
                match candidates.iter().find(|c| c.is_file()) {
                    Some(found) => found.clone(),
                    None => {
                        return Err(RobotRefError::Missing {
                            file: file.to_path_buf(),
                            path: path.clone(),
                            looked: candidates
                                .iter()
                                .map(|c| c.display().to_string())
                                .collect::<Vec<_>>()
                                .join(" and "),
                        });
                    }
                }
            }
            Self::Path(path) => {
                let given = PathBuf::from(path);
                if !given.is_file() {
                    return Err(RobotRefError::Missing {
                        file: file.to_path_buf(),
                        path: path.clone(),
                        looked: path.clone(),
                    });
                }
                given
            }
        };
        if let Some(recorded) = self.sha256() {
            let actual = file_sha256(&found)?;
            if actual != recorded {
                return Err(RobotRefError::Digest {
                    file: file.to_path_buf(),
                    reference: self.to_string(),
                    recorded: recorded.to_string(),
                    found,
                    actual,
                });
            }
        }
        Ok(found)
    }
}

/// The reference as a file records it in its `robot` field.
impl fmt::Display for RobotRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Shipped { name, sha256 } => {
                write!(f, "{SHIPPED_PREFIX}{name}{DIGEST_SEPARATOR}{sha256}")
            }
            Self::File { path, sha256 } => {
                write!(f, "{FILE_PREFIX}{path}{DIGEST_SEPARATOR}{sha256}")
            }
            Self::Path(path) => f.write_str(path),
        }
    }
}

/// The SHA-256 digest of the file at `path`, as 64 lowercase hexadecimal digits.
pub fn file_sha256(path: &Path) -> Result<String, RobotRefError> {
    let bytes = std::fs::read(path).map_err(|source| RobotRefError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(Sha256::digest(&bytes)
        .iter()
        .map(|byte| format!("{byte:02x}"))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    const DIGEST: &str = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";

    #[test]
    fn references_read_back_as_written() {
        for reference in [
            RobotRef::Shipped {
                name: "fr3".into(),
                sha256: DIGEST.into(),
            },
            RobotRef::File {
                path: "arms/my@arm.urdf".into(),
                sha256: DIGEST.into(),
            },
            RobotRef::Path("/old/checkout/data/robots/fr3_pen.urdf".into()),
        ] {
            assert_eq!(RobotRef::parse(&reference.to_string()).unwrap(), reference);
        }
        assert_eq!(
            RobotRef::parse(&format!("shipped:ur5e@sha256:{DIGEST}"))
                .unwrap()
                .sha256(),
            Some(DIGEST)
        );
    }

    #[test]
    fn malformed_references_are_refused_naming_the_field() {
        for field in [
            "",
            "shipped:fr3",
            "shipped:@sha256:0123",
            &format!("file:@sha256:{DIGEST}"),
            &format!("shipped:fr3@sha256:{}", DIGEST.to_uppercase()),
            &format!("file:x.urdf@sha256:{}", &DIGEST[1..]),
        ] {
            let error = RobotRef::parse(field).unwrap_err().to_string();
            assert!(error.starts_with("field 'robot'"), "{field:?}: {error}");
        }
    }

    #[test]
    fn a_file_is_found_beside_the_file_naming_it_and_refused_when_changed() {
        let dir = tempfile::tempdir().unwrap();
        let robot = dir.path().join("arm.urdf");
        std::fs::write(&robot, "<robot name='arm'/>").unwrap();
        let reference = RobotRef::File {
            path: "arm.urdf".into(),
            sha256: file_sha256(&robot).unwrap(),
        };
        let program = dir.path().join("program.json");
        let none = |_: &str| None;
        assert_eq!(reference.resolve(none, &program).unwrap(), robot);
        std::fs::write(&robot, "<robot name='other'/>").unwrap();
        let error = reference.resolve(none, &program).unwrap_err().to_string();
        assert!(
            error.contains(reference.sha256().unwrap()) && error.contains("field 'robot'"),
            "{error}"
        );
        let elsewhere = Path::new("/nonexistent/program.json");
        let error = reference.resolve(none, elsewhere).unwrap_err().to_string();
        assert!(error.contains("/nonexistent/arm.urdf"), "{error}");
        let shipped = RobotRef::Shipped {
            name: "arm".into(),
            sha256: file_sha256(&robot).unwrap(),
        };
        assert_eq!(
            shipped.resolve(|_| Some(robot.clone()), &program).unwrap(),
            robot
        );
        assert!(matches!(
            shipped.resolve(none, &program),
            Err(RobotRefError::UnknownShipped { .. })
        ));
    }
}
