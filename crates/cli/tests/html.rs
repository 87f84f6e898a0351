//! `emg plan --html`: the viewer page is written beside the trajectory files, one per task.

mod common;

use std::process::{Command, Output};

use emg_kinematics::{JointVector, Robot};
use serde_json::Value;

use common::{NO_WEIGHTS, read, task_json, temp_dir};

/// Runs `emg plan` with the classical controller and `args`, asserting success; returns stdout.
fn plan_ok(args: &[&str]) -> String {
    let output: Output = Command::new(env!("CARGO_BIN_EXE_emg"))
        .args(["plan", "--controller", "classical", "--weights", NO_WEIGHTS])
        .args(args)
        .output()
        .expect("run emg");
    assert!(
        output.status.success(),
        "emg plan {args:?} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// The files directly inside `dir`, sorted.
fn listing(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn html_page_holds_the_planned_motion() {
    let tmp = temp_dir("single");
    let dir = tmp.path();
    let stem = dir.join("demo");
    let page_path = dir.join("pages/demo.html");
    let stdout = plan_ok(&[
        "--seed",
        "home",
        "--out",
        stem.to_str().unwrap(),
        "--html",
        page_path.to_str().unwrap(),
    ]);
    assert!(
        stdout.contains(&format!("wrote {}", page_path.display())),
        "the page is reported: {stdout}"
    );
    let page = read(&page_path);
    assert!(page.starts_with("<!DOCTYPE html>"));
    let recorded: Value = serde_json::from_str(&read(&dir.join("demo.json"))).unwrap();
    let mut acted: Vec<&str> = Vec::new();
    for step in recorded["steps"].as_array().unwrap() {
        if let Some(name) = step["controller"]
            .as_str()
            .filter(|name| !acted.contains(name))
        {
            acted.push(name);
        }
    }
    let title = match acted.as_slice() {
        [one] => format!("<title>demo: steps by the {one} controller</title>"),
        [first @ .., last] => format!(
            "<title>demo: steps by the {} and {last} controllers</title>",
            first.join(", ")
        ),
        [] => panic!("no step recorded a controller"),
    };
    assert!(
        page.contains(&title),
        "titled by the controllers that acted: {title}"
    );
    // The page plays the motion the robot executes: its last step at the timed motion's end.
    let timed: Value =
        serde_json::from_str(&read(&dir.join("demo.joint_trajectory.json"))).unwrap();
    let duration_s = timed["timing"]["duration_s"].as_f64().unwrap();
    let last_s = page
        .rsplit_once(r#""t":"#)
        .and_then(|(_, rest)| rest.split([',', '}']).next()?.parse::<f64>().ok())
        .expect("the page's last step time");
    assert!(
        (last_s - duration_s).abs() < 0.01,
        "the page plays {last_s} s, the timed motion takes {duration_s} s"
    );
    assert!(!page.contains("http://") && !page.contains("https://"));
    let trajectory: Value = serde_json::from_str(&read(&dir.join("demo.json"))).unwrap();
    let steps = trajectory["steps"].as_array().unwrap();
    assert!(steps.len() > 10, "a real motion: {} steps", steps.len());
    let acting = steps
        .iter()
        .filter(|s| s["controller"] == "classical")
        .count();
    assert_eq!(
        page.matches(r#""controller":"classical""#).count(),
        acting,
        "one entry per recorded step"
    );
    assert_eq!(
        listing(&dir.join("pages")),
        ["demo.html"],
        "no .partial is left"
    );
}

#[test]
fn html_pages_follow_the_per_task_suffix_rule() {
    let tmp = temp_dir("set");
    let dir = tmp.path();
    let robot = Robot::from_urdf_file(common::fr3_path(), "link0", "pen_tip").unwrap();
    let mid = robot.mid_range();
    let tasks: Vec<Value> = [
        mid,
        mid + JointVector::from([0.3, 0.2, -0.2, 0.3, 0.1, -0.2, 0.4]),
    ]
    .iter()
    .map(|q| task_json(&robot, q))
    .collect();
    let task_file = dir.join("tasks.json");
    std::fs::write(&task_file, serde_json::to_string(&tasks).unwrap()).unwrap();
    let task_file = task_file.to_str().unwrap();
    let out = dir.join("out/set");
    let out = out.to_str().unwrap();

    let with_extension = dir.join("view/set.html");
    let stdout = plan_ok(&[
        "--task-file",
        task_file,
        "--out",
        out,
        "--html",
        with_extension.to_str().unwrap(),
    ]);
    assert_eq!(
        listing(&dir.join("view")),
        ["set-00000.html", "set-00001.html"]
    );
    for i in 0..2 {
        let page = dir.join(format!("view/set-{i:05}.html"));
        assert!(
            stdout.contains(&format!("wrote {}", page.display())),
            "{stdout}"
        );
        assert!(read(&page).contains(&format!("<title>set-{i:05}: steps by the ")));
    }

    let without_extension = dir.join("bare/set");
    plan_ok(&[
        "--task-file",
        task_file,
        "--out",
        out,
        "--html",
        without_extension.to_str().unwrap(),
    ]);
    assert_eq!(
        listing(&dir.join("bare")),
        ["set-00000.html", "set-00001.html"]
    );
}

#[test]
fn no_page_without_html() {
    let tmp = temp_dir("none");
    let dir = tmp.path();
    let stdout = plan_ok(&[
        "--seed",
        "home",
        "--out",
        dir.join("demo").to_str().unwrap(),
    ]);
    assert!(!stdout.contains(".html"), "{stdout}");
    assert!(listing(dir).iter().all(|name| !name.ends_with(".html")));
}
