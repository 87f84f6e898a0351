//! Task validation (`Task::new`) and task-set files (`write_task_set` / `read_tasks`).
//!
//! Every rejection names the offending field (and the joint, for a seed outside its limits);
//! valid input is normalised and `d` is made exactly perpendicular to `n`. Binary task sets
//! round-trip bit for bit (including a task without `q0_seed`); truncated, padded, foreign,
//! wrong-version and wrong-width files are refused with a message saying so; JSON files report
//! the index and field of an invalid task and the name of an unknown key.

mod common;

use std::path::PathBuf;

use emg_control::{SEED_POSITION_TOLERANCE_M, Task, TaskError};
use emg_io::{TaskFileError, read_tasks, write_task_set};
use emg_kinematics::{JointVector, Robot, Vec3};

use common::{robot, tasks};

/// A valid start: the TCP at mid-range, with its tool axis and a direction ⟂ to it.
fn valid(robot: &Robot) -> (Vec3, Vec3, Vec3, JointVector) {
    let q = robot.mid_range();
    let kin = robot.forward(&q);
    let n = kin.tool_axis();
    let d = n.cross(&Vec3::new(0.3, -0.5, 0.8)).normalize();
    (kin.tcp(), d, n, q)
}

fn message(result: Result<Task, TaskError>) -> String {
    result.expect_err("must be rejected").to_string()
}

#[test]
fn rejections_name_the_field() {
    let robot = robot();
    let (p0, d, n, q) = valid(&robot);
    Task::new(&robot, p0, d, n, Some(q)).expect("the valid task is accepted");

    let m = message(Task::new(&robot, p0, Vec3::zeros(), n, None));
    assert!(m.contains("'d'") && m.contains("zero"), "{m}");
    assert_eq!(
        Task::new(&robot, p0, Vec3::zeros(), n, None),
        Err(TaskError::ZeroVector { field: "d" })
    );
    let m = message(Task::new(&robot, p0, d * 1e-12, n, None));
    assert!(m.contains("'d'"), "a numerically zero d: {m}");

    let m = message(Task::new(&robot, p0, d, Vec3::zeros(), None));
    assert!(m.contains("'n'") && m.contains("zero"), "{m}");

    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let m = message(Task::new(&robot, Vec3::new(p0.x, bad, p0.z), d, n, None));
        assert!(m.contains("'p0'") && m.contains("not finite"), "{m}");
        let m = message(Task::new(&robot, p0, Vec3::new(bad, 0.0, 1.0), n, None));
        assert!(m.contains("'d'"), "{m}");
        let m = message(Task::new(&robot, p0, d, Vec3::new(0.0, 1.0, bad), None));
        assert!(m.contains("'n'"), "{m}");
        let mut seed = q;
        seed[2] = bad;
        let m = message(Task::new(&robot, p0, d, n, Some(seed)));
        assert!(m.contains("'q0_seed'"), "{m}");
    }

    let m = message(Task::new(&robot, p0, d + n * 0.1, n, None));
    assert!(
        m.contains("'d'") && m.contains("'n'") && m.contains("perpendicular"),
        "{m}"
    );
    let m = message(Task::new(&robot, p0, n, n, None));
    assert!(m.contains("'d'") && m.contains("'n'"), "parallel: {m}");
    assert!(
        Task::new(&robot, p0, d + n * 1e-5, n, None).is_err(),
        "|d·n| = 1e-5 exceeds the tolerance"
    );

    let far = p0 + Vec3::new(5.0, 0.0, 0.0);
    let m = message(Task::new(&robot, far, d, n, None));
    assert!(m.contains("'p0'") && m.contains("unreachable"), "{m}");
    let (centre, reach) = robot.reach_sphere();
    assert!(reach > 0.8 && reach < 1.5, "reach {reach}");
    assert!(
        Task::new(
            &robot,
            centre + Vec3::new(0.0, reach * 1.01, 0.0),
            d,
            n,
            None
        )
        .is_err()
    );
    assert!(
        Task::new(
            &robot,
            centre + Vec3::new(0.0, reach * 0.99, 0.0),
            d,
            n,
            None
        )
        .is_ok()
    );

    for (joint, upper) in [(1usize, true), (4, true), (6, false), (7, false)] {
        let mut seed = q;
        seed[joint - 1] = if upper {
            robot.limits().upper[joint - 1] + 1e-3
        } else {
            robot.limits().lower[joint - 1] - 1e-3
        };
        let m = message(Task::new(&robot, p0, d, n, Some(seed)));
        assert!(
            m.contains("'q0_seed'") && m.contains(&format!("joint {joint} ")),
            "{m}"
        );
    }

    let m = message(Task::new(
        &robot,
        p0 + Vec3::new(0.0, 0.0, 0.01),
        d,
        n,
        Some(q),
    ));
    assert!(m.contains("'q0_seed'") && m.contains("p0"), "{m}");
    // Within the documented tolerance the seed is accepted.
    let near = p0 + Vec3::new(0.0, 0.0, SEED_POSITION_TOLERANCE_M * 0.5);
    Task::new(&robot, near, d, n, Some(q)).expect("seed within tolerance");
    assert!(
        Task::new(
            &robot,
            p0 + Vec3::new(0.0, 0.0, SEED_POSITION_TOLERANCE_M * 2.0),
            d,
            n,
            Some(q)
        )
        .is_err()
    );
}

#[test]
fn valid_input_is_normalised_and_made_perpendicular() {
    let robot = robot();
    let (p0, d, n, q) = valid(&robot);
    let task = Task::new(&robot, p0, d * 3.0, n * 0.2, Some(q)).unwrap();
    assert!((task.d.norm() - 1.0).abs() < 1e-15 && (task.n.norm() - 1.0).abs() < 1e-15);
    assert!((task.d - d).norm() < 1e-15 && (task.n - n).norm() < 1e-15);
    assert_eq!(task.p0, p0);
    assert_eq!(task.q0_seed, Some(q));

    // Nearly perpendicular: removed exactly (to rounding) and still a unit vector.
    for n in [
        Vec3::new(0.2, -0.4, 0.9).normalize(),
        Vec3::z(),
        Vec3::new(-0.7, 0.7, 0.1).normalize(),
    ] {
        let d = n.cross(&Vec3::new(1.0, 2.0, -0.3)).normalize();
        let tilted = (d + n * 1e-8).normalize();
        assert!((tilted.dot(&n) - 1e-8).abs() < 1e-12);
        let task = Task::new(&robot, p0, tilted, n, None).unwrap();
        assert!(
            task.d.dot(&task.n).abs() < 1e-16,
            "d·n = {}",
            task.d.dot(&task.n)
        );
        assert!((task.d.norm() - 1.0).abs() < 1e-15);
        assert!((task.d - d).norm() < 1e-12);
    }
    // Validating a validated task changes nothing, bit for bit.
    for (_, task) in tasks(&robot, 200) {
        let again = Task::new(&robot, task.p0, task.d, task.n, task.q0_seed).unwrap();
        assert_eq!(bits(again.d.as_slice()), bits(task.d.as_slice()));
        assert_eq!(bits(again.n.as_slice()), bits(task.n.as_slice()));
        assert_eq!(again, task);
    }
    // The helper methods use the normalised fields.
    let task = Task::new(&robot, p0, d, n, None).unwrap();
    let side = n.cross(&d);
    let p = p0 + d * 0.3 + side * 0.01 + n * 0.02;
    assert!((task.progress(&p) - 0.3).abs() < 1e-15);
    assert!((task.lateral_error(&p) - (-(side * 0.01 + n * 0.02))).norm() < 1e-15);
}

/// A path inside a fresh temporary directory, which is removed on drop.
struct TempFile {
    path: PathBuf,
    _dir: tempfile::TempDir,
}

impl TempFile {
    fn new(name: &str) -> Self {
        let dir = tempfile::Builder::new()
            .prefix("emg-control-test-")
            .tempdir()
            .expect("create temp dir");
        Self {
            path: dir.path().join(name),
            _dir: dir,
        }
    }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn sample_set(robot: &Robot) -> Vec<Task> {
    let mut set: Vec<Task> = tasks(robot, 40).into_iter().map(|(_, t)| t).collect();
    let (p0, d, n, _) = valid(robot);
    set.insert(3, Task::new(robot, p0, d, n, None).unwrap());
    // Awkward values: a direction that is not exactly unit after one normalisation, a far start.
    let odd = Task::new(
        robot,
        Vec3::new(0.1, -0.7, 0.3),
        Vec3::new(1.0, 1.0, 1.0 / 3.0),
        Vec3::new(-1.0, 1.0, 0.0),
        None,
    );
    set.push(odd.unwrap());
    set
}

#[test]
fn binary_task_sets_round_trip_bit_for_bit() {
    let robot = robot();
    let set = sample_set(&robot);
    let file = TempFile::new("roundtrip.tasks");
    write_task_set(&file.path, &set).unwrap();
    let bytes = std::fs::read(&file.path).unwrap();
    assert_eq!(bytes.len(), 24 + set.len() * 16 * 8);
    assert_eq!(&bytes[..8], b"EMGTASKS");
    let back = read_tasks(&file.path, &robot).unwrap();
    assert_eq!(back.len(), set.len());
    for (i, (a, b)) in set.iter().zip(&back).enumerate() {
        assert_eq!(
            bits(a.p0.as_slice()),
            bits(b.p0.as_slice()),
            "p0 of task {i}"
        );
        assert_eq!(bits(a.d.as_slice()), bits(b.d.as_slice()), "d of task {i}");
        assert_eq!(bits(a.n.as_slice()), bits(b.n.as_slice()), "n of task {i}");
        match (&a.q0_seed, &b.q0_seed) {
            (Some(x), Some(y)) => assert_eq!(
                bits(x.as_slice()),
                bits(y.as_slice()),
                "q0_seed of task {i}"
            ),
            (None, None) => {}
            _ => panic!("q0_seed presence of task {i} changed"),
        }
    }
    assert!(back[3].q0_seed.is_none());
    // An empty set round-trips too.
    write_task_set(&file.path, &[]).unwrap();
    assert!(read_tasks(&file.path, &robot).unwrap().is_empty());
}

fn format_error(result: Result<Vec<Task>, TaskFileError>) -> String {
    match result {
        Err(e @ TaskFileError::Format { .. }) => e.to_string(),
        other => panic!("expected a format error, got {other:?}"),
    }
}

#[test]
fn damaged_binary_files_are_refused() {
    let robot = robot();
    let set: Vec<Task> = tasks(&robot, 3).into_iter().map(|(_, t)| t).collect();
    let file = TempFile::new("damaged.tasks");
    write_task_set(&file.path, &set).unwrap();
    let good = std::fs::read(&file.path).unwrap();

    for cut in [8, 1, good.len() - 24 - 1] {
        std::fs::write(&file.path, &good[..good.len() - cut]).unwrap();
        let m = format_error(read_tasks(&file.path, &robot));
        assert!(m.contains("truncated"), "cut {cut}: {m}");
        assert!(
            m.contains(&file.path.display().to_string()),
            "the path is named: {m}"
        );
    }
    // Cut inside the header, after the magic.
    for keep in [12, 20] {
        std::fs::write(&file.path, &good[..keep]).unwrap();
        let m = format_error(read_tasks(&file.path, &robot));
        assert!(m.contains("truncated"), "header cut to {keep} bytes: {m}");
    }
    let mut padded = good.clone();
    padded.extend_from_slice(&[0; 8]);
    std::fs::write(&file.path, &padded).unwrap();
    assert!(format_error(read_tasks(&file.path, &robot)).contains("padded"));

    let mut foreign = good.clone();
    foreign[..8].copy_from_slice(b"NOTTASKS");
    std::fs::write(&file.path, &foreign).unwrap();
    assert!(format_error(read_tasks(&file.path, &robot)).contains("EMGTASKS"));
    std::fs::write(&file.path, b"").unwrap();
    format_error(read_tasks(&file.path, &robot));

    let mut version = good.clone();
    version[8..12].copy_from_slice(&7u32.to_le_bytes());
    std::fs::write(&file.path, &version).unwrap();
    let m = format_error(read_tasks(&file.path, &robot));
    assert!(m.contains("version 7"), "{m}");

    let mut width = good.clone();
    width[12..16].copy_from_slice(&15u32.to_le_bytes());
    std::fs::write(&file.path, &width).unwrap();
    assert!(format_error(read_tasks(&file.path, &robot)).contains("15 values per task"));

    let mut count = good.clone();
    count[16..24].copy_from_slice(&u64::MAX.to_le_bytes());
    std::fs::write(&file.path, &count).unwrap();
    format_error(read_tasks(&file.path, &robot));

    // A binary record holding an invalid task is reported with its index.
    let mut invalid = good.clone();
    let record = 24 + 2 * 16 * 8;
    for k in 0..3 {
        invalid[record + 24 + 8 * k..record + 32 + 8 * k].copy_from_slice(&0f64.to_le_bytes());
    }
    std::fs::write(&file.path, &invalid).unwrap();
    match read_tasks(&file.path, &robot) {
        Err(TaskFileError::Task {
            index: 2,
            source: TaskError::ZeroVector { field: "d" },
            ..
        }) => {}
        other => panic!("expected task 2's zero d, got {other:?}"),
    }

    let missing = TempFile::new("missing.tasks");
    assert!(matches!(
        read_tasks(&missing.path, &robot),
        Err(TaskFileError::Io { .. })
    ));
}

#[test]
fn json_task_files() {
    let robot = robot();
    let (p0, d, n, q) = valid(&robot);
    let spec = |p0: Vec3, d: Vec3, seed: Option<JointVector>| {
        let mut value = serde_json::json!({"p0": [p0.x, p0.y, p0.z], "d": [d.x, d.y, d.z], "n": [n.x, n.y, n.z]});
        if let Some(q) = seed {
            value["q0_seed"] = serde_json::json!(q.as_slice());
        }
        value
    };
    let file = TempFile::new("tasks.json");

    // A list, and a single object, both read.
    let list = serde_json::json!([spec(p0, d, Some(q)), spec(p0 + d * 0.01, d * 2.0, None)]);
    std::fs::write(&file.path, list.to_string()).unwrap();
    let read = read_tasks(&file.path, &robot).unwrap();
    assert_eq!(read.len(), 2);
    assert_eq!(read[0].q0_seed, Some(q));
    assert!(read[1].q0_seed.is_none() && (read[1].d.norm() - 1.0).abs() < 1e-15);
    std::fs::write(&file.path, spec(p0, d, None).to_string()).unwrap();
    assert_eq!(read_tasks(&file.path, &robot).unwrap().len(), 1);

    // One invalid task: its index and field are named.
    let cases = [
        (spec(p0, Vec3::zeros(), None), "'d'"),
        (spec(p0 + Vec3::new(5.0, 0.0, 0.0), d, None), "'p0'"),
        (
            spec(p0 + Vec3::new(0.0, 0.0, 0.01), d, Some(q)),
            "'q0_seed'",
        ),
        (spec(p0, d + n * 0.5, None), "'n'"),
    ];
    for (bad, field) in cases {
        let list = serde_json::json!([
            spec(p0, d, None),
            spec(p0, d, Some(q)),
            bad,
            spec(p0, d, None)
        ]);
        std::fs::write(&file.path, list.to_string()).unwrap();
        match read_tasks(&file.path, &robot) {
            Err(e @ TaskFileError::Task { index: 2, .. }) => {
                let m = e.to_string();
                assert!(m.contains("task 2") && m.contains(field), "{m}");
            }
            other => panic!("expected task 2 to be blamed for {field}, got {other:?}"),
        }
    }

    // An unknown key is named, in a list and in a single object.
    let mut extra = spec(p0, d, None);
    extra["speed"] = serde_json::json!(0.3);
    for text in [
        serde_json::json!([spec(p0, d, None), extra.clone()]).to_string(),
        extra.to_string(),
    ] {
        std::fs::write(&file.path, &text).unwrap();
        let m = format_error(read_tasks(&file.path, &robot));
        assert!(m.contains("speed"), "unknown key not named: {m}");
    }
    // A missing field is reported as a format error naming the field; a seed of another
    // length than the arm's joints as an error of its task naming the field and both counts.
    let mut missing = spec(p0, d, None);
    missing.as_object_mut().unwrap().remove("n");
    std::fs::write(&file.path, serde_json::json!([missing]).to_string()).unwrap();
    assert!(format_error(read_tasks(&file.path, &robot)).contains("`n`"));
    let mut short = spec(p0, d, None);
    short["q0_seed"] = serde_json::json!([0.0, 1.0]);
    std::fs::write(&file.path, serde_json::json!([short]).to_string()).unwrap();
    let message = read_tasks(&file.path, &robot).unwrap_err().to_string();
    assert!(
        message.contains("task 0")
            && message.contains("'q0_seed' has 2 values; the robot has 7 joints"),
        "{message}"
    );
    std::fs::write(&file.path, "not json").unwrap();
    format_error(read_tasks(&file.path, &robot));
}

#[test]
fn task_files_are_told_apart_by_content_not_by_name() {
    let robot = robot();
    let set = sample_set(&robot);
    // A binary set under a `.json` name.
    let binary = TempFile::new("set.json");
    write_task_set(&binary.path, &set).unwrap();
    assert_eq!(read_tasks(&binary.path, &robot).unwrap(), set);
    // A JSON list under a `.tasks` name.
    let json = TempFile::new("hand.tasks");
    let specs: Vec<emg_io::TaskSpec> = set
        .iter()
        .map(|t| emg_io::TaskSpec::of(t, &robot))
        .collect();
    std::fs::write(&json.path, serde_json::to_string(&specs).unwrap()).unwrap();
    assert_eq!(read_tasks(&json.path, &robot).unwrap().len(), set.len());
    // Neither.
    std::fs::write(&json.path, "p0,d,n\n").unwrap();
    let m = format_error(read_tasks(&json.path, &robot));
    assert!(
        m.contains("neither the EMGTASKS header") && m.contains("JSON"),
        "{m}"
    );
}
