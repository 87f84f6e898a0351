//! `emg job`: an SVG placed where its options say, and wrong jobs refused naming what is wrong,
//! nothing written.

mod common;

use std::path::Path;

use common::{emg, read_json, temp_dir, text};

fn examples() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

#[test]
fn a_drawing_lands_where_its_placement_options_put_it() {
    let dir = temp_dir("job-placement");
    let out = dir.path().join("house.job.json");
    let drawing = examples().join("drawing.svg");
    let output = emg(&[
        "job",
        drawing.to_str().unwrap(),
        "--origin",
        "0.5,0.1,0.25",
        "--width",
        "0.1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let program = read_json(&out);
    let mut low = [f64::INFINITY; 3];
    let mut high = [f64::NEG_INFINITY; 3];
    for segment in program["segments"].as_array().unwrap() {
        if let Some(start) = segment["task"]["path"]["start"].as_array() {
            for (axis, value) in start.iter().enumerate() {
                let value = value.as_f64().unwrap();
                low[axis] = low[axis].min(value);
                high[axis] = high[axis].max(value);
            }
        }
    }
    // Every stroke starts on the plane z = 0.25, round (0.5, 0.1): the drawing 0.1 m wide along
    // its x axis (the base's −y by default) and, taller than wide, up to 0.12 m along the
    // base's x.
    assert!((low[2] - 0.25).abs() < 1e-9 && (high[2] - 0.25).abs() < 1e-9);
    for (axis, centre, half) in [(0, 0.5, 0.06), (1, 0.1, 0.0501)] {
        assert!(
            low[axis] >= centre - half && high[axis] <= centre + half,
            "axis {axis}: {low:?} to {high:?}"
        );
    }
}

#[test]
fn wrong_jobs_are_refused_and_nothing_is_written() {
    let dir = temp_dir("job-refused");
    let out = dir.path().join("out.job.json");
    let refused = |file: &Path, extra: &[&str], expected: &str| {
        let mut args = vec![
            "job",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let output = emg(&args);
        assert_eq!(output.status.code(), Some(1), "{}", text(&output.stdout));
        let stderr = text(&output.stderr);
        assert!(stderr.contains(expected), "{stderr}");
        assert!(!out.exists(), "{} was written", out.display());
    };
    let empty = dir.path().join("empty.json");
    std::fs::write(&empty, r#"{"version": 1, "strokes": []}"#).unwrap();
    refused(&empty, &[], "job field 'strokes' is empty");
    let blank = dir.path().join("blank.svg");
    std::fs::write(
        &blank,
        r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 10"></svg>"#,
    )
    .unwrap();
    refused(&blank, &[], "holds no stroke");
    let drawing = examples().join("drawing.svg");
    refused(
        &drawing,
        &["--origin", "3,0,0.25"],
        "no stroke of the job can be drawn",
    );
    refused(
        &examples().join("seams.json"),
        &["--width", "0.1"],
        "place an SVG drawing",
    );
}
