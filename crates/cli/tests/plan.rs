//! End-to-end tests of `emg plan`: run the built binary and read back what it wrote.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use emg_control::{CheckRollout, RolloutConfig, Task, Trajectory};
use emg_kinematics::{JointVector, Robot};
use emg_verify::ReferenceModel;
use serde_json::Value;

use common::{NO_WEIGHTS, data_dir, emg, read, read_json, task_json, temp_dir, text};

fn stderr(output: &Output) -> String {
    text(&output.stderr)
}

/// Runs `emg plan` with `args`, asserting success.
fn plan_ok(args: &[&str]) -> String {
    let output = emg(&[&["plan"], args].concat());
    assert!(
        output.status.success(),
        "emg plan {args:?} failed: {}",
        stderr(&output)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Runs `emg plan` with `args`, asserting failure, and returns stderr.
fn plan_err(args: &[&str]) -> String {
    let output = emg(&[&["plan"], args].concat());
    assert!(!output.status.success(), "emg plan {args:?} should fail");
    assert_eq!(
        output.status.code(),
        Some(1),
        "runtime errors exit with status 1"
    );
    stderr(&output)
}

#[test]
fn demo_task_writes_documented_json_and_csv() {
    let tmp = temp_dir("demo");
    let dir = tmp.path();
    let stem = dir.join("nested/demo");
    // Without diffusion weights the default seed is the task's generating configuration.
    let stdout = plan_ok(&[
        "--planner",
        "controller",
        "--out",
        stem.to_str().unwrap(),
        "--weights",
        NO_WEIGHTS,
    ]);
    assert!(
        stdout.contains("path length") && stdout.contains("wrote"),
        "{stdout}"
    );
    let (json_path, csv_path) = (dir.join("nested/demo.json"), dir.join("nested/demo.csv"));
    assert!(json_path.is_file() && csv_path.is_file());

    let doc = read_json(&json_path);
    assert_eq!(doc["format"], "emg-trajectory/1");
    assert_eq!(doc["seed_source"], "generating");
    assert_eq!(
        doc["controller"], "hybrid",
        "the default controller is the hybrid"
    );
    assert_eq!(doc["joint_names"].as_array().unwrap().len(), 7);
    assert!(
        doc["robot"]
            .as_str()
            .unwrap()
            .starts_with("shipped:fr3@sha256:")
    );
    for field in ["p0", "d", "n", "q0_seed"] {
        assert!(doc["task"][field].is_array(), "task.{field}");
    }
    assert_eq!(doc["config"]["dt_s"], 0.05);
    assert_eq!(doc["gains"]["k_mu"], 0.8);
    let steps = doc["steps"].as_array().unwrap();
    assert!(steps.len() > 10);
    for key in ["time_s", "q", "tcp", "tool_angle_deg", "rho", "controller"] {
        assert!(steps[0].get(key).is_some(), "step field {key}");
    }
    assert_eq!(steps[0]["q"].as_array().unwrap().len(), 7);
    assert_eq!(steps[0]["tcp"].as_array().unwrap().len(), 3);
    // The demo starts at the mid-range configuration (ρ = 0, far inside the switch's shell), so
    // the hybrid's learned policy acts first.
    assert_eq!(steps[0]["rho"], 0.0);
    assert_eq!(steps[0]["controller"], "learned");
    let reason = doc["termination"]["reason"].as_str().unwrap();
    assert!(["violation", "invalid_start", "step_cap"].contains(&reason));
    if reason == "violation" {
        assert!(doc["termination"]["violation"]["constraint"].is_string());
    }
    assert!(doc["path_length_m"].as_f64().unwrap() > 0.1);

    let csv = std::fs::read_to_string(&csv_path).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time_s,q1,q2,q3,q4,q5,q6,q7,qd1,qd2,qd3,qd4,qd5,qd6,qd7,\
         tcp_x,tcp_y,tcp_z,tool_angle_deg,rho,controller"
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), steps.len());
    assert!(rows.iter().all(|r| r.split(',').count() == 21));
    let first: Vec<&str> = rows[0].split(',').collect();
    assert_eq!(first[20], steps[0]["controller"].as_str().unwrap());
    let q1: f64 = first[1].parse().unwrap();
    assert_eq!(q1, steps[0]["q"][0].as_f64().unwrap());
}

#[test]
fn a_work_surface_cutting_the_base_is_named_and_the_scene_is_recorded() {
    let tmp = temp_dir("surface");
    let dir = tmp.path();
    let line = [
        "--planner",
        "controller",
        "--p0",
        "0.45,0.0,0.35",
        "--d",
        "0,1,0",
        "--n",
        "0,0,-1",
        "--weights",
        NO_WEIGHTS,
        "--reach",
        "off",
    ];
    // Drawing downwards 35 cm above the base: the default plate under the line clears the
    // base and the line plans; the whole half-space cuts the base, and the task is refused
    // with nothing written and a nonzero exit status.
    let stem = dir.join("plate");
    let out = plan_ok(&[&line[..], &["--out", stem.to_str().unwrap()]].concat());
    assert!(out.contains("path length"), "{out}");
    let doc = read_json(&dir.join("plate.json"));
    let plate = &doc["config"]["constraints"]["work_surface"]["plate"];
    assert_eq!(plate["half_width_m"], 0.1, "{doc}");
    assert!(doc["path_length_m"].as_f64().unwrap() > 0.1, "{doc}");
    let stem = dir.join("cut");
    let error = plan_err(
        &[
            &line[..],
            &["--surface", "half-space", "--out", stem.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(error.contains("refused, nothing written"), "{error}");
    assert!(error.contains("link0 touched the work surface"), "{error}");
    assert!(error.contains("which never moves"), "{error}");
    assert!(error.contains("--surface off"), "{error}");
    assert!(!dir.join("cut.json").exists() && !dir.join("cut.csv").exists());
    // A scene file is recorded in the constraints, and its obstacles end the motion.
    let scene = dir.join("scene.json");
    std::fs::write(
        &scene,
        r#"{"obstacles": [{"name": "ball", "sphere": {"centre": [0.45, 0.1, 0.35], "radius": 0.02}}]}"#,
    )
    .unwrap();
    let stem = dir.join("ball");
    let out = plan_ok(
        &[
            &line[..],
            &[
                "--surface",
                "off",
                "--scene",
                scene.to_str().unwrap(),
                "--out",
                stem.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert!(out.contains("pen_tip touched the ball"), "{out}");
    let doc = read_json(&dir.join("ball.json"));
    assert_eq!(
        doc["config"]["constraints"]["scene"]["obstacles"][0]["name"],
        "ball"
    );
    assert!(doc["config"]["constraints"].get("work_surface").is_none());
    // A bad scene file is refused naming the obstacle and the field.
    std::fs::write(
        &scene,
        r#"{"obstacles": [{"name": "ball", "sphere": {"centre": [0, 0, 0], "radius": -1}}]}"#,
    )
    .unwrap();
    let error = plan_err(&[&line[..], &["--scene", scene.to_str().unwrap()]].concat());
    assert!(
        error.contains("obstacles[0] ('ball'): sphere.radius must be a number ≥ 0"),
        "{error}"
    );
}

#[test]
fn written_trajectory_passes_the_independent_checker() {
    let tmp = temp_dir("check");
    let dir = tmp.path();
    let stem = dir.join("line");
    plan_ok(&[
        "--planner",
        "controller",
        "--p0",
        "0.45,0.0,0.35",
        "--d",
        "0,1,0",
        "--n",
        "0,0,-1",
        "--surface",
        "off",
        "--out",
        stem.to_str().unwrap(),
        "--weights",
        NO_WEIGHTS,
    ]);
    let doc = read_json(&dir.join("line.json"));
    assert_eq!(doc["seed_source"], "home");
    assert!(doc["task"]["q0_seed"].is_null());
    let task: Task = serde_json::from_value(doc["task"].clone()).unwrap();
    let config: RolloutConfig = serde_json::from_value(doc["config"].clone()).unwrap();
    // The file's steps/termination/path_length_m read back as the library's Trajectory.
    let trajectory: Trajectory = serde_json::from_value(doc.clone()).unwrap();
    assert!(
        trajectory.path_length_m > 0.05,
        "{}",
        trajectory.path_length_m
    );
    let checker = ReferenceModel::from_urdf_file(&common::fr3_path(), "link0", "pen_tip").unwrap();
    checker
        .check(&task, &trajectory, &config.constraints)
        .unwrap();
    // The seed was projected onto the exact start pose.
    let (tcp, _) = checker.tcp_pose(&trajectory.steps[0].q);
    assert!((tcp - task.p0).norm() < 1e-8);
}

#[test]
fn bad_inputs_fail_naming_the_field() {
    let tmp = temp_dir("bad");
    let dir = tmp.path();
    let out = dir.join("never");
    let out = out.to_str().unwrap();

    let err = plan_err(&[
        "--p0",
        "0.4,0,0.3",
        "--d",
        "0,0,0",
        "--n",
        "0,0,-1",
        "--out",
        out,
    ]);
    assert!(err.contains("'d'") && err.contains("zero vector"), "{err}");

    let err = plan_err(&[
        "--p0", "5,5,5", "--d", "1,0,0", "--n", "0,0,-1", "--out", out,
    ]);
    assert!(err.contains("'p0'") && err.contains("unreachable"), "{err}");

    let config = dir.join("config.json");
    std::fs::write(&config, r#"{"rollout": {"max_steps": 10, "dt": 0.1}}"#).unwrap();
    let err = plan_err(&["--config", config.to_str().unwrap(), "--out", out]);
    assert!(err.contains("unknown field `dt`"), "{err}");
    std::fs::write(&config, r#"{"gain": {}}"#).unwrap();
    let err = plan_err(&["--config", config.to_str().unwrap(), "--out", out]);
    assert!(err.contains("unknown field `gain`"), "{err}");

    // A step cap no rollout could use is refused before anything is allocated for it.
    std::fs::write(&config, r#"{"rollout": {"max_steps": 1000000000}}"#).unwrap();
    let err = plan_err(&["--config", config.to_str().unwrap(), "--out", out]);
    assert!(
        err.contains("rollout.max_steps must be in [1, 100000], got 1000000000"),
        "{err}"
    );

    let err = plan_err(&[
        "--p0",
        "0.4,0,0.3",
        "--d",
        "0,1,0",
        "--n",
        "0,0,-1",
        "--seed",
        "generating",
        "--out",
        out,
    ]);
    assert!(
        err.contains("--seed generating") && err.contains("q0_seed"),
        "{err}"
    );

    assert!(!dir.join("never.json").exists());
}

#[test]
fn task_file_with_three_tasks_gives_three_results() {
    let tmp = temp_dir("set");
    let dir = tmp.path();
    let robot = Robot::from_urdf_file(common::fr3_path(), "link0", "pen_tip").unwrap();
    let mid = robot.mid_range();
    let configs = [
        mid,
        mid + JointVector::from([0.3, 0.2, -0.2, 0.3, 0.1, -0.2, 0.4]),
        mid + JointVector::from([-0.4, -0.2, 0.3, 0.2, -0.3, 0.3, -0.5]),
    ];
    let tasks: Vec<Value> = configs
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let mut task = task_json(&robot, q);
            if i == 2 {
                task.as_object_mut().unwrap().remove("q0_seed");
            }
            task
        })
        .collect();
    let task_file = dir.join("tasks.json");
    std::fs::write(&task_file, serde_json::to_string_pretty(&tasks).unwrap()).unwrap();
    let stem = dir.join("out/set");
    let stdout = plan_ok(&[
        "--planner",
        "controller",
        "--task-file",
        task_file.to_str().unwrap(),
        "--out",
        stem.to_str().unwrap(),
        "--weights",
        NO_WEIGHTS,
    ]);
    assert_eq!(stdout.matches("path length").count(), 3, "{stdout}");
    for i in 0..3 {
        let json = dir.join(format!("out/set-{i:05}.json"));
        assert!(dir.join(format!("out/set-{i:05}.csv")).is_file());
        let doc = read_json(&json);
        assert_eq!(
            doc["seed_source"],
            if i == 2 { "home" } else { "generating" }
        );
    }
    assert!(!dir.join("out/set.json").exists());
    assert!(!dir.join("out/set-00003.json").exists());
}

#[test]
fn given_seed_is_projected_and_recorded() {
    let tmp = temp_dir("given");
    let dir = tmp.path();
    let stem = dir.join("given");
    let stdout = plan_ok(&[
        "--planner",
        "controller",
        "--p0",
        "0.45,0.0,0.35",
        "--d",
        "0,1,0",
        "--n",
        "0,0,-1",
        "--seed",
        "q=0,-0.5,0,-2.0,0,1.6,0.8",
        "--out",
        stem.to_str().unwrap(),
    ]);
    assert!(stdout.contains("projected"), "{stdout}");
    let doc = read_json(&dir.join("given.json"));
    assert_eq!(doc["seed_source"], "given");
}

#[test]
fn dp_seed_is_the_default_with_the_shipped_weights() {
    let tmp = temp_dir("dp");
    let dir = tmp.path();
    let stem = dir.join("demo");
    let stdout = plan_ok(&["--planner", "controller", "--out", stem.to_str().unwrap()]);
    assert!(stdout.contains("seed: dp"), "{stdout}");
    let doc = read_json(&dir.join("demo.json"));
    assert_eq!(doc["seed_source"], "dp");
    let task: Task = serde_json::from_value(doc["task"].clone()).unwrap();
    let config: RolloutConfig = serde_json::from_value(doc["config"].clone()).unwrap();
    let trajectory: Trajectory = serde_json::from_value(doc.clone()).unwrap();
    let checker = ReferenceModel::from_urdf_file(&common::fr3_path(), "link0", "pen_tip").unwrap();
    checker
        .check(&task, &trajectory, &config.constraints)
        .expect("the DP-seeded trajectory passes the independent checker");
    let explicit = plan_ok(&[
        "--planner",
        "controller",
        "--seed",
        "dp",
        "--out",
        stem.to_str().unwrap(),
    ]);
    assert_eq!(explicit, stdout);
}

#[test]
fn dp_seed_with_missing_or_damaged_weights_fails_clearly() {
    let tmp = temp_dir("dp-bad");
    let dir = tmp.path();
    let stem = dir.join("x");
    let err = plan_err(&[
        "--seed",
        "dp",
        "--weights",
        NO_WEIGHTS,
        "--out",
        stem.to_str().unwrap(),
    ]);
    assert!(
        err.contains("cannot load diffusion weights") && err.contains(NO_WEIGHTS),
        "{err}"
    );
    let shipped = std::fs::read(emg_cli_weights()).unwrap();
    let cut = dir.join("cut.weights");
    std::fs::write(&cut, &shipped[..shipped.len() / 2]).unwrap();
    let err = plan_err(&[
        "--weights",
        cut.to_str().unwrap(),
        "--out",
        stem.to_str().unwrap(),
    ]);
    assert!(err.contains("truncated"), "{err}");
}

/// The shipped diffusion weights.
fn emg_cli_weights() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/models/diffusion-v1.weights")
}

/// `--robot iiwa14` plans on the second shipped arm: its own file and joint names, a demo task
/// away from its stretched-out (singular) mid-range configuration, a trajectory its checker
/// accepts. A robot file that is not shipped has no default models, and the error says what to
/// pass instead.
#[test]
fn robot_by_name_and_by_file() {
    let tmp = temp_dir("iiwa");
    let dir = tmp.path();
    let stem = dir.join("iiwa");
    plan_ok(&[
        "--robot",
        "iiwa14",
        "--controller",
        "classical",
        "--seed",
        "generating",
        "--out",
        stem.to_str().unwrap(),
    ]);
    let doc = read_json(&dir.join("iiwa.json"));
    let reference = doc["robot"].as_str().unwrap();
    assert!(
        reference.starts_with("shipped:iiwa14@sha256:"),
        "{reference}"
    );
    let robot_path = data_dir().join("robots/iiwa14_pen.urdf");
    assert_eq!(doc["joint_names"][6], "iiwa_joint_7");
    assert!(doc["path_length_m"].as_f64().unwrap() > 0.1, "{doc}");
    let robot = Robot::from_chain_file(&robot_path).unwrap();
    let task: Task = serde_json::from_value(doc["task"].clone()).unwrap();
    let config: RolloutConfig = serde_json::from_value(doc["config"].clone()).unwrap();
    let trajectory: Trajectory = serde_json::from_value(doc).unwrap();
    let checker = ReferenceModel::from_urdf_file(&robot_path, "iiwa_link_0", "pen_tip").unwrap();
    checker
        .check(&task, &trajectory, &config.constraints)
        .expect("the iiwa plan holds every constraint");
    let mid = robot.forward(&robot.mid_range());
    assert!(
        (mid.tcp() - task.p0).norm() > 0.1,
        "the demo avoids the stretched-out pose"
    );

    let copy = dir.join("my_arm.urdf");
    std::fs::copy(&robot_path, &copy).unwrap();
    // A robot file with no models and no limits file beside it plans with the default command:
    // the classical controller and assumed limits, each said in one line.
    let plain = [
        "--robot",
        copy.to_str().unwrap(),
        "--out",
        stem.to_str().unwrap(),
    ];
    let out = plan_ok(&plain);
    assert!(out.contains("controller: classical (no policy"), "{out}");
    assert!(
        out.contains("joint limits: no my_arm.joint_limits.yaml") && out.contains("assumed"),
        "{out}"
    );
    let joint = read_json(&dir.join("iiwa.joint_trajectory.json"));
    assert_eq!(joint["limits"]["joint_limits_file"], "assumed", "{joint}");
    let message = plan_err(&[&plain[..], &["--controller", "hybrid"]].concat());
    assert!(message.contains("--policy"), "{message}");
    let classical = [&plain[..], &["--controller", "classical"]].concat();
    let limits = robot_path.with_file_name("iiwa14_pen.joint_limits.yaml");
    let limited = [&classical[..], &["--limits", limits.to_str().unwrap()]].concat();
    plan_ok(&limited);
    let message = plan_err(&[&limited[..], &["--velocity-scaling", "0"]].concat());
    assert!(
        message.contains("velocity_scaling must be in (0, 1], got 0"),
        "{message}"
    );
    let message = plan_err(&[&limited[..], &["--rate-hz", "0"]].concat());
    assert!(
        message.contains("rate_hz") && message.contains("got 0"),
        "{message}"
    );
    // Half the acceleration limits and 100 Hz: a slower motion in fewer points, still within
    // the halved limits by `emg check`.
    let full = read_json(&dir.join("iiwa.joint_trajectory.json"));
    plan_ok(
        &[
            &limited[..],
            &["--acceleration-scaling", "0.5", "--rate-hz", "100"],
        ]
        .concat(),
    );
    let slow = read_json(&dir.join("iiwa.joint_trajectory.json"));
    assert_eq!(slow["limits"]["acceleration_scaling"], 0.5);
    assert_eq!(slow["limits"]["max_acceleration"][0], 2.5);
    assert_eq!(slow["timing"]["rate_hz"], 100.0);
    let duration = |doc: &Value| doc["timing"]["duration_s"].as_f64().unwrap();
    assert!(
        duration(&slow) > duration(&full),
        "{} vs {}",
        duration(&slow),
        duration(&full)
    );
    let points = |doc: &Value| doc["points"].as_array().unwrap().len();
    assert_eq!(
        points(&slow),
        (duration(&slow) * 100.0).round() as usize + 1
    );
    let output = common::emg(&[
        "check",
        dir.join("iiwa.joint_trajectory.json").to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", text(&output.stderr));
}

#[test]
fn search_plan_records_its_planner_and_bound_and_checks() {
    let tmp = temp_dir("search");
    let dir = tmp.path();
    let stem = dir.join("searched");
    let config = dir.join("small.json");
    std::fs::write(
        &config,
        r#"{"search": {"budget_steps": 2000, "ik_restarts": 16}}"#,
    )
    .unwrap();
    let stdout = plan_ok(&[
        "--planner",
        "search",
        "--config",
        config.to_str().unwrap(),
        "--out",
        stem.to_str().unwrap(),
    ]);
    assert!(stdout.contains("reachable"), "{stdout}");
    let doc = read_json(&dir.join("searched.json"));
    assert_eq!(doc["planner"], "search");
    let length = doc["path_length_m"].as_f64().unwrap();
    let bound = doc["reachable_m"].as_f64().unwrap();
    assert!(
        length <= bound + 0.01,
        "{length} m planned, bound {bound} m"
    );
    let joint = dir.join("searched.joint_trajectory.json");
    let output = emg(&["check", joint.to_str().unwrap()]);
    assert!(output.status.success(), "{}", stderr(&output));
    // Without the bound the file has no reachable_m.
    plan_ok(&[
        "--reach",
        "off",
        "--out",
        stem.to_str().unwrap(),
        "--weights",
        NO_WEIGHTS,
    ]);
    assert!(
        read_json(&dir.join("searched.json"))
            .get("reachable_m")
            .is_none()
    );
}

/// A seed that cannot be put on the start pose ends the paper's pipeline with an error that says
/// what to try, and does not stop the search, which goes on from its other starts.
#[test]
fn an_unprojectable_seed_leaves_the_search_its_other_starts() {
    let tmp = temp_dir("unprojectable");
    let stem = tmp.path().join("up");
    let line = [
        "--p0",
        "0.45,-0.2,0.25",
        "--d",
        "0,1,0",
        "--n",
        "0,0,1",
        "--seed",
        "home",
        "--reach",
        "off",
        "--out",
        stem.to_str().unwrap(),
    ];
    let error = plan_err(&[&line[..], &["--planner", "controller"]].concat());
    assert!(
        error.contains("cannot project the home seed") && error.contains("--planner search"),
        "{error}"
    );
    assert_eq!(
        error.matches("cannot project").count(),
        1,
        "said once: {error}"
    );
    let out = plan_ok(&line);
    let doc = read_json(&tmp.path().join("up.json"));
    assert!(doc["path_length_m"].as_f64().unwrap() > 0.1, "{out}");
    assert_ne!(doc["seed_source"], "home", "{out}");
}

/// Every kind of input a run reads, named by an output of the same run: refused before anything
/// is planned, naming both, with the input unchanged and nothing written.
#[test]
fn no_output_replaces_an_input() {
    let tmp = temp_dir("clash");
    let dir = tmp.path();
    let robot = Robot::from_urdf_file(common::fr3_path(), "link0", "pen_tip").unwrap();
    let task = serde_json::to_string(&task_json(&robot, &robot.mid_range())).unwrap();
    let path = r#"{"version": 1, "start": [0.5, -0.15, 0.2], "normal": [0, 0, -1],
        "segments": [{"line": {"to": [0.5, 0.15, 0.2]}}]}"#;
    let urdf = read(&common::fr3_path());
    // (option, input file name, its contents, the options that name it as an output)
    let cases: [(&str, &str, &str, &[&str]); 6] = [
        ("--task-file", "job.json", &task, &["--out", "job"]),
        ("--path", "slot.json", path, &["--out", "slot"]),
        ("--config", "cfg.json", "{}", &["--out", "cfg"]),
        (
            "--scene",
            "cell.json",
            r#"{"obstacles": []}"#,
            &["--out", "cell"],
        ),
        (
            "--limits",
            "limits.yaml",
            "not read",
            &["--html", "limits.yaml"],
        ),
        (
            "--robot",
            "robot.urdf",
            &urdf,
            &["--html", "./sub/../robot.urdf"],
        ),
    ];
    for (option, name, contents, output) in cases {
        let input = dir.join(name);
        std::fs::write(&input, contents).unwrap();
        let mut args = vec![option, input.to_str().unwrap()];
        let named: Vec<String> = output
            .chunks(2)
            .flat_map(|pair| [pair[0].to_string(), dir.join(pair[1]).display().to_string()])
            .collect();
        args.extend(named.iter().map(String::as_str));
        let error = plan_err(&args);
        assert!(
            error.contains(&format!("which is the {option} file"))
                && error.contains(output[0])
                && error.contains("nothing was written"),
            "{option}: {error}"
        );
        assert_eq!(read(&input), contents, "{option}: the input is unchanged");
        let written: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|entry| entry.unwrap().file_name().into_string().unwrap())
            .filter(|file| file.ends_with(".csv") || file.ends_with(".html"))
            .collect();
        assert!(written.is_empty(), "{option}: wrote {written:?}");
        std::fs::remove_file(&input).unwrap();
    }
}

/// A task file plans every task it can: an unreachable task is refused and counted, the
/// others are planned and written.
#[test]
fn a_task_file_plans_every_task_it_can() {
    let tmp = temp_dir("partial");
    let dir = tmp.path();
    let robot = Robot::from_urdf_file(common::fr3_path(), "link0", "pen_tip").unwrap();
    let valid = task_json(&robot, &robot.mid_range());
    let unreachable = serde_json::json!({"p0": [3.0, 0.0, 0.2], "d": [0, 1, 0], "n": [0, 0, -1]});
    let task_file = dir.join("tasks.json");
    let tasks = serde_json::json!([valid, unreachable, valid]);
    std::fs::write(&task_file, tasks.to_string()).unwrap();
    let stem = dir.join("out/set");
    let error = plan_err(&[
        "--planner",
        "controller",
        "--task-file",
        task_file.to_str().unwrap(),
        "--out",
        stem.to_str().unwrap(),
    ]);
    assert!(
        error.contains("2 of 3 tasks planned; 1 refused at their start, 0 failed")
            && error.contains("task 1: ")
            && error.contains("unreachable"),
        "{error}"
    );
    assert!(dir.join("out/set-00000.json").is_file());
    assert!(!dir.join("out/set-00001.json").exists());
    assert!(dir.join("out/set-00002.json").is_file());
}

/// A start inside the arm's own base is refused saying so, and a refusal of the search never
/// suggests the planner or the seed in use.
#[test]
fn a_start_no_configuration_can_hold_is_refused_with_its_cause() {
    let tmp = temp_dir("inside");
    let stem = tmp.path().join("inside");
    let error = plan_err(&[
        "--p0",
        "0.0,0.02,0.2",
        "--d",
        "1,0,0",
        "--n",
        "0,0,-1",
        "--out",
        stem.to_str().unwrap(),
    ]);
    assert!(
        error.contains("no configuration at p0 holds every constraint")
            && error.contains("inside the space the arm's base occupies"),
        "{error}"
    );
    assert!(
        !error.contains("--planner") && !error.contains("--seed") && !error.contains("Newton"),
        "{error}"
    );
    assert!(!tmp.path().join("inside.json").exists());
}

/// The default plate is a part: under a line heading at the arm it ends short of the arm's
/// base, and under a circle it covers the circle only, whichever way the circle turns (the
/// plate carried 2 m ahead of the start along the start tangent used to cut the base).
#[test]
fn the_default_plate_never_covers_the_arms_base() {
    let tmp = temp_dir("plate");
    let dir = tmp.path();
    let toward = dir.join("toward");
    plan_ok(&[
        "--p0",
        "0.4,0,0.2",
        "--d",
        "-1,0,0",
        "--n",
        "0,0,-1",
        "--out",
        toward.to_str().unwrap(),
    ]);
    let doc = read_json(&dir.join("toward.json"));
    assert!(doc["path_length_m"].as_f64().unwrap() > 0.1, "{doc}");
    for sweep in [360, -360] {
        let file = dir.join(format!("circle{sweep}.json"));
        std::fs::write(
            &file,
            format!(
                r#"{{"version": 1, "start": [0.5, 0.05, 0.2], "normal": [0, 0, -1],
                "segments": [{{"arc": {{"centre": [0.5, -0.05, 0.2], "sweep_deg": {sweep}}}}}]}}"#
            ),
        )
        .unwrap();
        let stem = dir.join(format!("out/circle{sweep}"));
        let out = plan_ok(&[
            "--path",
            file.to_str().unwrap(),
            "--out",
            stem.to_str().unwrap(),
        ]);
        assert!(
            out.contains("reached the end of the path"),
            "sweep {sweep}: {out}"
        );
        let check = emg(&[
            "check",
            &format!("{}.joint_trajectory.json", stem.display()),
        ]);
        assert!(check.status.success(), "sweep {sweep}: {}", stderr(&check));
    }
}

/// First-hour inputs: a seed gives one value per joint, `--config` takes inline JSON, a bad
/// rate is named as the rate, and a tool speed the joints never allow is said.
#[test]
fn first_hour_inputs_are_read_as_written() {
    let tmp = temp_dir("first-hour");
    let stem = tmp.path().join("x");
    let out = ["--out", stem.to_str().unwrap()];
    let error = plan_err(&[&["--robot", "ur5e", "--seed", "q=0,0,0,0,0,0,0"], &out[..]].concat());
    assert!(
        error.contains("gives 7 joint values, and the arm has 6 joints"),
        "{error}"
    );
    let error = plan_err(&[&["--rate-hz", "0"], &out[..]].concat());
    assert!(
        error.contains("--rate-hz 0") && !error.contains("--tool-speed"),
        "{error}"
    );
    let inline = r#"{"rollout": {"constraints": {"theta_max_deg": 20}}}"#;
    plan_ok(&[&["--config", inline, "--reach", "off"], &out[..]].concat());
    let doc = read_json(&tmp.path().join("x.json"));
    assert_eq!(doc["config"]["constraints"]["theta_max_deg"], 20.0);
    let fast = plan_ok(&[&["--tool-speed", "5", "--reach", "off"], &out[..]].concat());
    assert!(
        fast.contains("never let the tool reach the requested 5 m/s"),
        "{fast}"
    );
}

/// `--tolerance MM` and `--cone DEG` set the line tolerance and the tool cone of the plan, the
/// bound, the timed motion and the checker, and every file records them; a bad value names the
/// option.
#[test]
fn tolerance_and_cone_are_options_every_file_records() {
    let tmp = temp_dir("tolerance");
    let stem = tmp.path().join("fine");
    plan_ok(&[
        "--tolerance",
        "0.5",
        "--cone",
        "20",
        "--out",
        stem.to_str().unwrap(),
    ]);
    let rollout = read_json(&tmp.path().join("fine.json"));
    let timed = read_json(&tmp.path().join("fine.joint_trajectory.json"));
    for constraints in [&rollout["config"]["constraints"], &timed["constraints"]] {
        assert_eq!(constraints["line_tolerance_m"], 0.0005, "{constraints}");
        assert_eq!(constraints["theta_max_deg"], 20.0, "{constraints}");
    }
    let check = emg(&[
        "check",
        tmp.path()
            .join("fine.joint_trajectory.json")
            .to_str()
            .unwrap(),
    ]);
    assert!(check.status.success(), "{}", stderr(&check));
    let refused = emg(&["plan", "--tolerance", "0", "--out", stem.to_str().unwrap()]);
    let error = stderr(&refused);
    assert_eq!(refused.status.code(), Some(2), "a usage error: {error}");
    assert!(
        error.contains("--tolerance") && error.contains("must be > 0 mm, got 0"),
        "{error}"
    );
}
