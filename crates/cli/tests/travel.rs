//! Files that travel: a program, a trajectory and their exports, written in one directory, name
//! their robot by reference (a shipped robot by name, an imported one by its path as given, each
//! with its file's digest) and no directory of this machine; they check and export from another
//! directory with the shipped data moved, and are refused when the robot found there differs.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{data_dir, read_json, temp_dir, text};

/// Runs `emg` in `dir` with `args`, the shipped data taken from `data` (`EMG_DATA`) when given,
/// else from the checkout.
fn emg_in(dir: &Path, data: Option<&Path>, args: &[&str]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_emg"));
    command.args(args).current_dir(dir).env_remove("EMG_DATA");
    if let Some(data) = data {
        command.env("EMG_DATA", data);
    }
    command.output().expect("run emg")
}

/// `output` succeeded; its stdout.
fn ok(output: &Output) -> String {
    assert!(
        output.status.success(),
        "{}\n{}",
        text(&output.stdout),
        text(&output.stderr)
    );
    text(&output.stdout)
}

/// `output` failed; its stderr.
fn refused(output: &Output) -> String {
    assert!(!output.status.success(), "{}", text(&output.stdout));
    text(&output.stderr)
}

fn seams() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/seams.json")
}

/// A copy of the shipped robots' files under `to/robots`: the shipped data, moved.
fn moved_data(to: &Path) -> PathBuf {
    let robots = to.join("robots");
    std::fs::create_dir_all(&robots).unwrap();
    for entry in std::fs::read_dir(data_dir().join("robots")).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), robots.join(entry.file_name())).unwrap();
    }
    to.to_path_buf()
}

/// The SHA-256 digest a reference records.
fn digest(reference: &str) -> &str {
    reference.rsplit_once("@sha256:").expect("a reference").1
}

/// Asserts that no file in `dir` holds any of `paths` (as text).
fn assert_names_none_of(dir: &Path, paths: &[&Path]) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let file = entry.unwrap().path();
        let bytes = std::fs::read(&file).unwrap();
        let content = String::from_utf8_lossy(&bytes);
        for path in paths {
            let path = path.to_str().unwrap();
            assert!(!content.contains(path), "{} names {path}", file.display());
        }
    }
}

#[test]
fn files_written_here_check_and_export_elsewhere_with_the_shipped_data_moved() {
    let written = temp_dir("travel-written");
    let seams = seams();
    let here = written.path();
    ok(&emg_in(
        here,
        None,
        &[
            "job",
            seams.to_str().unwrap(),
            "--out",
            "seams.job.json",
            "--html",
            "seams.html",
            "--export",
            "ros2-mcap",
        ],
    ));
    let line = [
        "--p0",
        "0.45,-0.2,0.25",
        "--d",
        "0,1,0",
        "--n",
        "0,0,-1",
        "--reach",
        "off",
    ];
    ok(&emg_in(
        here,
        None,
        &[
            &["plan", "--out", "line", "--export", "ros2-mcap"],
            &line[..],
        ]
        .concat(),
    ));
    ok(&emg_in(
        here,
        None,
        &[
            &[
                "plan",
                "--robot",
                "ur5e",
                "--out",
                "ur",
                "--export",
                "urscript",
                "--config",
                r#"{"rollout": {"max_steps": 20}}"#,
            ],
            &line[..],
        ]
        .concat(),
    ));
    let program = read_json(&here.join("seams.job.json"));
    let reference = program["robot"].as_str().unwrap();
    assert!(reference.starts_with("shipped:fr3@sha256:"), "{reference}");
    assert_eq!(
        read_json(&here.join("line.joint_trajectory.json"))["robot"],
        program["robot"]
    );
    let script = std::fs::read_to_string(here.join("ur.script")).unwrap();
    assert!(script.contains("robot shipped:ur5e@sha256:"), "{script}");
    let checkout = data_dir().join("..").canonicalize().unwrap();
    assert_names_none_of(here, &[&checkout, &here.canonicalize().unwrap()]);

    // Elsewhere: the files copied, the shipped data moved.
    let elsewhere = temp_dir("travel-elsewhere");
    let there = elsewhere.path();
    let moved = temp_dir("travel-data");
    let data = moved_data(moved.path());
    for name in ["seams.job.json", "line.joint_trajectory.json", "line.json"] {
        std::fs::copy(here.join(name), there.join(name)).unwrap();
    }
    drop(written);
    for file in ["seams.job.json", "line.joint_trajectory.json", "line.json"] {
        let stdout = ok(&emg_in(there, Some(&data), &["check", file]));
        assert!(stdout.ends_with("OK\n"), "{stdout}");
    }
    // From a third directory, by a path through the second.
    let third = temp_dir("travel-third");
    let program_there = there.join("seams.job.json");
    ok(&emg_in(
        third.path(),
        Some(&data),
        &["check", program_there.to_str().unwrap()],
    ));
    ok(&emg_in(
        there,
        Some(&data),
        &[
            "export",
            "seams.job.json",
            "--format",
            "ros2-mcap",
            "--out",
            "again.mcap",
        ],
    ));
    assert!(there.join("again.mcap").is_file());

    // A robot that changed since: refused, naming the field, both digests and what to do.
    let urdf = data.join("robots/fr3_pen.urdf");
    let mut changed = std::fs::read_to_string(&urdf).unwrap();
    changed.push_str("<!-- changed -->\n");
    std::fs::write(&urdf, changed).unwrap();
    for args in [
        &["check", "seams.job.json"][..],
        &["check", "line.joint_trajectory.json"][..],
        &[
            "export",
            "seams.job.json",
            "--format",
            "ros2-mcap",
            "--out",
            "changed.mcap",
        ][..],
    ] {
        let error = refused(&emg_in(there, Some(&data), args));
        let found = emg_io::file_sha256(&urdf).unwrap();
        assert!(
            error.contains("field 'robot'")
                && error.contains(digest(reference))
                && error.contains(&found)
                && error.contains("plan the motion again"),
            "{error}"
        );
    }
    assert!(!there.join("changed.mcap").exists());
    // --robot overrides the file's robot.
    ok(&emg_in(
        there,
        None,
        &["check", "seams.job.json", "--robot", "fr3"],
    ));
}

#[test]
fn an_imported_robot_is_found_by_its_path_as_given_and_old_files_by_their_path() {
    let dir = temp_dir("travel-imported");
    let here = dir.path();
    std::fs::create_dir(here.join("arms")).unwrap();
    for (from, to) in [
        ("fr3_pen.urdf", "arm.urdf"),
        ("fr3_pen.joint_limits.yaml", "arm.joint_limits.yaml"),
    ] {
        std::fs::copy(
            data_dir().join("robots").join(from),
            here.join("arms").join(to),
        )
        .unwrap();
    }
    let seams = seams();
    ok(&emg_in(
        here,
        None,
        &[
            "job",
            seams.to_str().unwrap(),
            "--robot",
            "arms/arm.urdf",
            "--out",
            "arm.job.json",
        ],
    ));
    let program = read_json(&here.join("arm.job.json"));
    let reference = program["robot"].as_str().unwrap();
    assert!(
        reference.starts_with("file:arms/arm.urdf@sha256:"),
        "{reference}"
    );
    // From another directory the path is found from the program's directory.
    let other = temp_dir("travel-other");
    let program_path = here.join("arm.job.json");
    ok(&emg_in(
        other.path(),
        None,
        &["check", program_path.to_str().unwrap()],
    ));
    // Not there: refused naming where it was looked for.
    std::fs::rename(here.join("arms"), here.join("moved")).unwrap();
    let error = refused(&emg_in(
        other.path(),
        None,
        &["check", program_path.to_str().unwrap()],
    ));
    assert!(
        error.contains("field 'robot'")
            && error.contains("arms/arm.urdf, which is not a file here"),
        "{error}"
    );

    // A file written before references names the robot file by its path: read as before.
    let mut old = program.clone();
    old["robot"] =
        serde_json::Value::String(here.join("moved/arm.urdf").to_str().unwrap().to_string());
    std::fs::write(here.join("old.job.json"), old.to_string()).unwrap();
    ok(&emg_in(
        other.path(),
        None,
        &["check", here.join("old.job.json").to_str().unwrap()],
    ));
}
