//! The shipped robot files are standard URDF: the reference C++ parser used by ROS, MoveIt and
//! Pinocchio (urdfdom, its `check_urdf` tool) reads every one of them without an error, and every
//! link of the file is in the tree it prints. Capsules are written as a cylinder plus two sphere
//! caps, which urdfdom reads and our loader turns back into one capsule.
//!
//! The tool is `$EMG_CHECK_URDF`, else `check_urdf` on `PATH` (Debian: `liburdfdom-tools`).
//! The test is ignored (with that reason) unless run with `cargo test -- --include-ignored`, as
//! `.ci/run` does after installing the tool; so run, without the tool it prints a notice and
//! passes, unless `EMG_REQUIRE_URDFDOM=1` (as in CI).

use std::path::PathBuf;
use std::process::Command;

fn check_urdf() -> Option<PathBuf> {
    let tool =
        std::env::var_os("EMG_CHECK_URDF").map_or_else(|| "check_urdf".into(), PathBuf::from);
    let found = Command::new(&tool).arg("--help").output().is_ok();
    if !found {
        assert!(
            std::env::var("EMG_REQUIRE_URDFDOM").as_deref() != Ok("1"),
            "EMG_REQUIRE_URDFDOM=1 but `{}` was not found: install urdfdom's tools (Debian: \
             liburdfdom-tools) or point EMG_CHECK_URDF at check_urdf",
            tool.display()
        );
        eprintln!(
            "notice: skipping the standard-parser check of the robot files: no `check_urdf` \
             (set EMG_REQUIRE_URDFDOM=1 to make this a failure)"
        );
    }
    found.then_some(tool)
}

fn shipped_robot_files() -> Vec<PathBuf> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("data/robots lists")
        .map(|entry| entry.expect("directory entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "urdf"))
        .collect();
    files.sort();
    files
}

#[test]
#[ignore = "needs urdfdom's `check_urdf` (Debian: liburdfdom-tools): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn urdfdom_reads_every_shipped_robot_file_whole() {
    let files = shipped_robot_files();
    assert!(files.len() >= 2, "found {files:?}");
    let Some(tool) = check_urdf() else {
        return;
    };
    for file in &files {
        let output = Command::new(&tool)
            .arg(file)
            .output()
            .expect("check_urdf runs");
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        );
        assert!(
            output.status.success() && text.contains("Successfully Parsed XML"),
            "{}: urdfdom refuses it:\n{text}",
            file.display()
        );
        assert!(
            !text.contains("Error"),
            "{}: urdfdom reports:\n{text}",
            file.display()
        );
        let source = std::fs::read_to_string(file).expect("robot file reads");
        let links = source.matches("<link ").count();
        let printed = text
            .lines()
            .filter(|line| {
                let line = line.trim_start();
                line.starts_with("root Link:") || line.starts_with("child(")
            })
            .count();
        assert_eq!(
            printed,
            links,
            "{}: links in urdfdom's tree:\n{text}",
            file.display()
        );
        assert!(
            !source.contains("<capsule"),
            "{}: <capsule> is not standard URDF; write a cylinder plus two sphere caps",
            file.display()
        );
    }
}
