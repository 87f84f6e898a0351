//! `emg place`: an icon placed where the arm draws little of it is moved to where the planner
//! draws all of it, the program there passed by `emg check`, the place written as a job file's
//! transform that `emg job` plans to the same program; the same by moving the robot's base in a
//! cell, the cell read back with the same transform; wrong regions refused naming what is wrong,
//! nothing written.

mod common;

use std::path::{Path, PathBuf};

use common::{emg, read_json, temp_dir, text};

fn pencil() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../io/tests/data/icons/pencil.svg")
}

/// lucide's pencil 0.3 m wide, pen down at 0.78 m in front of the FR3: near the edge of its
/// reach.
const FAR: [&str; 4] = ["--origin", "0.85,0,0.25", "--width", "0.3"];

/// The pen-down length drawn and in all of a program file.
fn drawn(program: &serde_json::Value) -> (f64, f64) {
    let summary = &program["summary"];
    (
        summary["drawn_m"].as_f64().unwrap(),
        summary["total_m"].as_f64().unwrap(),
    )
}

/// The six numbers of the `translation_m [...], rpy [...]` line `emg place` prints for the
/// job's transform.
fn printed_transform(stdout: &str) -> Vec<f64> {
    let line = stdout
        .lines()
        .find(|line| line.contains("the job's transform"))
        .unwrap_or_else(|| panic!("no transform printed:\n{stdout}"));
    line.split(['[', ']'])
        .skip(1)
        .step_by(2)
        .flat_map(|list| list.split(", ").map(|x| x.parse::<f64>().unwrap()))
        .collect()
}

#[test]
fn a_closed_standard_output_stops_no_file_being_written() {
    let dir = temp_dir("place-pipe");
    let file = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let seams = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/seams.json");
    let (placed, job_out) = (file("placed.json"), file("placed-job.json"));
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_emg"))
        .args([
            "place",
            seams.to_str().unwrap(),
            "--x=-0.02,0.02",
            "--y=-0.02,0.02",
            "--rotation=-5,5",
            "--positions",
            "2",
            "--rotations",
            "2",
            "--certify",
            "1",
            "--out",
            &placed,
            "--job-out",
            &job_out,
            "--export",
            "ros2-mcap",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // The reader goes before anything is printed, as `| head` does after its lines.
    drop(child.stdout.take());
    let output = child.wait_with_output().unwrap();
    let stderr = text(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for path in [&placed, &job_out, &file("placed.mcap")] {
        assert!(
            Path::new(path).is_file(),
            "{path} was not written: {stderr}"
        );
    }
}

#[test]
fn an_icon_out_of_reach_is_moved_to_where_it_is_drawn_whole() {
    let dir = temp_dir("place");
    let pencil = pencil();
    let file = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let mut job = vec!["job", pencil.to_str().unwrap()];
    job.extend(FAR);
    let far = file("far.json");
    let output = emg(&[&job[..], &["--out", &far]].concat());
    assert!(output.status.success(), "{}", text(&output.stderr));
    let (far_drawn, total) = drawn(&read_json(Path::new(&far)));
    assert!(
        far_drawn < 0.8 * total,
        "{far_drawn} of {total} m drawn where it stands"
    );

    let (placed, map, export) = (
        file("placed.json"),
        file("map.svg"),
        file("placed-job.json"),
    );
    let mut place = vec!["place", pencil.to_str().unwrap()];
    place.extend(FAR);
    place.extend([
        "--x=-0.3,0",
        "--y=-0.1,0.1",
        "--rotation=-45,45",
        "--positions",
        "3",
        "--rotations",
        "2",
        "--certify",
        "2",
        "--out",
        &placed,
        "--map",
        &map,
        "--job-out",
        &export,
    ]);
    let output = emg(&place);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let stdout = text(&output.stdout);
    // 3 × 3 positions, 3 heights along the normal, 2 turns.
    assert!(stdout.contains("screened 54 places"), "{stdout}");
    // The transform printed is the one written, to the last bit.
    let printed = printed_transform(&stdout);
    let transform = &read_json(Path::new(&export))["transform"];
    let written: Vec<f64> = ["translation_m", "rpy"]
        .iter()
        .flat_map(|key| transform[key].as_array().unwrap().clone())
        .map(|value| value.as_f64().unwrap())
        .collect();
    assert_eq!(printed, written, "{stdout}");
    let (placed_drawn, placed_total) = drawn(&read_json(Path::new(&placed)));
    assert!((placed_total - total).abs() < 1e-9);
    assert!(
        placed_drawn > total - 1e-3,
        "{placed_drawn} of {total} m drawn at the chosen place:\n{stdout}"
    );
    let check = emg(&["check", &placed]);
    assert!(check.status.success(), "{}", text(&check.stdout));
    let svg = std::fs::read_to_string(&map).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("planned places ranked"));

    // A region too small to draw it whole: the chosen place lies on the edge of --x, and the
    // user is told that a larger range may draw more.
    let mut small = vec!["place", pencil.to_str().unwrap()];
    small.extend(FAR);
    let cramped = file("cramped.json");
    small.extend([
        "--x=-0.05,0",
        "--y=0,0",
        "--z=0,0",
        "--rotation=0,0",
        "--positions",
        "2",
        "--rotations",
        "1",
        "--certify",
        "1",
        "--out",
        &cramped,
    ]);
    let output = emg(&small);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let stdout = text(&output.stdout);
    let (cramped_drawn, _) = drawn(&read_json(Path::new(&cramped)));
    assert!(cramped_drawn < total - 1e-3, "{stdout}");
    assert!(
        stdout.contains("the best place is on the edge of --x (its ")
            && stdout.contains("a larger range may draw more"),
        "{stdout}"
    );
    assert!(!stdout.contains("edge of --y"), "{stdout}");

    // The exported job file plans the same program.
    let again = file("again.json");
    let output = emg(&["job", &export, "--out", &again]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    assert_eq!(
        read_json(Path::new(&again))["segments"],
        read_json(Path::new(&placed))["segments"]
    );
}

#[test]
fn the_base_is_moved_in_its_cell_to_where_the_icon_is_drawn_whole() {
    let dir = temp_dir("place-base");
    let pencil = pencil();
    let cell = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/cell.json");
    let file = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let (placed, export) = (file("placed.json"), file("placed-job.json"));
    let mut place = vec!["place", pencil.to_str().unwrap()];
    place.extend(FAR);
    place.extend([
        "--scene",
        cell.to_str().unwrap(),
        "--move",
        "base",
        "--x=0,0.3",
        "--y=-0.1,0.1",
        "--rotation=-30,30",
        "--positions",
        "3",
        "--rotations",
        "2",
        "--certify",
        "2",
        "--out",
        &placed,
        "--job-out",
        &export,
    ]);
    let output = emg(&place);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let stdout = text(&output.stdout);
    assert!(stdout.contains("the base's new pose"), "{stdout}");
    let program = read_json(Path::new(&placed));
    let (drawn_m, total_m) = drawn(&program);
    assert!(
        drawn_m > total_m - 1e-3,
        "{drawn_m} of {total_m} m:\n{stdout}"
    );
    let check = emg(&["check", &placed]);
    assert!(check.status.success(), "{}", text(&check.stdout));
    // In the moved base's frame the cell moves as the job does: the cell file with the job's
    // transform plans the same program.
    let job = read_json(Path::new(&export));
    let mut scene = read_json(&cell);
    scene["transform"] = job["transform"].clone();
    let moved_cell = file("cell-moved.json");
    std::fs::write(&moved_cell, scene.to_string()).unwrap();
    let again = file("again.json");
    let output = emg(&["job", &export, "--scene", &moved_cell, "--out", &again]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    assert_eq!(
        read_json(Path::new(&again))["segments"],
        program["segments"]
    );
}

#[test]
fn wrong_regions_are_refused_and_nothing_is_written() {
    let dir = temp_dir("place-refused");
    let out = dir.path().join("placed.json");
    let pencil = pencil();
    let refused = |extra: &[&str], expected: &str| {
        let mut args = vec![
            "place",
            pencil.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--positions",
            "2",
            "--rotations",
            "1",
        ];
        args.extend(extra);
        let output = emg(&args);
        assert!(!output.status.success(), "{extra:?} was accepted");
        let stderr = text(&output.stderr);
        assert!(stderr.contains(expected), "{extra:?}: {stderr}");
        assert!(!out.exists(), "{extra:?} wrote {}", out.display());
    };
    refused(&["--x=0.2,-0.2"], "region field 'x_m'");
    refused(&["--rotation=10,nan"], "region field 'rotation_deg'");
    refused(&["--z=0.1,-0.1"], "region field 'z_m'");
    refused(&["--y=0.1"], "is not MIN,MAX");
    // Two metres beyond the arm's reach.
    refused(&["--x=2,2.5"], "no place of the region lets the arm reach");
}

#[test]
fn the_ur5e_house_is_placed_with_the_default_region_heights_included_and_drawn_whole() {
    let dir = temp_dir("place-house");
    let house = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/cases/house.svg");
    let placed = dir.path().join("placed.json");
    let output = emg(&[
        "place",
        house.to_str().unwrap(),
        "--robot",
        "ur5e",
        "--out",
        placed.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let stdout = text(&output.stdout);
    // 10 × 10 positions, 3 heights 3 cm either side of the surface, 5 turns.
    assert!(stdout.contains("screened 1500 places"), "{stdout}");
    let (drawn_m, total_m) = drawn(&read_json(&placed));
    assert!(
        drawn_m >= 0.99 * total_m,
        "{drawn_m} of {total_m} m:\n{stdout}"
    );
}
