//! Paths and shared loading of the workspace's data.

use std::path::{Path, PathBuf};

use anyhow::Context;
use emg_control::ReferenceModel;
use emg_kinematics::Robot;

/// The workspace root (parent of `xtask/`).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives inside the workspace")
        .to_path_buf()
}

/// Path relative to the workspace root, for records that must not depend on the checkout place.
pub fn relative(path: &Path) -> String {
    let canonical = |p: &Path| p.canonicalize().unwrap_or_else(|_| p.to_path_buf());
    let (path, root) = (canonical(path), canonical(&root()));
    path.strip_prefix(&root)
        .unwrap_or(&path)
        .display()
        .to_string()
}

/// Loads a robot file whose links form one chain (base = its root link, tip = its leaf).
pub fn load_robot(path: &Path) -> anyhow::Result<Robot> {
    Robot::from_chain_file(path).with_context(|| format!("loading robot {}", path.display()))
}

/// The independent checker of `robot`, read again from its file.
pub fn load_checker(path: &Path, robot: &Robot) -> anyhow::Result<ReferenceModel> {
    ReferenceModel::from_urdf_file(path, robot.base_link(), robot.tip_link())
        .map_err(anyhow::Error::msg)
        .with_context(|| format!("loading the checker's model of {}", path.display()))
}

/// Builds a rayon pool with `threads` threads (0 = one per core).
pub fn thread_pool(threads: usize) -> anyhow::Result<rayon::ThreadPool> {
    Ok(rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?)
}

/// CPU model and core count of this machine.
pub fn machine() -> String {
    let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let model = cpuinfo
        .lines()
        .find_map(|l| {
            l.strip_prefix("model name")
                .map(|m| m.trim_start_matches([' ', '\t', ':']).to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    format!(
        "{model}, {} cores",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    )
}
