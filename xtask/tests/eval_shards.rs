//! `cargo xtask eval --shard i/n` as a job-array element: a rerun with the same inputs skips a
//! finished shard, other inputs recompute it, a merge refuses shards of different inputs and
//! names a missing one, and the merged tables equal a single run's. (Also what builds the xtask
//! binary that `deploy/slurm/test.sh` drives.)

use std::path::Path;
use std::process::{Command, Output};

fn xtask(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(args)
        .output()
        .expect("xtask runs")
}

fn succeed(args: &[&str]) -> String {
    let output = xtask(args);
    assert!(
        output.status.success(),
        "xtask {args:?} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn fail(args: &[&str]) -> String {
    let output = xtask(args);
    assert!(!output.status.success(), "xtask {args:?} succeeded");
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn text(path: &Path) -> String {
    path.display().to_string()
}

/// `eval` without the measured seed times, the only wall-clock values it records.
fn without_seed_times(path: &Path) -> serde_json::Value {
    let mut record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("eval.json")).expect("JSON");
    for set in record["sets"].as_array_mut().expect("sets") {
        set.as_object_mut().expect("set").remove("seed_time_ms");
    }
    record
}

#[test]
fn shards_skip_when_done_recompute_on_new_inputs_and_merge_like_a_single_run() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let root = dir.path();
    let tasks = root.join("tasks");
    succeed(&[
        "make-tasks",
        "--eval-count",
        "12",
        "--train-count",
        "0",
        "--out-dir",
        &text(&tasks),
    ]);
    let labels = root.join("labels");
    succeed(&[
        "label-seeds",
        "--set",
        "eval",
        "--tasks-dir",
        &text(&tasks),
        "--out-dir",
        &text(&labels),
        "--journal-dir",
        &text(&root.join("journal")),
        "--chunk-size",
        "4",
    ]);
    let task_file = text(&tasks.join("eval-v1.tasks"));
    let label_file = text(&labels.join("eval-v1.labels"));
    let eval = |out: &Path, extra: &[&str]| -> Vec<String> {
        let mut args: Vec<String> = [
            "eval",
            "--tasks",
            &task_file,
            "--labels",
            &label_file,
            "--seen-count",
            "0",
            "--out-dir",
            &text(out),
        ]
        .map(String::from)
        .to_vec();
        args.extend(extra.iter().map(|s| s.to_string()));
        args
    };
    let run = |out: &Path, extra: &[&str]| {
        let args = eval(out, extra);
        succeed(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };

    let single = root.join("single");
    run(&single, &[]);
    let sharded = root.join("sharded");
    for i in 0..3 {
        let shard = format!("{i}/3");
        assert!(run(&sharded, &["--shard", &shard]).contains("done; wrote"));
    }
    assert!(run(&sharded, &["--shard", "1/3"]).contains("shard 1/3 is already done"));
    run(&sharded, &["--merge", "3"]);
    assert_eq!(
        without_seed_times(&single.join("eval.json")),
        without_seed_times(&sharded.join("eval.json"))
    );

    // Other inputs: the shard is computed again, and a merge refuses the mixture.
    assert!(run(&sharded, &["--shard", "2/3", "--limit", "9"]).contains("other inputs"));
    let args = eval(&sharded, &["--merge", "3"]);
    let refused = fail(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        refused.contains("eval-shard-2-of-3.json was computed from other inputs"),
        "{refused}"
    );

    let args = eval(&sharded, &["--merge", "4"]);
    let missing = fail(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        missing.contains("cargo xtask eval --shard 0/4"),
        "{missing}"
    );
}
