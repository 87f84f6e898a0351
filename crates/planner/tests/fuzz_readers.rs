//! Property tests of every reader of a user's file or option: task sets (binary and JSON), label
//! files, both weights formats, the three trajectory layouts, robot files (the planner's model
//! and the checker's) and planner configurations, plus the values of command-line options.
//!
//! Inputs are random bytes and valid files mutated byte by byte (bit flips, extreme integers
//! written over header fields, cuts, insertions) or token by token (a number or word replaced by
//! `NaN`, `1e999`, `-1`, `null`, markup, …). A reader must return a value or an error: a panic
//! fails the property, an abort or a hang fails the test binary. What a reader accepts is then
//! used the way `emg plan` and `emg check` use it (planned, verified), which must not panic
//! either.
//!
//! The generator's seed is fixed, so a run is reproducible. Each property runs [`CASES`] cases;
//! `PROPTEST_CASES=<n>` runs more for a longer search.

use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::sync::LazyLock;
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::Duration;

use emg_control::{ConstraintConfig, Task};
use emg_io::{
    JointTrajectory, TaskSpec, TrajectoryContents, TrajectoryFile, parse_tasks, trajectory_csv,
    write_task_set,
};
use emg_kinematics::{JointVector, Robot};
use emg_planner::{
    ControllerKind, DataDir, Models, MotionTiming, PlanRequest, Planner, PlannerConfig,
    PlannerKind, SeedSource, ShippedRobot, demo_task, limits_file_beside, robot_stamp,
};
use emg_seeding::{Label, LabelSet, Shard, TaskLabels};
use emg_timing::Scaling;
use emg_verify::{Recording, ReferenceModel, check_joint_names, check_replay};
use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestError, TestRunner};

/// Cases per property in CI (each case parses one input and uses what parses).
const CASES: u32 = 48;

/// Steps a rollout may take when an accepted input is planned (keeps each case short).
const PLAN_STEPS: usize = 30;

fn config() -> Config {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(CASES);
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x454d_4746_555a_5a31),
        failure_persistence: None,
        max_shrink_time: 120_000,
        ..Config::default()
    }
}

fn data() -> DataDir {
    DataDir::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data"))
}

fn shipped(name: &str) -> ShippedRobot {
    ShippedRobot::by_name(name).expect("shipped robot")
}

fn robot_file(name: &str) -> PathBuf {
    shipped(name).path(&data())
}

fn fr3() -> &'static Robot {
    static FR3: LazyLock<Robot> =
        LazyLock::new(|| Robot::from_chain_file(robot_file("fr3")).expect("the FR3 loads"));
    &FR3
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

// ---------------------------------------------------------------------------------------------
// Mutations

/// A position in the input: anywhere, or within its first bytes (where headers live).
#[derive(Clone, Debug)]
struct At {
    in_head: bool,
    index: Index,
}

impl At {
    fn of(&self, len: usize) -> usize {
        let span = if self.in_head { len.min(512) } else { len };
        if span == 0 { 0 } else { self.index.index(span) }
    }
}

/// Integers a corrupted header field commonly holds.
const EXTREME_WORDS: [u64; 10] = [
    0,
    1,
    0xff,
    u32::MAX as u64,
    1 << 31,
    1 << 32,
    1 << 62,
    u64::MAX,
    0x7ff8_0000_0000_0000, // f64 NaN
    0x7ff0_0000_0000_0000, // f64 infinity
];

/// What a number or word of a text file may be replaced by: extreme and malformed values, and
/// plain ones (which keep more inputs valid, so that their use is exercised too).
const TOKENS: [&str; 33] = [
    "0.5",
    "2",
    "100",
    "0.001",
    "7",
    "1",
    "30",
    "0.05",
    "500",
    "NaN",
    "inf",
    "-inf",
    "1e999",
    "-1e999",
    "1e308",
    "-1",
    "0",
    "-0",
    "1e-320",
    "18446744073709551616",
    "4294967295",
    "null",
    "true",
    "\"\"",
    "[]",
    "{}",
    "",
    ",",
    "]}",
    "<a>",
    "\"",
    "&#0;",
    "é\u{0}",
];

#[derive(Clone, Debug)]
enum Mutation {
    FlipBit {
        at: At,
        bit: u8,
    },
    Word {
        at: At,
        word: usize,
        wide: bool,
    },
    Truncate {
        at: At,
    },
    Remove {
        at: At,
        len: u8,
    },
    Insert {
        at: At,
        bytes: Vec<u8>,
    },
    Token {
        in_head: bool,
        numbers_only: bool,
        nth: Index,
        token: usize,
    },
}

fn at() -> impl Strategy<Value = At> {
    (any::<bool>(), any::<Index>()).prop_map(|(in_head, index)| At { in_head, index })
}

fn token_mutation() -> impl Strategy<Value = Mutation> {
    (any::<[bool; 2]>(), any::<Index>(), 0..TOKENS.len()).prop_map(
        |([in_head, numbers_only], nth, token)| Mutation::Token {
            in_head,
            numbers_only,
            nth,
            token,
        },
    )
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (at(), 0..8u8).prop_map(|(at, bit)| Mutation::FlipBit { at, bit }),
        (at(), 0..EXTREME_WORDS.len(), any::<bool>()).prop_map(|(at, word, wide)| Mutation::Word {
            at,
            word,
            wide
        }),
        at().prop_map(|at| Mutation::Truncate { at }),
        (at(), any::<u8>()).prop_map(|(at, len)| Mutation::Remove { at, len }),
        (at(), proptest::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(at, bytes)| Mutation::Insert { at, bytes }),
        token_mutation(),
    ]
}

fn is_token_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b"._+-".contains(&b)
}

impl Mutation {
    fn apply(&self, bytes: &mut Vec<u8>) {
        let len = bytes.len();
        match self {
            Self::FlipBit { at, bit } => {
                if len > 0 {
                    bytes[at.of(len)] ^= 1 << bit;
                }
            }
            Self::Word { at, word, wide } => {
                let value = EXTREME_WORDS[*word].to_le_bytes();
                let start = at.of(len);
                let width = if *wide { 8 } else { 4 };
                let end = (start + width).min(len);
                bytes[start..end].copy_from_slice(&value[..end - start]);
            }
            Self::Truncate { at } => bytes.truncate(at.of(len)),
            Self::Remove { at, len: n } => {
                let start = at.of(len);
                bytes.drain(start..(start + usize::from(*n)).min(len));
            }
            Self::Insert { at, bytes: new } => {
                let start = at.of(len);
                bytes.splice(start..start, new.iter().copied());
            }
            Self::Token {
                in_head,
                numbers_only,
                nth,
                token,
            } => {
                let span = if *in_head { len.min(1024) } else { len };
                let mut tokens = token_spans(&bytes[..span]);
                if *numbers_only {
                    tokens.retain(|&(start, _)| matches!(bytes[start], b'0'..=b'9' | b'-'));
                }
                if !tokens.is_empty() {
                    let (start, end) = tokens[nth.index(tokens.len())];
                    bytes.splice(start..end, TOKENS[*token].bytes());
                }
            }
        }
    }
}

/// The byte ranges of the numbers and words of `bytes` (maximal runs of token bytes).
fn token_spans(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = None;
    for (i, &b) in bytes.iter().chain(b" ").enumerate() {
        match (start, is_token_byte(b)) {
            (None, true) => start = Some(i),
            (Some(s), false) => {
                spans.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    spans
}

/// Random bytes, or one of the valid `files` with one token replaced (which often keeps it
/// valid) or with a few mutations of any kind.
fn inputs(files: Vec<Vec<u8>>) -> impl Strategy<Value = Vec<u8>> {
    let mutated = |mutations| {
        (0..files.len(), mutations).prop_map({
            let files = files.clone();
            move |(file, mutations): (usize, Vec<Mutation>)| {
                let mut bytes = files[file].clone();
                for mutation in &mutations {
                    mutation.apply(&mut bytes);
                }
                bytes
            }
        })
    };
    let one_token = token_mutation().prop_map(|mutation| vec![mutation]);
    prop_oneof![
        1 => proptest::collection::vec(any::<u8>(), 0..256),
        2 => mutated(one_token.boxed()),
        3 => mutated(proptest::collection::vec(mutation(), 1..4).boxed()),
    ]
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

// ---------------------------------------------------------------------------------------------
// Using what a reader accepts

/// Plans `task` on `robot` as `emg plan` does with no models (the classical controller from
/// the task's generating configuration, else the mid-range one), in a few steps.
fn plan_briefly(robot: &Robot, mut config: PlannerConfig, task: &Task) {
    config.rollout.max_steps = config.rollout.max_steps.min(PLAN_STEPS);
    let models = Models::load(robot, None, None).expect("no model files to read");
    let Ok(planner) = Planner::new(robot.clone(), models, config) else {
        return;
    };
    let request = PlanRequest {
        seed: None,
        controller: ControllerKind::Classical,
        ..PlanRequest::pipeline()
    };
    let _ = planner.plan(task, &request);
}

/// Verifies a trajectory file's contents as `emg check` does, on the FR3.
fn check_contents(robot: &Robot, model: &ReferenceModel, contents: &TrajectoryContents) {
    let (task, constraints) = match contents.carried() {
        Some(carried) => {
            let Ok(task) = Task::new(
                robot,
                carried.task.p0,
                carried.task.d,
                carried.task.n,
                carried.task.q0_seed,
            ) else {
                return;
            };
            (task, carried.constraints)
        }
        None => (
            demo_task(robot).expect("the FR3 has a demo task"),
            ConstraintConfig::default(),
        ),
    };
    if let Some(names) = contents.joint_names()
        && check_joint_names(names, robot.joint_names()).is_err()
    {
        return;
    }
    let recording = match contents {
        TrajectoryContents::Rollout(rollout) => Some(Recording::from(&rollout.trajectory)),
        _ => None,
    };
    let limits = match contents {
        TrajectoryContents::Joint(file) => Some(file.limits.dynamics()),
        _ => None,
    };
    let _ = check_replay(
        model,
        &(&task).into(),
        &(&constraints).into(),
        &contents.samples(),
        recording.as_ref(),
        limits.as_ref(),
    );
}

// ---------------------------------------------------------------------------------------------
// Valid files to start from

fn task_files(robot: &Robot) -> Vec<Vec<u8>> {
    let tasks = emg_io::read_tasks(
        &shipped("fr3").data_dir(&data()).join("tasks/eval-v1.tasks"),
        robot,
    )
    .expect("shipped tasks load");
    let tasks = &tasks[..3];
    let dir = tempfile::tempdir().expect("temporary directory");
    let binary = dir.path().join("set.tasks");
    write_task_set(&binary, tasks).expect("task set written");
    let specs: Vec<TaskSpec> = tasks.iter().map(|t| TaskSpec::of(t, robot)).collect();
    vec![
        read(&binary),
        serde_json::to_vec_pretty(&specs).expect("JSON"),
        serde_json::to_vec(&specs[0]).expect("JSON"),
    ]
}

fn label_file() -> Vec<u8> {
    let label = |k: f64, length_m| {
        Label::stored(
            JointVector::from_fn(|i, _| 0.1 * (i as f64) - k),
            length_m,
            k as u32,
            0.01,
        )
    };
    let tasks = vec![
        TaskLabels {
            task_index: 0,
            labels: vec![label(0.0, 0.6), label(1.0, 0.4)],
        },
        TaskLabels {
            task_index: 2,
            labels: vec![],
        },
        TaskLabels {
            task_index: 3,
            labels: vec![label(2.0, 0.3)],
        },
    ];
    LabelSet::new([7; 32], 5, 4, tasks)
        .expect("valid label set")
        .to_bytes()
}

/// The three files `emg plan` writes for the FR3's demo task.
fn trajectory_files(robot: &Robot) -> Vec<Vec<u8>> {
    let config = PlannerConfig::default();
    let task = demo_task(robot).expect("demo task");
    let planner = Planner::new(
        robot.clone(),
        Models::load(robot, None, None).expect("no models"),
        config.clone(),
    )
    .expect("default config");
    let request = PlanRequest {
        seed: Some(SeedSource::Home),
        controller: ControllerKind::Classical,
        ..PlanRequest::pipeline()
    };
    let plan = planner.plan(&task, &request).expect("the demo task plans");
    let trajectory = &plan.trajectory;
    let file = TrajectoryFile {
        format: emg_io::TRAJECTORY_FORMAT,
        robot: "fr3".into(),
        joint_names: robot.joint_names(),
        task: &task,
        seed_source: plan.seed.source,
        planner: "controller",
        controller: ControllerKind::Classical.name(),
        config: &config.rollout,
        gains: &config.gains,
        steps: &trajectory.steps,
        termination: &trajectory.termination,
        path_length_m: trajectory.path_length_m,
        reachable_m: Some(0.5),
        below_bound: None,
    };
    // A low rate keeps the timed file small enough to mutate many times.
    let timing = MotionTiming::new(
        robot,
        &limits_file_beside(&robot_file("fr3")),
        Scaling::default(),
        0.2,
        20.0,
        &config.rollout.constraints,
    )
    .expect("the shipped limits");
    let motion = timing
        .time(robot, &task, &config.rollout.constraints, trajectory)
        .expect("the plan times");
    let joint = JointTrajectory::new(
        "fr3",
        robot.joint_names(),
        &task,
        &config.rollout.constraints,
        timing.record(),
        &motion,
        20.0,
    )
    .expect("joint trajectory");
    vec![
        file.to_json().into_bytes(),
        joint.to_json().into_bytes(),
        trajectory_csv(&trajectory.steps, 7).into_bytes(),
    ]
}

// ---------------------------------------------------------------------------------------------
// The properties

/// Longer than any reader or brief plan takes by orders of magnitude: a case still running
/// after it is a hang.
const HANG: Duration = Duration::from_secs(20);

/// Runs `read` (which says whether it accepted its input) on inputs generated from the valid
/// `files` (each of which it must accept): each case on its own thread, so that a panic or a
/// hang fails the property with the input shrunk. The generator must have produced inputs the
/// reader accepts as well as inputs it refuses, so that the use of accepted inputs is
/// exercised.
fn read_or_refuse(what: &str, files: Vec<Vec<u8>>, read: fn(&[u8]) -> bool) {
    for (index, file) in files.iter().enumerate() {
        assert!(read(file), "{what}: valid file {index} is refused");
    }
    let (accepted, refused) = (Cell::new(0u32), Cell::new(0u32));
    let result = TestRunner::new(config()).run(&inputs(files), |bytes| {
        let (sender, receiver) = channel();
        std::thread::spawn(move || sender.send(read(&bytes)));
        match receiver.recv_timeout(HANG) {
            Ok(true) => accepted.set(accepted.get() + 1),
            Ok(false) => refused.set(refused.get() + 1),
            Err(RecvTimeoutError::Timeout) => {
                return Err(TestCaseError::fail(format!("no answer within {HANG:?}")));
            }
            Err(RecvTimeoutError::Disconnected) => {
                return Err(TestCaseError::fail("the reader panicked"));
            }
        }
        Ok(())
    });
    if let Err(error) = result {
        let name = format!("fuzz-{}.input", what.replace(' ', "-"));
        let saved = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
        let note = match &error {
            TestError::Fail(_, input) => match std::fs::write(&saved, input) {
                Ok(()) => format!("the input is saved to {}", saved.display()),
                Err(e) => format!("the input could not be saved to {}: {e}", saved.display()),
            },
            TestError::Abort(_) => String::new(),
        };
        panic!("{what}: {error}; {note}");
    }
    assert!(
        accepted.get() > 0 && refused.get() > 0,
        "{what}: {} inputs accepted and {} refused; the generator must produce both",
        accepted.get(),
        refused.get()
    );
}

#[test]
fn task_sets_are_read_or_refused() {
    read_or_refuse("task sets", task_files(fr3()), |bytes| {
        let Ok(tasks) = parse_tasks("fuzzed", bytes, fr3()) else {
            return false;
        };
        for task in tasks.iter().take(2) {
            plan_briefly(fr3(), PlannerConfig::default(), task);
        }
        true
    });
}

#[test]
fn label_files_are_read_or_refused() {
    read_or_refuse("label files", vec![label_file()], |bytes| {
        LabelSet::from_bytes("fuzzed", bytes).is_ok()
    });
}

fn shipped_model(file: &str) -> Vec<u8> {
    read(&shipped("fr3").data_dir(&data()).join("models").join(file))
}

#[test]
fn policy_weights_are_read_or_refused() {
    read_or_refuse(
        "policy weights",
        vec![shipped_model("ppo-v1.weights")],
        |bytes| {
            let Ok(weights) = emg_policy::PolicyWeights::from_bytes(bytes) else {
                return false;
            };
            let stamp = weights.header().robot.as_ref();
            let _ = emg_learning::check_stamp(stamp, &robot_stamp(fr3()), "fuzzed");
            let _ = emg_policy::RlController::new(&weights);
            true
        },
    );
}

#[test]
fn diffusion_weights_are_read_or_refused() {
    read_or_refuse(
        "diffusion weights",
        vec![shipped_model("diffusion-v1.weights")],
        |bytes| {
            let Ok(weights) = emg_diffusion::DenoiserWeights::from_bytes(bytes) else {
                return false;
            };
            let stamp = weights.header().robot.as_ref();
            let _ = emg_learning::check_stamp(stamp, &robot_stamp(fr3()), "fuzzed");
            let _ = emg_diffusion::DpSeeder::new(
                fr3(),
                &weights,
                emg_diffusion::DpSeedConfig::default(),
            );
            true
        },
    );
}

#[test]
fn trajectory_files_are_read_or_refused() {
    static CHECKER: LazyLock<ReferenceModel> = LazyLock::new(|| {
        ReferenceModel::from_urdf_file(&robot_file("fr3"), fr3().base_link(), fr3().tip_link())
            .expect("checker model")
    });
    read_or_refuse("trajectory files", trajectory_files(fr3()), |bytes| {
        match TrajectoryContents::parse(&text(bytes)) {
            Ok(contents) => {
                check_contents(fr3(), &CHECKER, &contents);
                true
            }
            Err(_) => false,
        }
    });
}

#[test]
fn robot_files_are_read_or_refused() {
    let files = vec![read(&robot_file("fr3")), read(&robot_file("iiwa14"))];
    read_or_refuse("robot files", files, |bytes| {
        let text = text(bytes);
        match Robot::from_chain_str(&text) {
            Ok(robot) => {
                let _ = ReferenceModel::from_urdf_str(&text, robot.base_link(), robot.tip_link());
                let _ = robot_stamp(&robot);
                if let Ok(task) = demo_task(&robot) {
                    plan_briefly(&robot, PlannerConfig::default(), &task);
                }
                true
            }
            Err(_) => {
                let _ = ReferenceModel::from_urdf_str(&text, "fr3_link0", "pen_tip");
                false
            }
        }
    });
}

#[test]
fn configs_are_read_or_refused() {
    let files = vec![
        serde_json::to_vec_pretty(&PlannerConfig::default()).expect("JSON"),
        br#"{"rollout": {"max_steps": 300, "constraints": {"theta_max_deg": 30}}}"#.to_vec(),
    ];
    read_or_refuse("configs", files, |bytes| {
        let Ok(config) = PlannerConfig::from_json("fuzzed", &text(bytes)) else {
            return false;
        };
        plan_briefly(fr3(), config, &demo_task(fr3()).expect("demo task"));
        true
    });
}

#[test]
fn option_values_are_read_or_refused() {
    let values = vec![
        b"q=0.1,-0.2,0.3,-2.0,0.0,1.9,0.7".to_vec(),
        b"dp".to_vec(),
        b"hybrid".to_vec(),
        b"search".to_vec(),
        b"2/4".to_vec(),
    ];
    read_or_refuse("option values", values, |bytes| {
        let value = text(bytes);
        let controller = value.parse::<ControllerKind>().is_ok();
        let planner = value.parse::<PlannerKind>().is_ok();
        let shard = value.parse::<Shard>().is_ok();
        let Ok(seed) = value.parse::<SeedSource>() else {
            return controller || planner || shard;
        };
        let models = Models::load(fr3(), None, None).expect("no model files to read");
        let planner =
            Planner::new(fr3().clone(), models, PlannerConfig::default()).expect("default config");
        let request = PlanRequest {
            seed: Some(seed),
            controller: ControllerKind::Classical,
            ..PlanRequest::pipeline()
        };
        let _ = planner.plan(&demo_task(fr3()).expect("demo task"), &request);
        true
    });
}
