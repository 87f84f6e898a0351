//! `cargo xtask`: the workspace's pipelines.
//!
//! * `cargo xtask make-tasks`: the evaluation set and the training pool in `data/tasks/`.
//! * `cargo xtask eval --controller classical`: path-length statistics over the evaluation set,
//!   written to `docs/results/`.

mod eval;
mod make_tasks;
mod progress;
mod workspace;

use clap::{Parser, Subcommand};

/// Pipelines of the extreme straight-line motion workspace.
#[derive(Parser)]
#[command(name = "cargo xtask")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Sample the evaluation set and the disjoint training pool (fixed seed, bit-for-bit regenerable).
    MakeTasks(make_tasks::Args),
    /// Evaluate a controller over the evaluation set and write the results to docs/results/.
    Eval(eval::Args),
}

fn main() -> anyhow::Result<()> {
    match Cli::parse().command {
        Command::MakeTasks(args) => make_tasks::run(&args),
        Command::Eval(args) => eval::run(&args),
    }
}
