//! End-to-end tests of `emg check`: plan a real task with the binary, verify each of the three
//! files it writes, then tamper with them and expect exit status 1 naming the point and the
//! constraint.

mod common;

use std::path::{Path, PathBuf};

use serde_json::Value;

use common::{emg, read_json, task_json, temp_dir, text};

/// Velocity-limit fraction of the planned task: low enough that many steps are slowed, so the
/// times are not uniform.
const FRACTION: f64 = 0.05;

/// Plans the demo task with the classical controller from its generating configuration (no
/// model to load) and returns the output stem.
fn plan(dir: &Path) -> PathBuf {
    let config = dir.join("plan.json");
    std::fs::write(
        &config,
        format!(r#"{{"rollout": {{"constraints": {{"velocity_limit_fraction": {FRACTION}}}}}}}"#),
    )
    .unwrap();
    let stem = dir.join("demo");
    let output = emg(&[
        "plan",
        "--controller",
        "classical",
        "--seed",
        "generating",
        "--config",
        config.to_str().unwrap(),
        "--out",
        stem.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let stdout = text(&output.stdout);
    assert!(stdout.contains("demo.joint_trajectory.json"), "{stdout}");
    stem
}

fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    PathBuf::from(format!("{}{ext}", stem.display()))
}

/// Runs `emg check` with `args`, asserting success; returns stdout.
fn check_ok(args: &[&str]) -> String {
    let output = emg(&[&["check"], args].concat());
    assert!(
        output.status.success(),
        "emg check {args:?} failed: {}",
        text(&output.stderr)
    );
    let stdout = text(&output.stdout);
    assert!(stdout.trim_end().ends_with("OK"), "{stdout}");
    stdout
}

/// Runs `emg check` with `args`, asserting exit status 1; returns stderr.
fn check_err(args: &[&str]) -> String {
    let output = emg(&[&["check"], args].concat());
    assert_eq!(
        output.status.code(),
        Some(1),
        "emg check {args:?} should fail with status 1: {}",
        text(&output.stdout)
    );
    text(&output.stderr)
}

/// Writes `doc` next to the original and returns the path as a string.
fn write_json(dir: &Path, name: &str, doc: &Value) -> String {
    let path = dir.join(name);
    std::fs::write(&path, doc.to_string()).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn every_file_of_a_plan_passes_and_tampering_is_caught() {
    let tmp = temp_dir("files");
    let dir = tmp.path();
    let stem = plan(dir);
    let json = with_ext(&stem, ".json");
    let csv = with_ext(&stem, ".csv");
    let joint = with_ext(&stem, ".joint_trajectory.json");

    let out = check_ok(&[json.to_str().unwrap()]);
    assert!(
        out.contains("emg-trajectory/1") && out.contains("recorded end verified"),
        "{out}"
    );
    let out = check_ok(&[joint.to_str().unwrap()]);
    assert!(out.contains("emg-joint-trajectory/2"), "{out}");
    assert!(
        out.contains("joint limits from the file; rest at both ends"),
        "{out}"
    );
    assert!(
        out.contains("not verifiable from this file: why the motion ended"),
        "{out}"
    );
    // The timed motion runs at the velocity limits (the fraction of the robot file's) somewhere.
    assert!(
        out.contains("peak joint velocity / limit") && out.contains("1.000"),
        "{out}"
    );
    assert!(out.contains("peak joint jerk / limit"), "{out}");
    let points = read_json(&joint)["points"].as_array().unwrap().len();
    assert!(out.contains(&format!("{points} points")), "{out}");
    let out = check_ok(&[json.to_str().unwrap()]);
    // The planned steps: the slowed ones run at the limit fraction.
    assert!(out.contains(&format!("{FRACTION:.3}")), "{out}");
    assert!(
        out.contains("peak joint acceleration between points")
            && out.contains("fastest joint at the first point"),
        "{out}"
    );
    // `replay` is an alias.
    let output = emg(&["replay", joint.to_str().unwrap()]);
    assert!(output.status.success(), "{}", text(&output.stderr));

    // The CSV carries no task: it comes from the JSON beside it, --task-from or --p0/--d/--n.
    let out = check_ok(&[csv.to_str().unwrap()]);
    assert!(
        out.contains(&format!("task from --task-from {}", json.display())),
        "{out}"
    );
    let alone = csv.with_file_name("alone.csv");
    std::fs::copy(&csv, &alone).unwrap();
    let err = check_err(&[alone.to_str().unwrap()]);
    assert!(
        err.contains("carries no task") && err.contains("--task-from"),
        "{err}"
    );
    let out = check_ok(&[csv.to_str().unwrap(), "--task-from", json.to_str().unwrap()]);
    assert!(
        out.contains("CSV") && out.contains("declared velocities agree"),
        "{out}"
    );
    let task = &read_json(&json)["task"];
    let vec3 = |field: &str| {
        let v: Vec<String> = task[field]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| format!("{:?}", x.as_f64().unwrap()))
            .collect();
        v.join(",")
    };
    let (p0, d, n) = (vec3("p0"), vec3("d"), vec3("n"));
    check_ok(&[csv.to_str().unwrap(), "--p0", &p0, "--d", &d, "--n", &n]);

    // The samples lie 1 ms apart, from rest to rest.
    let good = read_json(&joint);
    let seconds = |point: &Value| {
        let t = &point["time_from_start"];
        t["sec"].as_f64().unwrap() + t["nanosec"].as_f64().unwrap() / 1e9
    };
    let pts = good["points"].as_array().unwrap();
    let gaps: Vec<f64> = pts
        .windows(2)
        .map(|w| seconds(&w[1]) - seconds(&w[0]))
        .collect();
    assert!(gaps.iter().all(|g| (g - 1e-3).abs() < 1e-12), "{gaps:?}");
    let k = pts.len() / 2;

    let tamper = |name: &str, edit: &dyn Fn(&mut Value)| {
        let mut doc = good.clone();
        edit(&mut doc);
        check_err(&[&write_json(dir, name, &doc)])
    };
    let err = tamper("limit.json", &|doc| {
        doc["points"][k]["positions"][0] = 2.9.into();
    });
    assert!(
        err.contains(&format!("point {k} of")) && err.contains("joint 1 = 2.9 outside"),
        "{err}"
    );
    let err = tamper("line.json", &|doc| {
        let q = doc["points"][k]["positions"][1].as_f64().unwrap();
        doc["points"][k]["positions"][1] = (q + 0.1).into();
    });
    assert!(
        err.contains(&format!("point {k} of")) && err.contains("off the line"),
        "{err}"
    );
    let err = tamper("fast.json", &|doc| {
        // The gap before point k shrinks to a hundredth.
        let gap_ns = ((seconds(&pts[k]) - seconds(&pts[k - 1])) * 1e9).round() as u64;
        let start = (seconds(&pts[k - 1]) * 1e9).round() as u64 + gap_ns / 100;
        doc["points"][k]["time_from_start"] =
            serde_json::json!({"sec": start / 1_000_000_000, "nanosec": start % 1_000_000_000});
    });
    assert!(
        err.contains(&format!("point {k} of")) && err.contains("rad/s, above"),
        "{err}"
    );
    let err = tamper("names.json", &|doc| {
        doc["joint_names"][2] = "fr3_joint9".into();
    });
    assert!(
        err.contains("joint_names") && err.contains("same order"),
        "{err}"
    );
    let err = tamper("order.json", &|doc| {
        let names = doc["joint_names"].as_array_mut().unwrap();
        names.swap(0, 1);
    });
    assert!(
        err.contains("joint_names") && err.contains("fr3_joint2"),
        "{err}"
    );
    let err = tamper("declared.json", &|doc| {
        let v = doc["points"][k]["velocities"][3].as_f64().unwrap();
        doc["points"][k]["velocities"][3] = (v + 0.01).into();
    });
    assert!(
        err.contains(&format!("point {k} of"))
            && err.contains("joint 4: position change")
            && err.contains("declared velocities"),
        "{err}"
    );
    let err = tamper("moving-start.json", &|doc| {
        doc["points"][0]["accelerations"][5] = 0.5.into();
    });
    assert!(
        err.contains("point 0 of") && err.contains("the first point is not at rest"),
        "{err}"
    );
    let err = tamper("jerk.json", &|doc| {
        let a = doc["points"][k]["accelerations"][1].as_f64().unwrap();
        doc["points"][k]["accelerations"][1] = (a + 8.0).into();
    });
    assert!(
        err.contains(&format!("point {k} of"))
            && err.contains("joint 2 jerk (from declared accelerations"),
        "{err}"
    );
    let err = tamper("declared-fast.json", &|doc| {
        doc["points"][k]["velocities"][0] = 1.0.into();
    });
    assert!(
        err.contains("declared velocity of joint 1") && err.contains("× its limit"),
        "{err}"
    );

    // A too-fast step in the CSV: the time of step k moves close to step k - 1.
    let table = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<String> = table.lines().map(str::to_string).collect();
    let k = lines.len() / 2;
    let time = |line: &str| line.split(',').next().unwrap().parse::<f64>().unwrap();
    let (before, at) = (time(&lines[k]), time(&lines[k + 1]));
    let rest = lines[k + 1].split_once(',').unwrap().1.to_string();
    lines[k + 1] = format!("{:?},{rest}", before + (at - before) / 100.0);
    let fast_csv = dir.join("fast.csv");
    std::fs::write(&fast_csv, lines.join("\n")).unwrap();
    let err = check_err(&[
        fast_csv.to_str().unwrap(),
        "--task-from",
        json.to_str().unwrap(),
    ]);
    assert!(
        err.contains(&format!("point {k} of")) && err.contains("rad/s, above"),
        "{err}"
    );
}

#[test]
fn malformed_files_name_the_file_and_the_field() {
    let tmp = temp_dir("malformed");
    let dir = tmp.path();
    let stem = plan(dir);
    let joint = read_json(&with_ext(&stem, ".joint_trajectory.json"));

    let mut doc = joint.clone();
    doc["format"] = "emg-joint-trajectory/1".into();
    let path = write_json(dir, "format.json", &doc);
    let err = check_err(&[&path]);
    assert!(
        err.contains(&path)
            && err.contains("field 'format'")
            && err.contains("emg-joint-trajectory/2"),
        "{err}"
    );

    let mut doc = joint.clone();
    doc["points"][3]["positions"].as_array_mut().unwrap().pop();
    let path = write_json(dir, "count.json", &doc);
    let err = check_err(&[&path]);
    assert!(
        err.contains(&path) && err.contains("'points[3].positions' has 6 values, expected 7"),
        "{err}"
    );

    let mut doc = joint.clone();
    doc["joint_names"].as_array_mut().unwrap().truncate(5);
    let err = check_err(&[&write_json(dir, "names.json", &doc)]);
    assert!(
        err.contains("'joint_names' has 5 entries, expected 6 or 7"),
        "{err}"
    );

    let mut doc = read_json(&with_ext(&stem, ".json"));
    doc.as_object_mut().unwrap().remove("task");
    let err = check_err(&[&write_json(dir, "notask.json", &doc)]);
    assert!(err.contains("field 'task' is missing"), "{err}");

    let table = std::fs::read_to_string(with_ext(&stem, ".csv")).unwrap();
    let mut lines: Vec<String> = table.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[4].split(',').map(str::to_string).collect();
    cells[3] = "abc".into();
    lines[4] = cells.join(",");
    let bad_csv = dir.join("bad.csv");
    std::fs::write(&bad_csv, lines.join("\n")).unwrap();
    let err = check_err(&[
        bad_csv.to_str().unwrap(),
        "--task-from",
        &with_ext(&stem, ".json").to_string_lossy(),
    ]);
    assert!(
        err.contains(bad_csv.to_str().unwrap())
            && err.contains("CSV line 5, column 4 ('q3'): 'abc' is not a finite number"),
        "{err}"
    );
}

#[test]
fn a_task_set_writes_one_joint_trajectory_per_task() {
    let tmp = temp_dir("set");
    let dir = tmp.path();
    let robot =
        emg_kinematics::Robot::from_urdf_file(common::fr3_path(), "link0", "pen_tip").unwrap();
    let mid = robot.mid_range();
    let tasks: Vec<Value> = [
        mid,
        mid + emg_kinematics::JointVector::from([0.3, 0.2, -0.2, 0.3, 0.1, -0.2, 0.4]),
    ]
    .iter()
    .map(|q| task_json(&robot, q))
    .collect();
    let task_file = dir.join("tasks.json");
    std::fs::write(&task_file, Value::from(tasks).to_string()).unwrap();
    let stem = dir.join("out/set");
    let output = emg(&[
        "plan",
        "--task-file",
        task_file.to_str().unwrap(),
        "--controller",
        "classical",
        "--seed",
        "generating",
        "--out",
        stem.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    for i in 0..2 {
        let path = dir.join(format!("out/set-{i:05}.joint_trajectory.json"));
        check_ok(&[path.to_str().unwrap()]);
    }
    assert!(!dir.join("out/set.joint_trajectory.json").exists());
    assert!(!dir.join("out/set-00002.joint_trajectory.json").exists());
}
