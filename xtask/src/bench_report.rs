//! `cargo xtask bench-report`: runs the criterion benchmarks and writes their medians to
//! `docs/results/benchmarks.md` and the README's benchmark table.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};
use serde::Deserialize;

use crate::workspace;

const README_START: &str = "<!-- benchmarks:start -->";
const README_END: &str = "<!-- benchmarks:end -->";

/// Options of `bench-report`.
#[derive(clap::Args)]
pub struct Args {
    /// Do not run `cargo bench`; report the results already under target/criterion.
    #[arg(long)]
    no_run: bool,
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

/// Runs the benchmarks (unless `--no-run`) and writes the report and the README table.
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
    }
    let mut rows = Vec::new();
    collect(&criterion_dir, &mut rows)?;
    if rows.is_empty() {
        bail!("no criterion results under {}", criterion_dir.display());
    }
    rows.sort_by(|a, b| a.name.cmp(&b.name));
    let table = table(&rows);
    let report = format!(
        "# Benchmarks\n\nWritten by `cargo xtask bench-report` (criterion medians of `cargo bench -p emg-benches`) \
         on {}. Do not edit by hand.\n\n{table}",
        workspace::machine()
    );
    let report_path = root.join("docs/results/benchmarks.md");
    emg_io::write_atomically(&report_path, report)?;
    let readme_path = root.join("README.md");
    let readme = std::fs::read_to_string(&readme_path)?;
    let (Some(start), Some(end)) = (readme.find(README_START), readme.find(README_END)) else {
        bail!("README.md lacks the {README_START} … {README_END} markers");
    };
    let updated = format!(
        "{}{README_START}\n{table}{}",
        &readme[..start],
        &readme[end..]
    );
    emg_io::write_atomically(&readme_path, updated)?;
    println!("wrote {} and the README table", report_path.display());
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

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> anyhow::Result<T> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))
}

fn table(rows: &[Row]) -> String {
    let mut table = String::from("| benchmark | median | per second (one core) |\n|---|---|---|\n");
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
