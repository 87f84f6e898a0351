//! `emg export` and `emg plan --export`, checked against readers this project did not write:
//! the MCAP file read back with the `mcap` crate's reader (its CDR message decoded here by hand,
//! independently of the encoder), every point compared with the joint trajectory and the
//! controller's quintic spline between the kept points checked against every sample; the
//! URScript programs read back by the independent reader (`emg-ur-check`), every `servoj`
//! target compared with the trajectory at its time and checked against the UR5e's limits; wrong
//! inputs refused with nothing written.

mod common;

use std::path::{Path, PathBuf};

use common::{data_dir, read_json, temp_dir, text};
use serde_json::Value;

/// Runs `emg` in `dir`; returns (exit code, stdout, stderr).
fn run(dir: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_emg"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run emg");
    (
        output.status.code(),
        text(&output.stdout),
        text(&output.stderr),
    )
}

/// A little-endian CDR reader (alignment relative to the end of the 4-byte encapsulation).
struct Cdr<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Cdr<'_> {
    fn align(&mut self, n: usize) {
        self.at += (n - self.at % n) % n;
    }
    fn take(&mut self, n: usize) -> &[u8] {
        self.align(n.min(8));
        let out = &self.bytes[self.at..self.at + n];
        self.at += n;
        out
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take(4).try_into().unwrap())
    }
    fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.take(4).try_into().unwrap())
    }
    fn f64s(&mut self) -> Vec<f64> {
        let n = self.u32() as usize;
        (0..n)
            .map(|_| f64::from_le_bytes(self.take(8).try_into().unwrap()))
            .collect()
    }
    fn string(&mut self) -> String {
        let n = self.u32() as usize;
        let raw = &self.bytes[self.at..self.at + n];
        self.at += n;
        assert_eq!(raw.last(), Some(&0), "CDR strings end in NUL");
        String::from_utf8(raw[..n - 1].to_vec()).unwrap()
    }
}

/// A decoded `trajectory_msgs/msg/JointTrajectory`: (frame_id, joint names, points as
/// (positions, velocities, accelerations, effort, nanoseconds)).
type Decoded = (String, Vec<String>, Vec<[Vec<f64>; 4]>, Vec<i64>);

fn decode(data: &[u8]) -> Decoded {
    assert_eq!(&data[..4], &[0, 1, 0, 0], "CDR little-endian encapsulation");
    let mut cdr = Cdr {
        bytes: &data[4..],
        at: 0,
    };
    let (_sec, _nanosec) = (cdr.i32(), cdr.u32());
    let frame = cdr.string();
    let names = (0..cdr.u32()).map(|_| cdr.string()).collect();
    let count = cdr.u32();
    let mut points = Vec::new();
    let mut times = Vec::new();
    for _ in 0..count {
        points.push([cdr.f64s(), cdr.f64s(), cdr.f64s(), cdr.f64s()]);
        let (sec, nanosec) = (cdr.i32(), cdr.u32());
        times.push(i64::from(sec) * 1_000_000_000 + i64::from(nanosec));
    }
    assert_eq!(cdr.at, cdr.bytes.len(), "nothing after the message");
    (frame, names, points, times)
}

fn numbers(value: &Value) -> Vec<f64> {
    value
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

fn nanoseconds(point: &Value) -> i64 {
    let t = &point["time_from_start"];
    t["sec"].as_i64().unwrap() * 1_000_000_000 + t["nanosec"].as_i64().unwrap()
}

#[test]
fn ros2_mcap_holds_every_point_and_the_spline_stays_within_tolerance() {
    let dir = temp_dir("export-mcap");
    let (code, stdout, stderr) = run(
        dir.path(),
        &[
            "plan",
            "--p0",
            "0.45,-0.2,0.25",
            "--d",
            "0,1,0",
            "--n",
            "0,0,-1",
            "--out",
            "line",
            "--export",
            "ros2-mcap",
        ],
    );
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("wrote line.mcap"), "{stdout}");
    let file = read_json(&dir.path().join("line.joint_trajectory.json"));
    let points = file["points"].as_array().unwrap();
    let bytes = std::fs::read(dir.path().join("line.mcap")).unwrap();
    let messages: Vec<_> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .collect::<Result<_, _>>()
        .unwrap();
    assert_eq!(messages.len(), 1);
    let message = &messages[0];
    let schema = message.channel.schema.as_ref().unwrap();
    assert_eq!(
        (schema.name.as_str(), schema.encoding.as_str()),
        ("trajectory_msgs/msg/JointTrajectory", "ros2msg")
    );
    assert_eq!(message.channel.message_encoding, "cdr");
    assert_eq!(
        message.channel.topic,
        "/fr3_arm_controller/joint_trajectory"
    );
    let (frame, names, kept, times) = decode(&message.data);
    assert_eq!(frame, "fr3_link0");
    let fr3: Vec<String> = (1..=7).map(|i| format!("fr3_joint{i}")).collect();
    assert_eq!(names, fr3);
    assert!(
        kept.len() > 2 && kept.len() < points.len() / 10,
        "{}",
        kept.len()
    );
    // Every kept point is a sample of the file, bit for bit, the first and the last among them.
    let by_time: std::collections::BTreeMap<i64, &Value> =
        points.iter().map(|p| (nanoseconds(p), p)).collect();
    assert_eq!(times[0], 0);
    assert_eq!(*times.last().unwrap(), nanoseconds(points.last().unwrap()));
    for (point, time) in kept.iter().zip(&times) {
        let sample = by_time[time];
        assert_eq!(point[0], numbers(&sample["positions"]));
        assert_eq!(point[1], numbers(&sample["velocities"]));
        assert_eq!(point[2], numbers(&sample["accelerations"]));
        assert!(point[3].is_empty(), "no efforts");
    }
    // The quintic between kept points stays within the stated tolerance of every sample.
    let tolerance = 1e-5;
    let mut worst = 0.0_f64;
    for window in 0..kept.len() - 1 {
        let (t0, t1) = (times[window], times[window + 1]);
        let h = (t1 - t0) as f64 * 1e-9;
        for (t, sample) in by_time.range(t0 + 1..t1) {
            let q = numbers(&sample["positions"]);
            for (j, q) in q.iter().enumerate() {
                let end = |k: usize| [kept[k][0][j], kept[k][1][j], kept[k][2][j]];
                let s =
                    emg_ur_check::quintic(end(window), end(window + 1), h, (t - t0) as f64 * 1e-9);
                worst = worst.max((s - q).abs());
            }
        }
    }
    assert!(worst <= tolerance * (1.0 + 1e-6), "worst deviation {worst}");
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let index = &summary.metadata_indexes[0];
    let notes = mcap::read::metadata(&bytes, index).unwrap();
    assert_eq!(notes.name, "emg_export");
    assert_eq!(notes.metadata["points_after"], kept.len().to_string());
}

#[test]
fn urscript_targets_are_the_trajectory_every_2_ms_within_the_ur5e_limits() {
    let dir = temp_dir("export-urscript");
    let (code, stdout, stderr) = run(
        dir.path(),
        &[
            "plan", "--robot", "ur5e", "--out", "demo", "--export", "urscript",
        ],
    );
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("wrote demo.script"), "{stdout}");
    assert_urscript_follows(
        &dir.path().join("demo.joint_trajectory.json"),
        &[dir.path().join("demo.script")],
    );
}

#[test]
fn a_job_of_several_strokes_exports_to_urscript_and_ros2() {
    let dir = temp_dir("export-job");
    let icon = Path::new(env!("CARGO_MANIFEST_DIR")).join("../io/tests/data/icons/pencil.svg");
    let icon = icon.to_str().unwrap();
    let (code, stdout, stderr) = run(
        dir.path(),
        &[
            "job",
            icon,
            "--robot",
            "ur5e",
            "--out",
            "pencil.job.json",
            "--export",
            "urscript",
        ],
    );
    assert_eq!(code, Some(0), "{stderr}");
    // The job's program as one native program beside it.
    assert!(stdout.contains("native: one program of"), "{stdout}");
    assert!(stdout.contains("wrote pencil.job.script"), "{stdout}");
    let job = read_json(&dir.path().join("pencil.job.json"));
    let strokes = job["segments"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s["kind"] == "stroke")
        .count();
    assert!(strokes >= 2, "{strokes} strokes");
    let (code, stdout, stderr) = run(
        dir.path(),
        &[
            "export",
            "pencil.job.json",
            "--format",
            "urscript",
            "--out",
            "whole.script",
            "--urscript",
            "servoj",
            "--max-servoj",
            "100000",
        ],
    );
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("wrote whole.script"), "{stdout}");
    assert_urscript_follows(
        &dir.path().join("pencil.job.json"),
        &[dir.path().join("whole.script")],
    );
    // The joint stream split where the arm rests, each part a `.script` whatever --out's
    // extension; an --out replacing the program refused, nothing written. The limit lies
    // between the program's longest run without rest (5.5 s, 2,730 targets) and the whole
    // program (6.8 s).
    let (code, stdout, stderr) = run(
        dir.path(),
        &[
            "export",
            "pencil.job.json",
            "--format",
            "urscript",
            "--urscript",
            "servoj",
            "--max-servoj",
            "3000",
            "--out",
            "split.json",
        ],
    );
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("split where the arm rests"), "{stdout}");
    assert!(dir.path().join("split-part1.script").is_file(), "{stdout}");
    let parts: Vec<PathBuf> = (1..)
        .map(|n| dir.path().join(format!("split-part{n}.script")))
        .take_while(|part| part.is_file())
        .collect();
    let split = assert_urscript_follows(&dir.path().join("pencil.job.json"), &parts);
    assert!(split.programs >= 2 && split.home_checked, "{split:?}");
    assert!(!dir.path().join("split.json").exists());
    let before = std::fs::read(dir.path().join("pencil.job.json")).unwrap();
    for form in ["native", "servoj"] {
        let (code, _, stderr) = run(
            dir.path(),
            &[
                "export",
                "pencil.job.json",
                "--format",
                "urscript",
                "--urscript",
                form,
                "--max-servoj",
                "100000",
                "--out",
                "pencil.job.json",
            ],
        );
        assert_eq!(code, Some(1), "{form}: {stderr}");
        assert!(
            stderr.contains("which is the job program"),
            "{form}: {stderr}"
        );
    }
    assert_eq!(
        std::fs::read(dir.path().join("pencil.job.json")).unwrap(),
        before
    );
    let (code, stdout, stderr) = run(
        dir.path(),
        &[
            "export",
            "pencil.job.json",
            "--format",
            "ros2-mcap",
            "--out",
            "pencil.mcap",
        ],
    );
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("wrote pencil.mcap"), "{stdout}");
    // The FR3 has no URScript: refused before anything is planned.
    let (code, _, stderr) = run(
        dir.path(),
        &["job", icon, "--out", "fr3.job.json", "--export", "urscript"],
    );
    assert_eq!(code, Some(1));
    assert!(
        stderr.contains("nothing was planned or written"),
        "{stderr}"
    );
    assert!(!dir.path().join("fr3.job.json").exists());
}

/// The URScript programs `scripts` (in order) exported from the timed motion in `motion` (a
/// joint trajectory or a job's program), read back by the independent reader
/// (`emg_ur_check::read_servoj_motion`): a `movej` to its first point (a job's program, which
/// starts at its home, checks that the arm stands there instead and halts where it does not),
/// then one `servoj` target every 2 ms, each the motion's sample at that time, within the UR5e's
/// joint limits and the motion's velocity and acceleration limits, then a hold where the arm
/// rests and `stopj`; each later program from where the one before it stopped.
fn assert_urscript_follows(motion: &Path, scripts: &[PathBuf]) -> emg_ur_check::ServojReport {
    let text = std::fs::read_to_string(motion).unwrap();
    let programs: Vec<String> = scripts
        .iter()
        .map(|path| std::fs::read_to_string(path).unwrap())
        .collect();
    let programs: Vec<&str> = programs.iter().map(String::as_str).collect();
    let checker = emg_verify::ReferenceModel::from_urdf_file(
        &data_dir().join("robots/ur5e_pen.urdf"),
        "base_link",
        "pen_tip",
    )
    .unwrap();
    let report = if emg_job::JobFile::is_job(&text) {
        let plan = emg_job::JobFile::parse(&text).expect("a job's program");
        emg_ur_check::read_servoj(&programs, &plan, &checker)
    } else {
        let trajectory = emg_io::JointTrajectory::from_json(&text).expect("a joint trajectory");
        let motion = emg_ur_check::TimedMotion {
            points: &trajectory.points,
            limits: &trajectory.limits,
            home: None,
        };
        emg_ur_check::read_servoj_motion(&programs, &motion, &checker)
    };
    let report = report.unwrap_or_else(|e| panic!("{}: {e}", motion.display()));
    assert_eq!(report.programs, scripts.len());
    report
}

#[test]
fn wrong_inputs_are_refused_and_nothing_is_written() {
    let dir = temp_dir("export-wrong");
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let bad = examples.join("bad.joint_trajectory.json");
    let bad = bad.to_str().unwrap();
    let out = |name: &str| dir.path().join(name);
    let cases: [(Vec<&str>, &str, i32); 6] = [
        (
            vec![
                "--format",
                "urscript",
                "--urscript",
                "native",
                "--out",
                "n.script",
                "--robot",
                "ur5e",
            ],
            "--urscript native writes a job's program",
            1,
        ),
        (
            vec![
                "--format", "urscript", "--out", "a.script", "--robot", "fr3",
            ],
            "urscript runs on Universal Robots controllers only: robot",
            1,
        ),
        (
            vec![
                "--format",
                "ros2-mcap",
                "--out",
                "b.mcap",
                "--robot",
                "ur5e",
            ],
            "field 'joint_names' is",
            1,
        ),
        (
            vec!["--format", "ros3", "--out", "c.mcap"],
            "unknown export format 'ros3': give ros2-mcap, urscript or rapid",
            2,
        ),
        (
            vec!["--format", "rapid", "--out", "c.mod", "--robot", "fr3"],
            "rapid is written from a job's program",
            1,
        ),
        (
            vec!["--format", "ros2-mcap", "--out", bad, "--robot", "fr3"],
            "which is the joint trajectory file",
            1,
        ),
    ];
    for (args, message, status) in cases {
        let mut all = vec!["export", bad];
        all.extend(&args);
        let (code, _, stderr) = run(dir.path(), &all);
        assert_eq!(code, Some(status), "{all:?}: {stderr}");
        assert!(stderr.contains(message), "{all:?}: {stderr}");
    }
    let json = examples.join("plan.json");
    let (code, _, stderr) = run(
        dir.path(),
        &[
            "export",
            json.to_str().unwrap(),
            "--format",
            "ros2-mcap",
            "--out",
            "d.mcap",
        ],
    );
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("is not a joint trajectory (emg-joint-trajectory/2"),
        "{stderr}"
    );
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(names.is_empty(), "{names:?}");
    assert!(!out("a.script").exists());
    // Planning with --export urscript on a seven-joint arm is refused before anything is planned.
    let (code, _, stderr) = run(dir.path(), &["plan", "--out", "e", "--export", "urscript"]);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("nothing was planned or written"),
        "{stderr}"
    );
    assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
}
