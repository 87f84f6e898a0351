//! `cargo xtask bench-report`: runs the criterion benchmarks and writes their medians to
//! `docs/results/benchmarks.md`, with the instructions one
//! `full_step` step executes, counted by valgrind (a figure that, unlike a time, does not move
//! with the machine's load).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};
use serde::{Deserialize, Serialize};

use crate::workspace;

/// Repetitions of the `full_step` rollout in the two counted runs: the difference of their
/// instruction counts is the rollouts' alone, without the loading both runs share.
const COUNTED_REPETITIONS: [usize; 2] = [20, 200];

/// Where the instruction count is kept beside the criterion results (for `--no-run`).
const INSTRUCTIONS_FILE: &str = "full_step_instructions.json";

/// Options of `bench-report`.
#[derive(clap::Args)]
pub struct Args {
    /// Do not run `cargo bench` or valgrind; report the results already under target/criterion.
    #[arg(long)]
    no_run: bool,
}

/// The instructions of one `full_step` step, as counted.
#[derive(Serialize, Deserialize)]
struct StepInstructions {
    /// Instructions per accepted step.
    per_step: f64,
    /// Accepted steps between the two counted runs.
    steps: u64,
}

#[derive(Deserialize)]
struct Estimates {
    median: Estimate,
}

#[derive(Deserialize)]
struct Estimate {
    point_estimate: f64,
}

#[derive(Deserialize)]
struct BenchmarkId {
    full_id: String,
}

/// One benchmark's median.
struct Row {
    name: String,
    median_ns: f64,
}

/// Runs the benchmarks (unless `--no-run`) and writes the report.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let root = workspace::root();
    let criterion_dir = root.join("target/criterion");
    if !args.no_run {
        if criterion_dir.exists() {
            std::fs::remove_dir_all(&criterion_dir)?;
        }
        let status = Command::new(env!("CARGO"))
            .args(["bench", "-p", "emg-benches"])
            .current_dir(&root)
            .status()
            .context("running cargo bench")?;
        if !status.success() {
            bail!("cargo bench failed");
        }
        if let Some(count) = count_step_instructions(&root)? {
            let text = serde_json::to_string_pretty(&count)?;
            emg_io::write_atomically(criterion_dir.join(INSTRUCTIONS_FILE), text)?;
        }
    }
    let instructions: Option<StepInstructions> = match criterion_dir.join(INSTRUCTIONS_FILE) {
        path if path.exists() => Some(read_json(&path)?),
        _ => None,
    };
    let mut rows = Vec::new();
    collect(&criterion_dir, &mut rows)?;
    if rows.is_empty() {
        bail!("no criterion results under {}", criterion_dir.display());
    }
    rows.sort_by(|a, b| a.name.cmp(&b.name));
    let table = table(&rows) + &instructions_line(instructions.as_ref());
    let report = format!(
        "# Benchmarks\n\nWritten by `cargo xtask bench-report` (criterion medians of `cargo bench -p emg-benches`) \
         on {}. Do not edit by hand.\n\n{table}",
        workspace::machine()
    );
    let report_path = root.join("docs/results/benchmarks.md");
    emg_io::write_atomically(&report_path, report)?;
    println!("wrote {}", report_path.display());
    Ok(())
}

/// Every `new/estimates.json` below `dir`, named by its `new/benchmark.json`.
fn collect(dir: &Path, rows: &mut Vec<Row>) -> anyhow::Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for entry in entries {
        let path: PathBuf = entry?.path();
        if !path.is_dir() {
            continue;
        }
        let estimates = path.join("new/estimates.json");
        if estimates.exists() {
            let id: BenchmarkId = read_json(&path.join("new/benchmark.json"))?;
            let estimates: Estimates = read_json(&estimates)?;
            rows.push(Row {
                name: id.full_id,
                median_ns: estimates.median.point_estimate,
            });
        } else {
            collect(&path, rows)?;
        }
    }
    Ok(())
}

/// Counts the instructions of one `full_step` step: the `full_step_workload` example run under
/// valgrind (cachegrind, no cache simulation) at both [`COUNTED_REPETITIONS`]. `None`, with a
/// warning, where valgrind is not installed.
fn count_step_instructions(root: &Path) -> anyhow::Result<Option<StepInstructions>> {
    if Command::new("valgrind").arg("--version").output().is_err() {
        eprintln!("valgrind not found: the instruction count of a step is left out of the report");
        return Ok(None);
    }
    let status = Command::new(env!("CARGO"))
        .args(["build", "--release", "-p", "emg-benches"])
        .args(["--example", "full_step_workload"])
        .current_dir(root)
        .status()
        .context("building the full_step_workload example")?;
    if !status.success() {
        bail!("building the full_step_workload example failed");
    }
    let binary = root.join("target/release/examples/full_step_workload");
    let [fewer, more] = COUNTED_REPETITIONS;
    let (fewer_instructions, fewer_steps) = counted_run(&binary, fewer)?;
    let (more_instructions, more_steps) = counted_run(&binary, more)?;
    let steps = more_steps - fewer_steps;
    Ok(Some(StepInstructions {
        per_step: (more_instructions - fewer_instructions) as f64 / steps as f64,
        steps,
    }))
}

/// The instructions valgrind counted in `binary REPETITIONS`, and the steps it printed.
fn counted_run(binary: &Path, repetitions: usize) -> anyhow::Result<(u64, u64)> {
    println!("counting the instructions of {repetitions} full_step rollouts under valgrind");
    let output = Command::new("valgrind")
        .args([
            "--tool=cachegrind",
            "--cache-sim=no",
            "--cachegrind-out-file=/dev/null",
        ])
        .arg(binary)
        .arg(repetitions.to_string())
        .output()
        .context("running valgrind")?;
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success() {
        bail!("valgrind {} failed:\n{stderr}", binary.display());
    }
    let instructions = instruction_count(&stderr)
        .context("valgrind printed no instruction count (an `I refs:` line)")?;
    let steps = String::from_utf8_lossy(&output.stdout)
        .trim()
        .parse()
        .context("the step count full_step_workload printed")?;
    Ok((instructions, steps))
}

/// The count of valgrind's `I refs:` line (`==123== I   refs:      90,507,058`).
fn instruction_count(valgrind_stderr: &str) -> Option<u64> {
    valgrind_stderr.lines().find_map(|line| {
        let (_, count) = line.split_once("I")?.1.split_once("refs:")?;
        count.trim().replace(',', "").parse().ok()
    })
}

/// The sentence under the table that gives the instruction count (or says it is missing).
fn instructions_line(instructions: Option<&StepInstructions>) -> String {
    match instructions {
        Some(count) => format!(
            "\nOne `full_step` step executes **{:.0} instructions** (valgrind's count over {} steps of \
             the same rollout: {} minus {} repetitions of `benches/examples/full_step_workload.rs`); \
             unlike the times, the count does not move with the machine's load.\n",
            count.per_step, count.steps, COUNTED_REPETITIONS[1], COUNTED_REPETITIONS[0]
        ),
        None => {
            "\nThe instructions of a `full_step` step were not counted (valgrind was not found).\n"
                .to_string()
        }
    }
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> anyhow::Result<T> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))
}

/// The table of medians; every benchmark runs on one core except those named `…_all_cores`.
fn table(rows: &[Row]) -> String {
    let mut table = String::from(
        "| benchmark | median | per second (one core, or all for `…_all_cores`) |\n|---|---|---|\n",
    );
    for row in rows {
        table += &format!(
            "| {} | {} | {:.3e} |\n",
            row.name,
            human_time(row.median_ns),
            1e9 / row.median_ns
        );
    }
    table
}

fn human_time(ns: f64) -> String {
    if ns < 1e3 {
        format!("{ns:.0} ns")
    } else if ns < 1e6 {
        format!("{:.2} µs", ns / 1e3)
    } else {
        format!("{:.2} ms", ns / 1e6)
    }
}

#[cfg(test)]
mod tests {
    use super::instruction_count;

    #[test]
    fn reads_the_instruction_count_of_valgrind_output() {
        let stderr = "==29566== Cachegrind, a cache and branch-prediction profiler\n\
                      --29566-- warning: simulated LL cache: line_size 64  assoc 1\n\
                      ==29566== \n\
                      ==29566== I   refs:      90,507,058\n";
        assert_eq!(instruction_count(stderr), Some(90_507_058));
        assert_eq!(instruction_count("==1== I refs: 12\n"), Some(12));
        assert_eq!(instruction_count("==1== no count here\n"), None);
    }
}
