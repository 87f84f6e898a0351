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

// `emg job --html`: the job page, written beside the program.

/// Headless Chromium on a viewer page (the viewer's own browser-test helpers).
#[path = "../../viewer/tests/support/browser.rs"]
mod browser;

/// `emg job examples/seams.json --out … --html …`, run once for the tests below.
struct SeamsJob {
    /// What `emg job` printed.
    stdout: String,
    /// Where it wrote the page.
    page_path: std::path::PathBuf,
    /// The program (`emg-job/3`).
    program: Value,
    /// The page.
    page: String,
}

/// The seams job planned and its page written (once per test binary).
fn seams_job() -> &'static SeamsJob {
    static JOB: std::sync::OnceLock<SeamsJob> = std::sync::OnceLock::new();
    JOB.get_or_init(|| {
        let tmp = temp_dir("job-page");
        let dir = tmp.path();
        let seams =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/seams.json");
        let out = dir.join("seams.job.json");
        let page_path = dir.join("view/seams.html");
        let output = common::emg(&[
            "job",
            seams.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--html",
            page_path.to_str().unwrap(),
        ]);
        assert!(
            output.status.success(),
            "emg job --html failed: {}",
            common::text(&output.stderr)
        );
        SeamsJob {
            stdout: common::text(&output.stdout),
            page_path,
            program: common::read_json(&out),
            page: read(&dir.join("view/seams.html")),
        }
    })
}

/// The page's data blob.
fn page_data(page: &str) -> Value {
    let open = r#"<script type="application/json" id="motion-data">"#;
    let start = page.find(open).expect("the page holds its data") + open.len();
    let end = start + page[start..].find("</script>").expect("the data ends");
    serde_json::from_str(&page[start..end]).expect("the data is JSON")
}

/// A program segment's name as the page shows it.
fn segment_name(segment: &Value) -> String {
    match segment["kind"].as_str().unwrap() {
        "stroke" => format!("stroke {} part {}", segment["stroke"], segment["part"]),
        other => other.to_string(),
    }
}

#[test]
fn job_html_draws_the_whole_program() {
    let job = seams_job();
    assert!(
        job.stdout
            .contains(&format!("wrote {}", job.page_path.display())),
        "the page is reported: {}",
        job.stdout
    );
    let page = &job.page;
    assert!(page.starts_with("<!DOCTYPE html>"));
    assert!(
        page.contains("<title>seams: 3 strokes, "),
        "titled by the job"
    );
    assert!(!page.contains("http://") && !page.contains("https://"));
    let data = page_data(page);
    let program = &job.program;
    let summary = &program["summary"];

    // Every stroke, by the job's index, with what the program draws of it.
    let strokes = data["strokes"].as_array().unwrap();
    assert_eq!(strokes.len(), 3);
    for report in program["strokes"].as_array().unwrap() {
        let index = report["stroke"].as_u64().unwrap() as usize;
        let stroke = &strokes[index];
        assert_eq!(stroke["stroke"], index);
        let length = report["length_m"].as_f64().unwrap();
        assert!((stroke["path"]["length_m"].as_f64().unwrap() - length).abs() < 1e-5);
        let reached: Vec<[f64; 2]> = serde_json::from_value(stroke["reached"].clone()).unwrap();
        let drawn: f64 = reached.iter().map(|r| r[1] - r[0]).sum();
        let reported = report["drawn_m"].as_f64().unwrap();
        assert!(
            (drawn - reported).abs() < 1e-3,
            "stroke {index}: the page draws {drawn} m, the program reports {reported} m"
        );
        let whole = report["unreached"].as_array().unwrap().is_empty()
            && report["parts_left_out"].as_array().unwrap().is_empty();
        assert_eq!(
            stroke["unreached"].as_array().unwrap().is_empty(),
            whole,
            "stroke {index}: {stroke}"
        );
    }
    let drawn = data["drawn_m"].as_f64().unwrap();
    assert!((drawn - summary["drawn_m"].as_f64().unwrap()).abs() < 3e-3);

    // Every segment, named, at its time; the moves with the TCP's polyline.
    let segments = data["segments"].as_array().unwrap();
    let listed = program["segments"].as_array().unwrap();
    assert_eq!(segments.len(), listed.len());
    for (shown, segment) in segments.iter().zip(listed) {
        assert_eq!(shown["name"].as_str().unwrap(), segment_name(segment));
        for end in ["start_s", "end_s"] {
            assert!((shown[end].as_f64().unwrap() - segment[end].as_f64().unwrap()).abs() < 1e-6);
        }
        let is_move = segment["kind"] != "stroke";
        assert_eq!(shown.get("tcp").is_some(), is_move, "{shown}");
        if is_move {
            assert!(shown["tcp"].as_array().unwrap().len() >= 2);
        }
    }

    // The arm through the whole program, at 50 Hz.
    let steps = data["steps"].as_array().unwrap();
    let duration = summary["duration_s"].as_f64().unwrap();
    let last = steps.last().unwrap()["t"].as_f64().unwrap();
    assert!((last - duration).abs() < 1e-6, "{last} s of {duration} s");
    let expected = duration * emg_viewer::JOB_PAGE_RATE_HZ;
    assert!(
        (steps.len() as f64) >= expected
            && (steps.len() as f64) <= expected + 2.0 * segments.len() as f64 + 2.0,
        "{} steps for {duration} s",
        steps.len()
    );
}

#[test]
fn job_html_is_refused_where_it_names_an_input_or_the_program() {
    let tmp = temp_dir("job-page-refused");
    let dir = tmp.path();
    let seams = dir.join("seams.json");
    std::fs::copy(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/seams.json"),
        &seams,
    )
    .unwrap();
    let out = dir.join("seams.job.json");
    for (html, clash) in [
        (seams.clone(), "which is the job file"),
        (out.clone(), "which is written by --out too"),
    ] {
        let output = common::emg(&[
            "job",
            seams.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--html",
            html.to_str().unwrap(),
        ]);
        assert!(
            !output.status.success(),
            "--html {} was accepted",
            html.display()
        );
        let stderr = common::text(&output.stderr);
        assert!(
            stderr.contains(&format!("--html would write {}", html.display()))
                && stderr.contains(clash),
            "{stderr}"
        );
        assert!(!out.exists(), "nothing is written");
    }
    assert_eq!(listing(dir), ["seams.json"]);
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn job_html_plays_in_a_browser_naming_each_segment() {
    let Some(browser) = browser::browser() else {
        return;
    };
    let tmp = temp_dir("job-page-browser");
    let dir = tmp.path();
    let job = seams_job();
    let run = browser::dump_dom(&browser, dir, &job.page);
    if let Err(problems) = browser::page_problems(&run) {
        panic!("the job page did not run cleanly:\n{problems}");
    }
    let segments = job.program["segments"].as_array().unwrap();
    for (index, segment) in segments.iter().enumerate() {
        let t = 0.5 * (segment["start_s"].as_f64().unwrap() + segment["end_s"].as_f64().unwrap());
        let script = browser::scrub_and_record(t, &["r-segment", "r-stroke"]);
        let run = browser::dump_dom(
            &browser,
            dir,
            &browser::with_extra_script(&job.page, &script),
        );
        if let Err(problems) = browser::page_problems(&run) {
            panic!("scrubbing to {t} s broke the job page:\n{problems}");
        }
        assert_eq!(
            browser::body_data(&run, "r-segment").as_deref(),
            Some(
                format!(
                    "{} ({} of {})",
                    segment_name(segment),
                    index + 1,
                    segments.len()
                )
                .as_str()
            ),
            "at {t} s"
        );
        let stroke = browser::body_data(&run, "r-stroke").unwrap_or_default();
        assert_eq!(
            segment["kind"] == "stroke",
            stroke.contains(" m of "),
            "at {t} s: {stroke}"
        );
    }
}
