//! `cargo xtask regenerate`: every shipped data file and every result, in dependency order.
//!
//! A change that moves any bit of the control step (its arithmetic, the kinematics, a
//! constant) changes the task sets, which the sampler draws by rolling the classical controller
//! out, and so the labels, both models of both arms and every result after them. This runs
//! each pipeline that produces them, in order, each as its own `xtask` process with the
//! arguments that produced the shipped files. Finished stages are journaled in
//! `target/regenerate/`, so an interrupted run goes on from the stage it stopped in (the
//! labelling, the trainings and the limit search resume their own work there); `--from STAGE`
//! runs again from a stage on. The benchmarks (`cargo xtask bench-report`) and the backend
//! speed measurements (`--measure-backends`) are not part of it: they measure this machine, not
//! the code's results.

use std::process::Command;

use anyhow::{Context, bail};

use crate::workspace;

/// Options of `regenerate`.
#[derive(clap::Args)]
pub struct Args {
    /// Print the stages, their arguments and the files each writes, and stop.
    #[arg(long)]
    list: bool,
    /// Run again from this stage on (the stages before it are taken as done).
    #[arg(long, value_name = "STAGE")]
    from: Option<String>,
}

/// One pipeline run.
struct Stage {
    /// The stage's name (the journal's and `--from`'s).
    name: &'static str,
    /// The `cargo xtask` arguments.
    args: &'static [&'static str],
    /// The files it writes, relative to the workspace root.
    writes: &'static [&'static str],
}

/// Every stage, each after the ones whose files it reads.
const STAGES: &[Stage] = &[
    Stage {
        name: "tasks",
        args: &["make-tasks"],
        writes: &[
            "data/tasks/eval-v1.tasks",
            "data/tasks/train-v1.tasks",
            "data/tasks/tasks-v1.manifest.json",
        ],
    },
    Stage {
        name: "tasks-iiwa14",
        args: &["make-tasks", "--robot", "iiwa14", "--train-count", "20000"],
        writes: &[
            "data/iiwa14/tasks/eval-v1.tasks",
            "data/iiwa14/tasks/train-v1.tasks",
            "data/iiwa14/tasks/tasks-v1.manifest.json",
        ],
    },
    Stage {
        name: "tasks-ur5e",
        args: &["make-tasks", "--robot", "ur5e", "--train-count", "20000"],
        writes: &[
            "data/ur5e/tasks/eval-v1.tasks",
            "data/ur5e/tasks/train-v1.tasks",
            "data/ur5e/tasks/tasks-v1.manifest.json",
        ],
    },
    Stage {
        name: "labels",
        args: &["label-seeds"],
        writes: &[
            "data/labels/eval-v1.labels",
            "data/labels/eval-v1.manifest.json",
            "data/labels/train-v1.labels",
            "data/labels/train-v1.manifest.json",
        ],
    },
    Stage {
        name: "labels-iiwa14",
        args: &["label-seeds", "--robot", "iiwa14"],
        writes: &[
            "data/iiwa14/labels/eval-v1.labels",
            "data/iiwa14/labels/eval-v1.manifest.json",
            "data/iiwa14/labels/train-v1.labels",
            "data/iiwa14/labels/train-v1.manifest.json",
        ],
    },
    Stage {
        name: "labels-ur5e",
        args: &["label-seeds", "--robot", "ur5e"],
        writes: &[
            "data/ur5e/labels/eval-v1.labels",
            "data/ur5e/labels/eval-v1.manifest.json",
            "data/ur5e/labels/train-v1.labels",
            "data/ur5e/labels/train-v1.manifest.json",
        ],
    },
    Stage {
        name: "diffusion",
        args: &["train-diffusion"],
        writes: &[
            "data/models/diffusion-v1.weights",
            "data/models/diffusion-v1.json",
            "docs/results/diffusion-training.csv",
            "docs/results/diffusion-training.svg",
        ],
    },
    Stage {
        name: "diffusion-iiwa14",
        args: &["train-diffusion", "--robot", "iiwa14"],
        writes: &[
            "data/iiwa14/models/diffusion-v1.weights",
            "data/iiwa14/models/diffusion-v1.json",
            "docs/results/iiwa14/diffusion-training.csv",
            "docs/results/iiwa14/diffusion-training.svg",
        ],
    },
    Stage {
        name: "diffusion-ur5e",
        args: &["train-diffusion", "--robot", "ur5e"],
        writes: &[
            "data/ur5e/models/diffusion-v1.weights",
            "data/ur5e/models/diffusion-v1.json",
            "docs/results/ur5e/diffusion-training.csv",
            "docs/results/ur5e/diffusion-training.svg",
        ],
    },
    Stage {
        name: "ppo",
        args: &["train-ppo"],
        writes: &[
            "data/models/ppo-v1.weights",
            "data/models/ppo-v1.json",
            "docs/results/ppo-training.md",
            "docs/results/ppo-learning-curve.csv",
            "docs/results/ppo-learning-curve.svg",
        ],
    },
    Stage {
        name: "ppo-iiwa14",
        args: &["train-ppo", "--robot", "iiwa14"],
        writes: &[
            "data/iiwa14/models/ppo-v1.weights",
            "data/iiwa14/models/ppo-v1.json",
            "docs/results/iiwa14/ppo-training.md",
            "docs/results/iiwa14/ppo-learning-curve.csv",
            "docs/results/iiwa14/ppo-learning-curve.svg",
        ],
    },
    Stage {
        name: "ppo-ur5e",
        args: &["train-ppo", "--robot", "ur5e"],
        writes: &[
            "data/ur5e/models/ppo-v1.weights",
            "data/ur5e/models/ppo-v1.json",
            "docs/results/ur5e/ppo-training.md",
            "docs/results/ur5e/ppo-learning-curve.csv",
            "docs/results/ur5e/ppo-learning-curve.svg",
        ],
    },
    Stage {
        name: "search-eval",
        args: &["search-eval"],
        writes: &[
            "docs/results/search.json",
            "docs/results/search.md",
            "docs/figures/search-budget.svg",
        ],
    },
    Stage {
        name: "search-eval-iiwa14",
        args: &["search-eval", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/search.json",
            "docs/results/iiwa14/search.md",
            "docs/figures/iiwa14/search-budget.svg",
        ],
    },
    Stage {
        name: "search-eval-ur5e",
        args: &["search-eval", "--robot", "ur5e"],
        writes: &[
            "docs/results/ur5e/search.json",
            "docs/results/ur5e/search.md",
            "docs/figures/ur5e/search-budget.svg",
        ],
    },
    Stage {
        name: "cartesian-eval",
        args: &["cartesian-eval"],
        writes: &["docs/results/cartesian.json", "docs/results/cartesian.md"],
    },
    Stage {
        name: "cartesian-eval-iiwa14",
        args: &["cartesian-eval", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/cartesian.json",
            "docs/results/iiwa14/cartesian.md",
        ],
    },
    Stage {
        name: "cartesian-eval-ur5e",
        args: &["cartesian-eval", "--robot", "ur5e"],
        writes: &[
            "docs/results/ur5e/cartesian.json",
            "docs/results/ur5e/cartesian.md",
        ],
    },
    Stage {
        name: "path-eval",
        args: &["path-eval"],
        writes: &["docs/results/paths.json", "docs/results/paths.md"],
    },
    Stage {
        name: "path-eval-iiwa14",
        args: &["path-eval", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/paths.json",
            "docs/results/iiwa14/paths.md",
        ],
    },
    Stage {
        name: "path-eval-ur5e",
        args: &["path-eval", "--robot", "ur5e"],
        writes: &["docs/results/ur5e/paths.json", "docs/results/ur5e/paths.md"],
    },
    Stage {
        name: "precision-eval",
        args: &["precision-eval"],
        writes: &["docs/results/precision.json", "docs/results/precision.md"],
    },
    Stage {
        name: "precision-eval-iiwa14",
        args: &["precision-eval", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/precision.json",
            "docs/results/iiwa14/precision.md",
        ],
    },
    Stage {
        name: "precision-eval-ur5e",
        args: &["precision-eval", "--robot", "ur5e"],
        writes: &[
            "docs/results/ur5e/precision.json",
            "docs/results/ur5e/precision.md",
        ],
    },
    Stage {
        name: "gap-eval",
        args: &["gap-eval"],
        writes: &["docs/results/gaps.json", "docs/results/gaps.md"],
    },
    Stage {
        name: "gap-eval-iiwa14",
        args: &["gap-eval", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/gaps.json",
            "docs/results/iiwa14/gaps.md",
        ],
    },
    Stage {
        name: "gap-eval-ur5e",
        args: &["gap-eval", "--robot", "ur5e"],
        writes: &["docs/results/ur5e/gaps.json", "docs/results/ur5e/gaps.md"],
    },
    Stage {
        name: "job-eval",
        args: &["job-eval"],
        writes: &["docs/results/jobs.json", "docs/results/jobs.md"],
    },
    Stage {
        name: "job-eval-iiwa14",
        args: &["job-eval", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/jobs.json",
            "docs/results/iiwa14/jobs.md",
        ],
    },
    Stage {
        name: "job-eval-ur5e",
        args: &["job-eval", "--robot", "ur5e"],
        writes: &["docs/results/ur5e/jobs.json", "docs/results/ur5e/jobs.md"],
    },
    Stage {
        name: "corpus-eval",
        args: &["corpus-eval", "--every", "20"],
        writes: &["docs/results/corpus.json", "docs/results/corpus.md"],
    },
    Stage {
        name: "place-eval",
        args: &["place-eval"],
        writes: &[
            "docs/results/placement.json",
            "docs/results/placement.md",
            "docs/figures/placement-map.svg",
        ],
    },
    Stage {
        name: "labels-report",
        args: &["label-seeds", "--report"],
        writes: &["docs/results/labels.json", "docs/results/labels.md"],
    },
    Stage {
        name: "labels-report-iiwa14",
        args: &["label-seeds", "--report", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/labels.json",
            "docs/results/iiwa14/labels.md",
        ],
    },
    Stage {
        name: "labels-report-ur5e",
        args: &["label-seeds", "--report", "--robot", "ur5e"],
        writes: &[
            "docs/results/ur5e/labels.json",
            "docs/results/ur5e/labels.md",
        ],
    },
    Stage {
        name: "eval",
        args: &["eval"],
        writes: &["docs/results/eval.json", "docs/results/eval.md"],
    },
    Stage {
        name: "eval-iiwa14",
        args: &["eval", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/eval.json",
            "docs/results/iiwa14/eval.md",
        ],
    },
    Stage {
        name: "eval-ur5e",
        args: &["eval", "--robot", "ur5e"],
        writes: &["docs/results/ur5e/eval.json", "docs/results/ur5e/eval.md"],
    },
    Stage {
        name: "eval-classical",
        args: &["eval", "--controller", "classical"],
        writes: &["docs/results/classical.json", "docs/results/classical.md"],
    },
    Stage {
        name: "eval-rl",
        args: &["eval", "--controller", "rl"],
        writes: &["docs/results/rl.json", "docs/results/rl.md"],
    },
    Stage {
        name: "eval-hybrid",
        args: &["eval", "--controller", "hybrid"],
        writes: &["docs/results/hybrid.json", "docs/results/hybrid.md"],
    },
    Stage {
        name: "eval-classical-k_lat-0",
        args: &[
            "eval",
            "--controller",
            "classical",
            "--lateral-gain",
            "0",
            "--name",
            "classical-k_lat-0",
        ],
        writes: &[
            "docs/results/classical-k_lat-0.json",
            "docs/results/classical-k_lat-0.md",
        ],
    },
    Stage {
        name: "velocity-limits",
        args: &["eval", "--compare-velocity-limits"],
        writes: &[
            "docs/results/velocity-limits.json",
            "docs/results/velocity-limits.md",
        ],
    },
    Stage {
        name: "velocity-limits-iiwa14",
        args: &["eval", "--compare-velocity-limits", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/velocity-limits.json",
            "docs/results/iiwa14/velocity-limits.md",
        ],
    },
    Stage {
        name: "velocity-limits-ur5e",
        args: &["eval", "--compare-velocity-limits", "--robot", "ur5e"],
        writes: &[
            "docs/results/ur5e/velocity-limits.json",
            "docs/results/ur5e/velocity-limits.md",
        ],
    },
    Stage {
        name: "eval-surface-on",
        args: &[
            "eval",
            "--surface",
            "on",
            "--seen-count",
            "0",
            "--name",
            "eval-surface-on",
        ],
        writes: &[
            "docs/results/eval-surface-on.json",
            "docs/results/eval-surface-on.md",
        ],
    },
    Stage {
        name: "eval-cell-surface-off",
        args: &[
            "eval",
            "--surface-clearance",
            "0.01",
            "--seen-count",
            "0",
            "--name",
            "eval-cell-surface-off",
        ],
        writes: &[
            "docs/results/eval-cell-surface-off.json",
            "docs/results/eval-cell-surface-off.md",
        ],
    },
    Stage {
        name: "eval-cell-surface-on",
        args: &[
            "eval",
            "--surface",
            "on",
            "--surface-clearance",
            "0.01",
            "--seen-count",
            "0",
            "--name",
            "eval-cell-surface-on",
        ],
        writes: &[
            "docs/results/eval-cell-surface-on.json",
            "docs/results/eval-cell-surface-on.md",
        ],
    },
    Stage {
        name: "ablate-classical-weights",
        args: &["ablate", "classical-weights"],
        writes: &[
            "docs/results/ablate-classical-weights.json",
            "docs/results/ablate-classical-weights.md",
        ],
    },
    Stage {
        name: "ablate-switching",
        args: &["ablate", "switching"],
        writes: &[
            "docs/results/ablate-switching.json",
            "docs/results/ablate-switching.md",
        ],
    },
    Stage {
        name: "ablate-cfg-scale",
        args: &["ablate", "cfg-scale"],
        writes: &[
            "docs/results/ablate-cfg-scale.json",
            "docs/results/ablate-cfg-scale.md",
        ],
    },
    Stage {
        name: "ablate-ddim-steps",
        args: &["ablate", "ddim-steps"],
        writes: &[
            "docs/results/ablate-ddim-steps.json",
            "docs/results/ablate-ddim-steps.md",
        ],
    },
    Stage {
        name: "timing",
        args: &["timing"],
        writes: &[
            "docs/results/timing.json",
            "docs/results/timing.md",
            "docs/figures/timing-durations.svg",
        ],
    },
    Stage {
        name: "timing-iiwa14",
        args: &["timing", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/timing.json",
            "docs/results/iiwa14/timing.md",
            "docs/figures/iiwa14/timing-durations.svg",
        ],
    },
    Stage {
        name: "timing-ur5e",
        args: &["timing", "--robot", "ur5e"],
        writes: &[
            "docs/results/ur5e/timing.json",
            "docs/results/ur5e/timing.md",
            "docs/figures/ur5e/timing-durations.svg",
        ],
    },
    Stage {
        name: "limit",
        args: &["limit"],
        writes: &[],
    },
    Stage {
        name: "limit-merge",
        args: &["limit", "--merge"],
        writes: &["docs/results/limit.json", "docs/results/limit.md"],
    },
    Stage {
        name: "limit-iiwa14",
        args: &["limit", "--robot", "iiwa14"],
        writes: &[],
    },
    Stage {
        name: "limit-merge-iiwa14",
        args: &["limit", "--merge", "--robot", "iiwa14"],
        writes: &[
            "docs/results/iiwa14/limit.json",
            "docs/results/iiwa14/limit.md",
        ],
    },
    Stage {
        name: "limit-ur5e",
        args: &["limit", "--robot", "ur5e"],
        writes: &[],
    },
    Stage {
        name: "limit-merge-ur5e",
        args: &["limit", "--merge", "--robot", "ur5e"],
        writes: &["docs/results/ur5e/limit.json", "docs/results/ur5e/limit.md"],
    },
    Stage {
        name: "figure-dp-seeds",
        args: &["figure-dp-seeds"],
        writes: &["docs/figures/dp-seeds.svg"],
    },
    Stage {
        name: "figure-branches",
        args: &["figure-branches"],
        writes: &["docs/figures/self-motion-branches.svg"],
    },
    Stage {
        name: "readme-picture",
        args: &["readme-picture"],
        writes: &["docs/figures/readme-demo.png"],
    },
    Stage {
        name: "readme-job-picture",
        args: &["readme-picture", "--job"],
        writes: &["docs/figures/job-demo.png"],
    },
    Stage {
        name: "report",
        args: &["report"],
        writes: &[
            "docs/results.md",
            "docs/results/summary.md",
            "docs/figures/reference-lengths.svg",
            "docs/figures/path-lengths.svg",
            "docs/figures/hybrid-trace.svg",
        ],
    },
];

/// Runs the stages not yet done (or those from `--from` on), or lists them.
pub fn run(args: &Args) -> anyhow::Result<()> {
    if args.list {
        for stage in STAGES {
            println!("{:<24} cargo xtask {}", stage.name, stage.args.join(" "));
            for file in stage.writes {
                println!("{:<24}   → {file}", "");
            }
        }
        return Ok(());
    }
    let journal = workspace::root().join("target/regenerate");
    std::fs::create_dir_all(&journal).with_context(|| format!("creating {}", journal.display()))?;
    let first = match &args.from {
        None => 0,
        Some(name) => STAGES
            .iter()
            .position(|stage| stage.name == name)
            .with_context(|| {
                let names: Vec<&str> = STAGES.iter().map(|stage| stage.name).collect();
                format!(
                    "--from: no stage '{name}' (the stages: {})",
                    names.join(", ")
                )
            })?,
    };
    let done = |stage: &Stage| journal.join(format!("{}.done", stage.name));
    for stage in &STAGES[first..] {
        let marker = done(stage);
        if marker.exists() {
            std::fs::remove_file(&marker)
                .with_context(|| format!("removing {}", marker.display()))?;
        }
    }
    let xtask = std::env::current_exe().context("locating the xtask binary")?;
    for (index, stage) in STAGES.iter().enumerate() {
        if index < first || done(stage).exists() {
            println!("[{}/{}] {}: done", index + 1, STAGES.len(), stage.name);
            continue;
        }
        println!(
            "[{}/{}] {}: cargo xtask {}",
            index + 1,
            STAGES.len(),
            stage.name,
            stage.args.join(" ")
        );
        let status = Command::new(&xtask)
            .args(stage.args)
            .current_dir(workspace::root())
            .status()
            .with_context(|| format!("starting stage {}", stage.name))?;
        if !status.success() {
            bail!(
                "stage {} failed ({status}); `cargo xtask regenerate` goes on from it",
                stage.name
            );
        }
        emg_io::write_atomically(done(stage), b"")
            .with_context(|| format!("journaling stage {}", stage.name))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::*;

    /// The files the stages write, relative to the workspace root.
    fn written() -> Vec<PathBuf> {
        STAGES
            .iter()
            .flat_map(|stage| stage.writes.iter().map(PathBuf::from))
            .collect()
    }

    /// The generated files of the workspace: the task sets, labels and models of every shipped
    /// robot, and every result and figure but the machine's own measurements.
    fn generated_files() -> Vec<PathBuf> {
        let root = workspace::root();
        let mut files = Vec::new();
        let mut walk = vec![
            root.join("data/tasks"),
            root.join("data/labels"),
            root.join("data/models"),
            root.join("data/iiwa14"),
            root.join("docs/results"),
            root.join("docs/figures"),
        ];
        while let Some(dir) = walk.pop() {
            for entry in std::fs::read_dir(&dir).expect("readable directory") {
                let path = entry.expect("directory entry").path();
                if path.is_dir() {
                    walk.push(path);
                } else {
                    files.push(path.strip_prefix(&root).expect("inside").to_path_buf());
                }
            }
        }
        files.push(PathBuf::from("docs/results.md"));
        // Pages of measurements no pipeline writes: timings of this machine's benches and
        // backends, and the record of the figures behind past design choices.
        let measured = [
            "docs/results/architecture-notes.md",
            "docs/results/benchmarks.md",
            "docs/results/diffusion-backends.md",
            "docs/results/ppo-backends.md",
        ];
        files.retain(|f| !measured.iter().any(|m| f == &PathBuf::from(m)));
        files.sort();
        files
    }

    #[test]
    fn the_stages_write_every_generated_file_and_only_existing_ones() {
        let written = written();
        for file in generated_files() {
            assert!(
                written.contains(&file),
                "{} is shipped but no stage of `cargo xtask regenerate` writes it",
                file.display()
            );
        }
        for file in &written {
            assert!(
                workspace::root().join(file).is_file(),
                "a stage writes {}, which is not shipped",
                file.display()
            );
        }
    }

    #[test]
    fn stage_names_are_unique() {
        for (i, stage) in STAGES.iter().enumerate() {
            assert!(
                STAGES[..i].iter().all(|s| s.name != stage.name),
                "{} twice",
                stage.name
            );
        }
    }
}
