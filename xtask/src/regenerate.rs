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
use emg_planner::SHIPPED_ROBOTS;

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
    name: String,
    /// The `cargo xtask` arguments.
    args: Vec<&'static str>,
    /// The files it writes, relative to the workspace root.
    writes: Vec<String>,
}

/// A stage as [`TABLE`] states it: the FR3's where the pipeline runs for every shipped arm.
struct Template {
    name: &'static str,
    args: &'static [&'static str],
    writes: &'static [&'static str],
}

/// A row of [`TABLE`].
enum Row {
    /// A stage run once.
    Once(Template),
    /// Stages run for each shipped arm in turn, all of one arm's before the next arm's: the
    /// FR3's as stated, each other arm's named `<name>-<arm>`, its arguments followed by
    /// `--robot <arm>` and `other_arms_args`, its files in the arm's sub-directories.
    EveryArm {
        stages: &'static [Template],
        other_arms_args: &'static [&'static str],
    },
}

/// A pipeline run once for every shipped arm, with the same arguments on each.
const fn every_arm(stage: &'static Template) -> Row {
    Row::EveryArm {
        stages: std::slice::from_ref(stage),
        other_arms_args: &[],
    }
}

/// Every stage, each after the ones whose files it reads ([`stages`] spells them out).
const TABLE: &[Row] = &[
    Row::Once(Template {
        name: "import-arms",
        args: &["import-arms"],
        writes: &[
            "data/robots/irb120_pen.urdf",
            "data/robots/irb120_pen.srdf",
            "data/robots/irb120_pen.joint_limits.yaml",
            "data/robots/kr16_pen.urdf",
            "data/robots/kr16_pen.srdf",
            "data/robots/kr16_pen.joint_limits.yaml",
        ],
    }),
    Row::EveryArm {
        stages: &[Template {
            name: "tasks",
            args: &["make-tasks"],
            writes: &[
                "data/tasks/eval-v1.tasks",
                "data/tasks/train-v1.tasks",
                "data/tasks/tasks-v1.manifest.json",
            ],
        }],
        other_arms_args: &["--train-count", "20000"],
    },
    every_arm(&Template {
        name: "labels",
        args: &["label-seeds"],
        writes: &[
            "data/labels/eval-v1.labels",
            "data/labels/eval-v1.manifest.json",
            "data/labels/train-v1.labels",
            "data/labels/train-v1.manifest.json",
        ],
    }),
    every_arm(&Template {
        name: "diffusion",
        args: &["train-diffusion"],
        writes: &[
            "data/models/diffusion-v1.weights",
            "data/models/diffusion-v1.json",
            "docs/results/diffusion-training.csv",
            "docs/results/diffusion-training.svg",
        ],
    }),
    every_arm(&Template {
        name: "ppo",
        args: &["train-ppo"],
        writes: &[
            "data/models/ppo-v1.weights",
            "data/models/ppo-v1.json",
            "docs/results/ppo-training.md",
            "docs/results/ppo-learning-curve.csv",
            "docs/results/ppo-learning-curve.svg",
        ],
    }),
    every_arm(&Template {
        name: "search-eval",
        args: &["search-eval"],
        writes: &[
            "docs/results/search.json",
            "docs/results/search.md",
            "docs/figures/search-budget.svg",
        ],
    }),
    every_arm(&Template {
        name: "cartesian-eval",
        args: &["cartesian-eval"],
        writes: &["docs/results/cartesian.json", "docs/results/cartesian.md"],
    }),
    every_arm(&Template {
        name: "path-eval",
        args: &["path-eval"],
        writes: &["docs/results/paths.json", "docs/results/paths.md"],
    }),
    every_arm(&Template {
        name: "precision-eval",
        args: &["precision-eval"],
        writes: &["docs/results/precision.json", "docs/results/precision.md"],
    }),
    every_arm(&Template {
        name: "gap-eval",
        args: &["gap-eval"],
        writes: &["docs/results/gaps.json", "docs/results/gaps.md"],
    }),
    every_arm(&Template {
        name: "job-eval",
        args: &["job-eval"],
        writes: &["docs/results/jobs.json", "docs/results/jobs.md"],
    }),
    Row::Once(Template {
        name: "job-eval-irb120",
        args: &["job-eval", "--robot", "irb120"],
        writes: &[
            "docs/results/irb120/jobs.json",
            "docs/results/irb120/jobs.md",
        ],
    }),
    Row::Once(Template {
        name: "job-eval-kr16",
        args: &["job-eval", "--robot", "kr16"],
        writes: &["docs/results/kr16/jobs.json", "docs/results/kr16/jobs.md"],
    }),
    Row::Once(Template {
        name: "corpus-eval",
        args: &["corpus-eval", "--every", "20"],
        writes: &["docs/results/corpus.json", "docs/results/corpus.md"],
    }),
    Row::Once(Template {
        name: "place-eval",
        args: &["place-eval"],
        writes: &[
            "docs/results/placement.json",
            "docs/results/placement.md",
            "docs/figures/placement-map.svg",
        ],
    }),
    every_arm(&Template {
        name: "labels-report",
        args: &["label-seeds", "--report"],
        writes: &["docs/results/labels.json", "docs/results/labels.md"],
    }),
    every_arm(&Template {
        name: "eval",
        args: &["eval"],
        writes: &["docs/results/eval.json", "docs/results/eval.md"],
    }),
    Row::Once(Template {
        name: "eval-classical",
        args: &["eval", "--controller", "classical"],
        writes: &["docs/results/classical.json", "docs/results/classical.md"],
    }),
    Row::Once(Template {
        name: "eval-rl",
        args: &["eval", "--controller", "rl"],
        writes: &["docs/results/rl.json", "docs/results/rl.md"],
    }),
    Row::Once(Template {
        name: "eval-hybrid",
        args: &["eval", "--controller", "hybrid"],
        writes: &["docs/results/hybrid.json", "docs/results/hybrid.md"],
    }),
    Row::Once(Template {
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
    }),
    every_arm(&Template {
        name: "velocity-limits",
        args: &["eval", "--compare-velocity-limits"],
        writes: &[
            "docs/results/velocity-limits.json",
            "docs/results/velocity-limits.md",
        ],
    }),
    Row::Once(Template {
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
    }),
    Row::Once(Template {
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
    }),
    Row::Once(Template {
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
    }),
    Row::Once(Template {
        name: "ablate-classical-weights",
        args: &["ablate", "classical-weights"],
        writes: &[
            "docs/results/ablate-classical-weights.json",
            "docs/results/ablate-classical-weights.md",
        ],
    }),
    Row::Once(Template {
        name: "ablate-switching",
        args: &["ablate", "switching"],
        writes: &[
            "docs/results/ablate-switching.json",
            "docs/results/ablate-switching.md",
        ],
    }),
    Row::Once(Template {
        name: "ablate-cfg-scale",
        args: &["ablate", "cfg-scale"],
        writes: &[
            "docs/results/ablate-cfg-scale.json",
            "docs/results/ablate-cfg-scale.md",
        ],
    }),
    Row::Once(Template {
        name: "ablate-ddim-steps",
        args: &["ablate", "ddim-steps"],
        writes: &[
            "docs/results/ablate-ddim-steps.json",
            "docs/results/ablate-ddim-steps.md",
        ],
    }),
    every_arm(&Template {
        name: "timing",
        args: &["timing"],
        writes: &[
            "docs/results/timing.json",
            "docs/results/timing.md",
            "docs/figures/timing-durations.svg",
        ],
    }),
    Row::EveryArm {
        stages: &[
            Template {
                name: "limit",
                args: &["limit"],
                writes: &[],
            },
            Template {
                name: "limit-merge",
                args: &["limit", "--merge"],
                writes: &["docs/results/limit.json", "docs/results/limit.md"],
            },
        ],
        other_arms_args: &[],
    },
    Row::Once(Template {
        name: "figure-dp-seeds",
        args: &["figure-dp-seeds"],
        writes: &["docs/figures/dp-seeds.svg"],
    }),
    Row::Once(Template {
        name: "figure-branches",
        args: &["figure-branches"],
        writes: &["docs/figures/self-motion-branches.svg"],
    }),
    Row::Once(Template {
        name: "readme-picture",
        args: &["readme-picture"],
        writes: &["docs/figures/readme-demo.png"],
    }),
    Row::Once(Template {
        name: "readme-job-picture",
        args: &["readme-picture", "--job"],
        writes: &["docs/figures/job-demo.png"],
    }),
    Row::Once(Template {
        name: "report",
        args: &["report"],
        writes: &[
            "docs/results.md",
            "docs/results/summary.md",
            "docs/figures/reference-lengths.svg",
            "docs/figures/path-lengths.svg",
            "docs/figures/hybrid-trace.svg",
        ],
    }),
];

/// The directories a shipped arm other than the FR3 keeps its own files in, each under a
/// sub-directory of its own.
const ARM_DIRECTORIES: [&str; 3] = ["data/", "docs/results/", "docs/figures/"];

/// Every stage of [`TABLE`], in order.
fn stages() -> Vec<Stage> {
    let mut stages = Vec::new();
    for row in TABLE {
        match row {
            Row::Once(template) => stages.push(template.stage()),
            Row::EveryArm {
                stages: templates,
                other_arms_args,
            } => {
                for arm in SHIPPED_ROBOTS {
                    for template in *templates {
                        stages.push(match arm.data_subdir() {
                            "" => template.stage(),
                            subdir => template.other_arm(arm.name, subdir, other_arms_args),
                        });
                    }
                }
            }
        }
    }
    stages
}

impl Template {
    /// The stage as stated.
    fn stage(&self) -> Stage {
        Stage {
            name: self.name.to_string(),
            args: self.args.to_vec(),
            writes: self.writes.iter().map(|file| file.to_string()).collect(),
        }
    }

    /// The stage for the shipped arm `arm` whose files lie in the sub-directory `subdir`:
    /// `--robot <arm>` and `more_args` after the stated arguments.
    fn other_arm(&self, arm: &'static str, subdir: &str, more_args: &[&'static str]) -> Stage {
        let in_subdir = |file: &&str| {
            let (dir, rest) = ARM_DIRECTORIES
                .iter()
                .find_map(|dir| file.strip_prefix(dir).map(|rest| (dir, rest)))
                .unwrap_or_else(|| panic!("{file} lies outside every arm's directories"));
            format!("{dir}{subdir}/{rest}")
        };
        let mut args = self.args.to_vec();
        args.extend(["--robot", arm]);
        args.extend(more_args);
        Stage {
            name: format!("{}-{arm}", self.name),
            args,
            writes: self.writes.iter().map(in_subdir).collect(),
        }
    }
}

/// Runs the stages not yet done (or those from `--from` on), or lists them.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let stages = stages();
    if args.list {
        for stage in &stages {
            println!("{:<24} cargo xtask {}", stage.name, stage.args.join(" "));
            for file in &stage.writes {
                println!("{:<24}   → {file}", "");
            }
        }
        return Ok(());
    }
    let journal = workspace::root().join("target/regenerate");
    std::fs::create_dir_all(&journal).with_context(|| format!("creating {}", journal.display()))?;
    let first = match &args.from {
        None => 0,
        Some(name) => stages
            .iter()
            .position(|stage| &stage.name == name)
            .with_context(|| {
                let names: Vec<&str> = stages.iter().map(|stage| stage.name.as_str()).collect();
                format!(
                    "--from: no stage '{name}' (the stages: {})",
                    names.join(", ")
                )
            })?,
    };
    let done = |stage: &Stage| journal.join(format!("{}.done", stage.name));
    for stage in &stages[first..] {
        let marker = done(stage);
        if marker.exists() {
            std::fs::remove_file(&marker)
                .with_context(|| format!("removing {}", marker.display()))?;
        }
    }
    let xtask = std::env::current_exe().context("locating the xtask binary")?;
    for (index, stage) in stages.iter().enumerate() {
        if index < first || done(stage).exists() {
            println!("[{}/{}] {}: done", index + 1, stages.len(), stage.name);
            continue;
        }
        println!(
            "[{}/{}] {}: cargo xtask {}",
            index + 1,
            stages.len(),
            stage.name,
            stage.args.join(" ")
        );
        let status = Command::new(&xtask)
            .args(&stage.args)
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
        stages()
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
        let stages = stages();
        for (i, stage) in stages.iter().enumerate() {
            assert!(
                stages[..i].iter().all(|s| s.name != stage.name),
                "{} twice",
                stage.name
            );
        }
    }
}
