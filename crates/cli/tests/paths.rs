//! End-to-end tests of path tasks: the example of docs/paths.md planned with `emg plan --path`
//! to the end of its path, every file it writes verified by `emg check`, and malformed path files
//! refused naming the field.

mod common;

use std::path::Path;

use common::{emg, read_json, temp_dir, text};

/// The JSON example of docs/paths.md.
fn documented_example() -> String {
    let doc = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/paths.md");
    let doc = std::fs::read_to_string(doc).expect("docs/paths.md");
    let start = doc.find("```json\n").expect("a JSON example") + "```json\n".len();
    let end = start + doc[start..].find("```").expect("the example's end");
    doc[start..end].to_string()
}

#[test]
fn the_documented_slot_is_planned_to_its_end_and_every_file_checks() {
    let dir = temp_dir("path");
    let file = dir.path().join("slot.json");
    std::fs::write(&file, documented_example()).unwrap();
    let stem = dir.path().join("plan");
    let output = emg(&[
        "plan",
        "--path",
        file.to_str().unwrap(),
        "--out",
        stem.to_str().unwrap(),
    ]);
    let stdout = text(&output.stdout);
    assert!(output.status.success(), "{}", text(&output.stderr));
    assert!(
        stdout.contains("ended: reached the end of the path"),
        "{stdout}"
    );
    let written = read_json(&stem.with_extension("json"));
    assert_eq!(written["termination"]["reason"], "completed");
    let slot = 0.6 + std::f64::consts::PI * 0.1;
    let length = written["path_length_m"].as_f64().unwrap();
    assert!((length - slot).abs() < 2e-4, "{length} of {slot}");
    assert_eq!(
        written["task"]["path"]["segments"]
            .as_array()
            .unwrap()
            .len(),
        4
    );
    for ext in ["json", "joint_trajectory.json", "csv"] {
        let path = dir.path().join(format!("plan.{ext}"));
        let output = emg(&["check", path.to_str().unwrap()]);
        assert!(
            output.status.success(),
            "{ext}: {}{}",
            text(&output.stdout),
            text(&output.stderr)
        );
    }
}

/// Plans `args` at a tenth of a millimetre into `stem`, checks every file it writes with `emg
/// check`, and returns the trajectory file.
fn planned_at_a_tenth_of_a_millimetre(dir: &Path, stem: &str, args: &[&str]) -> serde_json::Value {
    let out = dir.join(stem);
    let mut all = vec!["plan", "--tolerance", "0.1", "--out", out.to_str().unwrap()];
    all.extend_from_slice(args);
    let output = emg(&all);
    assert!(output.status.success(), "{stem}: {}", text(&output.stderr));
    for ext in ["json", "joint_trajectory.json"] {
        let path = dir.join(format!("{stem}.{ext}"));
        let output = emg(&["check", path.to_str().unwrap()]);
        assert!(
            output.status.success(),
            "{stem}.{ext}: {}{}",
            text(&output.stdout),
            text(&output.stderr)
        );
    }
    read_json(&dir.join(format!("{stem}.json")))
}

#[test]
fn a_circle_a_blended_rectangle_and_a_long_line_are_planned_and_checked_at_a_tenth_of_a_millimetre()
{
    let dir = temp_dir("tenth");
    let circle = dir.path().join("circle.path.json");
    std::fs::write(
        &circle,
        r#"{"version": 1, "start": [0.6, 0.0, 0.2], "normal": [0, 0, -1],
            "segments": [{"arc": {"centre": [0.5, 0.0, 0.2], "sweep_deg": 360}}]}"#,
    )
    .unwrap();
    let rectangle = dir.path().join("rectangle.path.json");
    std::fs::write(
        &rectangle,
        r#"{"version": 1, "start": [0.4, -0.2, 0.2], "normal": [0, 0, -1], "blend_radius_m": 0.02,
            "segments": [{"line": {"to": [0.6, -0.2, 0.2]}}, {"line": {"to": [0.6, 0.2, 0.2]}},
                         {"line": {"to": [0.4, 0.2, 0.2]}}, {"line": {"to": [0.4, -0.2, 0.2]}}]}"#,
    )
    .unwrap();
    for (stem, path) in [("circle", &circle), ("rectangle", &rectangle)] {
        let written = planned_at_a_tenth_of_a_millimetre(
            dir.path(),
            stem,
            &["--path", path.to_str().unwrap()],
        );
        assert_eq!(written["termination"]["reason"], "completed", "{stem}");
        assert_eq!(written["config"]["constraints"]["line_tolerance_m"], 1e-4);
    }
    // The README's line: a metre at 0.1 mm, as at 20 mm.
    let line = planned_at_a_tenth_of_a_millimetre(
        dir.path(),
        "line",
        &["--p0", "0.45,-0.2,0.25", "--d", "0,1,0", "--n", "0,0,-1"],
    );
    let length = line["path_length_m"].as_f64().unwrap();
    assert!(length > 1.0, "{length} m at 0.1 mm");
}

#[test]
fn a_round_letter_gone_round_twice_is_timed_from_its_start() {
    // The `o` of a serif single-stroke font (Hershey's `timesr`) with its corners rounded: two
    // loops 2.3 mm across, the second a fraction of a millimetre inside the first and meeting
    // it at the start. The timing's refinement once moved a chord midpoint toward the nearest
    // point of the whole path (on the other loop), and the motion was cut at its first point.
    let dir = temp_dir("double-loop");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/double-loop.path.json");
    let out = dir.path().join("loop");
    let output = emg(&[
        "plan",
        "--tolerance",
        "0.375",
        "--path",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let trajectory = dir.path().join("loop.joint_trajectory.json");
    let points = read_json(&trajectory)["points"].as_array().unwrap().len();
    assert!(points > 300, "the motion is cut to {points} samples");
    let output = emg(&["check", trajectory.to_str().unwrap()]);
    assert!(output.status.success(), "{}", text(&output.stdout));
}

#[test]
fn a_malformed_path_file_is_refused_naming_the_field() {
    let dir = temp_dir("bad-path");
    let cases = [
        (
            r#"{"version": 1, "start": [0.5, 0, 0.2], "normal": [0, 0, -1], "segments": [{"line": {"to": [0.5, 0.2, 0.25]}}]}"#,
            "path field 'segments[0].line.to' lies",
        ),
        (
            r#"{"version": 1, "start": [0.5, 0, 0.2], "normal": [0, 0, -1], "segments": [{"arc": {"centre": [0.55, 0, 0.2], "to": [0.6, 0, 0.2]}}]}"#,
            "ambiguous",
        ),
        (
            r#"{"version": 1, "start": [0.5, 0, 0.2], "normal": [0, 0, -1], "blend_radius_m": 0.2, "segments": [{"line": {"to": [0.5, 0.1, 0.2]}}, {"line": {"to": [0.6, 0.1, 0.2]}}]}"#,
            "path field 'blend_radius_m' cannot round the corner between segments 0 and 1",
        ),
        (
            r#"{"version": 3, "start": [0.5, 0, 0.2], "normal": [0, 0, -1], "segments": []}"#,
            "path field 'version' is 3",
        ),
        (
            r#"{"version": 1, "start": [0.5, 0, 0.2], "normal": [0, 0, -1], "segments": [{"spiral": {}}]}"#,
            "unknown variant `spiral`",
        ),
    ];
    for (index, (json, expected)) in cases.iter().enumerate() {
        let file = dir.path().join(format!("bad-{index}.json"));
        std::fs::write(&file, json).unwrap();
        let output = emg(&[
            "plan",
            "--path",
            file.to_str().unwrap(),
            "--out",
            "/nonexistent/x",
        ]);
        let stderr = text(&output.stderr);
        assert!(!output.status.success());
        assert!(stderr.contains("invalid path file"), "{stderr}");
        assert!(stderr.contains(expected), "case {index}: {stderr}");
    }
}
