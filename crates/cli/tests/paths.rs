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
