//! The shipped data inside every binary that links the planner: the shipped robots' files,
//! joint limits and trained models are compiled in, so an installed `emg` or a wheel plans
//! wherever it is copied, without the checkout it was built from. On first use they are written to a directory of the user's cache named by the
//! package version and a hash of the contents (each file written whole, so processes that start
//! at once agree), and planned from there like any data directory.

use std::path::PathBuf;

use crate::shipped::DataDir;

/// `(path, contents)` of the file at `path` in the workspace's `data/` directory.
macro_rules! shipped {
    ($path:literal) => {
        (
            $path,
            include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/", $path)),
        )
    };
}

/// Every shipped file the package plans with, by its path inside the data directory.
const FILES: &[(&str, &[u8])] = &[
    shipped!("robots/fr3_pen.urdf"),
    shipped!("robots/fr3_pen.joint_limits.yaml"),
    shipped!("robots/iiwa14_pen.urdf"),
    shipped!("robots/iiwa14_pen.joint_limits.yaml"),
    shipped!("models/diffusion-v1.weights"),
    shipped!("models/ppo-v1.weights"),
    shipped!("iiwa14/models/diffusion-v1.weights"),
    shipped!("iiwa14/models/ppo-v1.weights"),
    shipped!("robots/ur5e_pen.urdf"),
    shipped!("robots/ur5e_pen.joint_limits.yaml"),
    shipped!("ur5e/models/diffusion-v1.weights"),
    shipped!("ur5e/models/ppo-v1.weights"),
];

/// The directory holding the compiled-in data, written there on first use:
/// `<cache>/extreme-line-motion/<version>-<hash>/`, the cache being `$XDG_CACHE_HOME`, else
/// `~/.cache`, else the system's temporary directory.
pub fn extracted() -> std::io::Result<DataDir> {
    let dir = cache_root().join("extreme-line-motion").join(format!(
        "{}-{:016x}",
        env!("CARGO_PKG_VERSION"),
        contents_hash()
    ));
    for (path, contents) in FILES {
        let file = dir.join(path);
        let whole = std::fs::metadata(&file).is_ok_and(|m| m.len() == contents.len() as u64);
        if !whole {
            emg_io::write_atomically(&file, contents)?;
        }
    }
    Ok(DataDir::new(dir))
}

/// Where per-user caches live.
fn cache_root() -> PathBuf {
    let var = |name: &str| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("XDG_CACHE_HOME")
        .or_else(|| var("HOME").map(|home| home.join(".cache")))
        .unwrap_or_else(std::env::temp_dir)
}

/// FNV-1a over every file's path and contents: another build's data get another directory.
fn contents_hash() -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    FILES
        .iter()
        .flat_map(|(path, contents)| path.as_bytes().iter().chain(contents.iter()))
        .fold(0xcbf2_9ce4_8422_2325, |hash, byte| {
            (hash ^ u64::from(*byte)).wrapping_mul(PRIME)
        })
}
