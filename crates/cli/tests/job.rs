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

#[test]
fn tolerance_and_cone_take_negative_values_and_refuse_them_in_their_unit() {
    let seams = examples().join("seams.json");
    let seams = seams.to_str().unwrap();
    for command in [&["plan"][..], &["job", seams], &["place", seams]] {
        for (option, expected) in [
            (&["--tolerance", "-1"][..], "must be > 0 mm, got -1"),
            (&["--tolerance=-0.5"][..], "must be > 0 mm, got -0.5"),
            (&["--cone", "95"][..], "must be in (0, 90)°, got 95"),
        ] {
            let output = emg(&[command, option].concat());
            let stderr = text(&output.stderr);
            assert!(
                !output.status.success()
                    && stderr.contains(&format!("'{}", option[0].split('=').next().unwrap()))
                    && stderr.contains(expected),
                "{command:?} {option:?}: {stderr}"
            );
        }
    }
}

#[test]
fn a_path_file_is_a_job_of_one_stroke_and_an_svg_keeps_its_physical_size() {
    let dir = temp_dir("job-path-file");
    // Missing parent directories of --out are created.
    let out = dir.path().join("new/sub/slot.job.json");
    let slot = examples().join("slot.json");
    let output = emg(&[
        "job",
        slot.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let stdout = text(&output.stdout);
    assert!(stdout.contains("\n1 stroke: 1 complete"), "{stdout}");
    assert_eq!(read_json(&out)["strokes"].as_array().unwrap().len(), 1);

    // 100 mm wide, a line of 80 of its 100 units.
    let svg = dir.path().join("ruler.svg");
    std::fs::write(
        &svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="50mm" viewBox="0 0 100 50">
           <path d="M 10 25 L 90 25" stroke="black"/></svg>"#,
    )
    .unwrap();
    let total = |extra: &[&str]| {
        let out = dir.path().join("ruler.job.json");
        let mut args = vec!["job", svg.to_str().unwrap(), "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let output = emg(&args);
        assert!(output.status.success(), "{}", text(&output.stderr));
        read_json(&out)["summary"]["total_m"].as_f64().unwrap()
    };
    // usvg reads the drawing in single precision: within a micrometre.
    assert!((total(&["--scale", "physical"]) - 0.08).abs() < 1e-6);
    // A scale is metres per CSS pixel (96 to the inch) of the drawing's own size.
    let pixels = 0.08 / (0.0254 / 96.0);
    assert!((total(&["--scale", "5e-4"]) - pixels * 5e-4).abs() < 1e-6);
    assert!((total(&[]) - 0.2).abs() < 1e-6, "the default width");
    let both = emg(&[
        "job",
        svg.to_str().unwrap(),
        "--scale",
        "physical",
        "--width",
        "0.1",
    ]);
    assert!(
        text(&both.stderr).contains("--width"),
        "{}",
        text(&both.stderr)
    );
}

/// A job starts and ends at the shipped arm's home unless `--home` gives another; a home that
/// does not fit the arm is refused naming `--home`; `emg check` prints the claims it measured,
/// and refuses a program of the first version, whose claims it cannot check.
#[test]
fn a_job_runs_from_home_and_back_and_check_reports_its_claims() {
    let dir = temp_dir("job-home");
    let drawing = examples().join("drawing.svg");
    let plan = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec![
            "job",
            drawing.to_str().unwrap(),
            "--robot",
            "ur5e",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        (emg(&args), out)
    };
    let home_of = |program: &serde_json::Value| -> Vec<f64> {
        serde_json::from_value(program["home"].clone()).expect("a home")
    };
    let first_and_last = |program: &serde_json::Value| -> (Vec<f64>, Vec<f64>) {
        let points = emg_job::JobFile::parse(&program.to_string())
            .expect("a program")
            .points();
        (
            points[0].positions.clone(),
            points[points.len() - 1].positions.clone(),
        )
    };
    let (output, out) = plan("shipped.job.json", &[]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let program = read_json(&out);
    let ur_home = vec![
        0.0,
        -std::f64::consts::FRAC_PI_2,
        0.0,
        -std::f64::consts::FRAC_PI_2,
        0.0,
        0.0,
    ];
    assert_eq!(home_of(&program), ur_home);
    assert_eq!(first_and_last(&program), (ur_home.clone(), ur_home));
    let given = [0.2, -1.4, 0.3, -1.7, -0.1, 0.4];
    let listed = given.map(|v| v.to_string()).join(",");
    let (output, out) = plan("given.job.json", &["--home", &listed]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let program = read_json(&out);
    assert_eq!(home_of(&program), given.to_vec());
    assert_eq!(first_and_last(&program), (given.to_vec(), given.to_vec()));
    let checked = emg(&["check", out.to_str().unwrap()]);
    assert!(checked.status.success(), "{}", text(&checked.stderr));
    let report = text(&checked.stdout);
    assert!(
        report.contains("claims as the samples draw them: pen down")
            && report.contains("from home and back"),
        "{report}"
    );
    let (output, out) = plan("short.job.json", &["--home", "0,-1.5"]);
    assert!(!output.status.success() && !out.exists());
    assert!(
        text(&output.stderr).contains("--home has 2 values; ur5e_pen has 6 joints"),
        "{}",
        text(&output.stderr)
    );
    // A program of the first version is refused naming its version.
    let mut old = program.clone();
    old["format"] = serde_json::Value::from("emg-job/1");
    let old_file = dir.path().join("old.job.json");
    std::fs::write(&old_file, old.to_string()).unwrap();
    let refused = emg(&["check", old_file.to_str().unwrap()]);
    assert!(!refused.status.success());
    assert!(
        text(&refused.stderr).contains("is an emg-job/1 program, which this emg does not read"),
        "{}",
        text(&refused.stderr)
    );
}
