//! `emg plan` stopped by SIGINT or SIGTERM in the middle of a task set: it exits with 128 + the
//! signal's number and says how far it got, every file it leaves is complete, and no `.partial`
//! file is left behind. `emg job` and `emg place` stopped while planning: the same exit, and
//! nothing written.

#![cfg(unix)]

mod common;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use emg_io::{TrajectoryContents, read_tasks, write_task_set};
use emg_kinematics::Robot;

use common::{data_dir, fr3_path, temp_dir, text};

/// Tasks in the set: far more than are planned before the signal arrives.
const TASKS: usize = 2000;

/// How long the first task may take to appear (a liveness bound, not a timing).
const FIRST_TASK_DEADLINE: Duration = Duration::from_secs(300);

fn interrupt_midway(signal: i32, name: &str) {
    let tmp = temp_dir("interrupt");
    let dir = tmp.path();
    let robot = Robot::from_chain_file(fr3_path()).expect("the FR3 loads");
    let tasks = read_tasks(&data_dir().join("tasks/eval-v1.tasks"), &robot).expect("tasks load");
    let task_file = dir.join("set.tasks");
    write_task_set(&task_file, &tasks[..TASKS]).expect("task set written");
    let out = dir.join("runs");
    let mut child = Command::new(env!("CARGO_BIN_EXE_emg"))
        .args(["plan", "--task-file"])
        .arg(&task_file)
        .args(["--seed", "generating", "--controller", "classical", "--out"])
        .arg(out.join("set"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("emg starts");

    let first = out.join("set-00000.joint_trajectory.json");
    let started = Instant::now();
    while !first.exists() {
        assert!(
            child.try_wait().expect("child status").is_none(),
            "emg ended before any task was written"
        );
        assert!(
            started.elapsed() < FIRST_TASK_DEADLINE,
            "no task written within {FIRST_TASK_DEADLINE:?}"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let pid = i32::try_from(child.id()).expect("pid fits");
    // SAFETY: `kill` only sends a signal to the child process started above.
    assert_eq!(unsafe { libc::kill(pid, signal) }, 0, "signal sent");
    let output = child.wait_with_output().expect("emg ends");
    let stderr = text(&output.stderr);
    assert_eq!(output.status.code(), Some(128 + signal), "{stderr}");
    assert!(stderr.contains(&format!("stopped by {name}")), "{stderr}");
    assert!(stderr.contains("planned and written whole"), "{stderr}");

    let planned = complete_tasks(&out);
    assert!(
        (1..TASKS).contains(&planned),
        "{planned} of {TASKS} tasks written: the signal should stop the run midway"
    );
    assert!(
        stderr.contains(&format!("{planned} of {TASKS} tasks")),
        "the message counts the tasks written ({planned}): {stderr}"
    );
}

/// Checks that `out` holds the three complete files of tasks 0..k and nothing else (no
/// `.partial`); returns k.
fn complete_tasks(out: &Path) -> usize {
    let mut names: Vec<String> = std::fs::read_dir(out)
        .expect("output directory")
        .map(|entry| {
            entry
                .expect("entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    names.sort();
    let partial: Vec<_> = names.iter().filter(|n| n.ends_with(".partial")).collect();
    assert!(partial.is_empty(), "left behind: {partial:?}");
    assert_eq!(names.len() % 3, 0, "three files per task: {names:?}");
    let planned = names.len() / 3;
    for index in 0..planned {
        for suffix in [".json", ".csv", ".joint_trajectory.json"] {
            let path = out.join(format!("set-{index:05}{suffix}"));
            TrajectoryContents::read(&path)
                .unwrap_or_else(|e| panic!("{} is not complete: {e:#}", path.display()));
        }
    }
    planned
}

#[test]
fn sigint_stops_after_the_current_task() {
    interrupt_midway(libc::SIGINT, "SIGINT");
}

#[test]
fn sigterm_stops_after_the_current_task() {
    interrupt_midway(libc::SIGTERM, "SIGTERM");
}

/// Runs `emg ARGS`, sends SIGINT once it has printed the job's size (its planning under way),
/// and checks that it stops with 130 and writes nothing into `dir` but `keep`.
fn stopped_while_planning(args: &[&str], dir: &Path, keep: &[&str]) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_emg"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("emg starts");
    let stdout = child.stdout.take().expect("stdout is piped");
    let size = BufReader::new(stdout)
        .lines()
        .map(|line| line.expect("stdout reads"))
        .find(|line| line.contains("m to draw"))
        .expect("the job's size is printed before it is planned");
    let pid = i32::try_from(child.id()).expect("pid fits");
    // SAFETY: `kill` only sends a signal to the child process started above.
    assert_eq!(unsafe { libc::kill(pid, libc::SIGINT) }, 0, "signal sent");
    let output = child.wait_with_output().expect("emg ends");
    let stderr = text(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "{size}\n{stderr}");
    assert!(stderr.contains("stopped by SIGINT"), "{stderr}");
    assert!(stderr.contains("nothing was written"), "{stderr}");
    let mut left: Vec<String> = std::fs::read_dir(dir)
        .expect("the directory lists")
        .map(|entry| {
            entry
                .expect("entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|name| !keep.contains(&name.as_str()))
        .collect();
    left.sort();
    assert!(left.is_empty(), "written although stopped: {left:?}");
}

#[test]
fn sigint_stops_a_job_while_planning_and_nothing_is_written() {
    let tmp = temp_dir("interrupt-job");
    let dir = tmp.path();
    let drawing = dir.join("scatter.svg");
    std::fs::write(&drawing, emg_io::scattered_strokes_svg(3000)).expect("drawing written");
    let out = dir.join("scatter.job.json");
    let html = dir.join("scatter.html");
    stopped_while_planning(
        &[
            "job",
            drawing.to_str().expect("utf-8 path"),
            "--out",
            out.to_str().expect("utf-8 path"),
            "--html",
            html.to_str().expect("utf-8 path"),
        ],
        dir,
        &["scatter.svg"],
    );
}

#[test]
fn sigint_stops_a_placement_while_screening_and_nothing_is_written() {
    let tmp = temp_dir("interrupt-place");
    let dir = tmp.path();
    let drawing = dir.join("scatter.svg");
    std::fs::write(&drawing, emg_io::scattered_strokes_svg(200)).expect("drawing written");
    let out = dir.join("scatter.job.json");
    stopped_while_planning(
        &[
            "place",
            drawing.to_str().expect("utf-8 path"),
            "--out",
            out.to_str().expect("utf-8 path"),
        ],
        dir,
        &["scatter.svg"],
    );
}
