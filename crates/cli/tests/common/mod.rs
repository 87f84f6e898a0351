//! Helpers shared by the end-to-end tests of the `emg` binary: fresh temp directories, running
//! the binary, and reading what it wrote.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;
use tempfile::TempDir;

/// A weights path that does not exist: the default seed chain then skips the DP seed.
pub const NO_WEIGHTS: &str = "/nonexistent/diffusion.weights";

/// A fresh, empty directory under the system temp dir, removed when dropped.
pub fn temp_dir(name: &str) -> TempDir {
    tempfile::Builder::new()
        .prefix(&format!("emg-cli-{name}-"))
        .tempdir()
        .expect("create temp dir")
}

/// Runs the built `emg` binary with `args`.
pub fn emg(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_emg"))
        .args(args)
        .output()
        .expect("run emg")
}

/// Bytes of a captured stream as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A file's text; panics naming the file.
pub fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A JSON file's contents.
pub fn read_json(path: &Path) -> Value {
    serde_json::from_str(&read(path)).expect("valid JSON")
}

/// A task (JSON, as in a task file) from configuration `q`: `p0` = its TCP, `n` = its tool axis,
/// `d` = +y made perpendicular to `n`, and `q0_seed` = `q`.
pub fn task_json(robot: &emg_kinematics::Robot, q: &emg_kinematics::JointVector) -> Value {
    let kin = robot.forward(q);
    let n = kin.tool_axis();
    let y = emg_kinematics::Vec3::y();
    let d = (y - n * y.dot(&n)).normalize();
    serde_json::json!({
        "p0": kin.tcp().as_slice(), "d": d.as_slice(), "n": n.as_slice(), "q0_seed": q.as_slice(),
    })
}

/// The workspace's shipped data directory.
pub fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

/// The shipped FR3 robot file.
pub fn fr3_path() -> std::path::PathBuf {
    data_dir().join("robots/fr3_pen.urdf")
}

/// A drawing of `../shared/cases/`.
pub fn case(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/cases")
        .join(name)
}

/// `text` with its line `line` (1-based) passed through `edit`, each line ended by a newline.
pub fn with_line(text: &str, line: usize, edit: impl Fn(&str) -> String) -> String {
    text.lines()
        .enumerate()
        .map(|(k, l)| {
            if k + 1 == line {
                edit(l)
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

/// The 1-based number of the first line of `text` that `is` says is it.
pub fn line_of(text: &str, is: impl Fn(&str) -> bool) -> usize {
    text.lines().position(is).expect("the line is there") + 1
}

/// `drawing` planned by `emg job ... --robot ROBOT --export FORMAT` (with `extra` arguments)
/// into `out` (the job's program); its plan, once `emg job` has succeeded.
pub fn job_exported(
    drawing: &Path,
    (robot, format): (&str, &str),
    out: &Path,
    extra: &[&str],
) -> emg_job::JobFile {
    let mut args = vec![
        "job",
        drawing.to_str().expect("utf-8 path"),
        "--robot",
        robot,
        "--out",
        out.to_str().expect("utf-8 path"),
        "--export",
        format,
    ];
    args.extend_from_slice(extra);
    let run = emg(&args);
    assert!(
        run.status.success(),
        "emg job failed:\n{}\n{}",
        text(&run.stdout),
        text(&run.stderr)
    );
    emg_job::JobFile::parse(&read(out)).expect("the plan parses")
}

/// `emg job --export FORMAT` on each of `robots` fails before anything is planned or written,
/// naming the format.
pub fn assert_export_refused_before_planning(format: &str, robots: &[&str]) {
    let dir = temp_dir(&format!("{format}-refused"));
    let out = dir.path().join("refused.job.json");
    for robot in robots {
        let run = emg(&[
            "job",
            case("pen-drag-house.svg").to_str().expect("utf-8 path"),
            "--robot",
            robot,
            "--out",
            out.to_str().expect("utf-8 path"),
            "--export",
            format,
        ]);
        assert_eq!(run.status.code(), Some(1), "{robot}");
        assert!(
            text(&run.stderr).contains(format),
            "{robot}: {}",
            text(&run.stderr)
        );
        assert!(!out.exists(), "{robot}: nothing is planned or written");
    }
}

/// `written` equals the file `tests/data/NAME` kept word for word; `EMG_WRITE_GOLDEN=1` writes
/// it again.
pub fn assert_golden(written: &str, name: &str) {
    let golden = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    if std::env::var_os("EMG_WRITE_GOLDEN").is_some() {
        std::fs::write(&golden, written).expect("golden written");
    }
    assert_eq!(
        written,
        read(&golden),
        "{} differs: if the change is meant, write it again with EMG_WRITE_GOLDEN=1",
        golden.display()
    );
}

/// A triangle drawing written into `dir`: the small job the golden programs are kept for.
pub fn triangle(dir: &Path) -> std::path::PathBuf {
    let drawing = dir.join("triangle.svg");
    std::fs::write(
        &drawing,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 10 10\">\
         <polygon fill=\"none\" stroke=\"black\" points=\"1,1 9,1 5,8\"/></svg>\n",
    )
    .expect("drawing written");
    drawing
}
