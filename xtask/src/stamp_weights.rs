//! `cargo xtask stamp-weights`: record in weights files which robot they were trained for (the
//! values stay as they are), for files written before weights carried their robot.

use std::path::PathBuf;

use anyhow::Context;
use emg_diffusion::DenoiserWeights;
use emg_policy::PolicyWeights;

use crate::workspace;

/// Options of `stamp-weights`.
#[derive(clap::Args)]
pub struct Args {
    /// The robot the weights were trained for.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
    /// Weights files to stamp: policy or diffusion weights, told apart by their content.
    #[arg(required = true, value_name = "WEIGHTS")]
    files: Vec<PathBuf>,
}

/// Stamps every file in place (atomically).
pub fn run(args: &Args) -> anyhow::Result<()> {
    let robot = workspace::load_robot(&args.robot)?;
    let stamp = emg_planner::robot_stamp(&robot);
    for file in &args.files {
        let bytes = std::fs::read(file).with_context(|| format!("reading {}", file.display()))?;
        let kind = match PolicyWeights::from_bytes(&bytes) {
            Ok(weights) => {
                weights.stamped(stamp.clone()).write(file)?;
                "policy"
            }
            Err(policy_error) => {
                let weights = DenoiserWeights::from_bytes(&bytes).with_context(|| {
                    format!(
                        "{} is neither policy weights ({policy_error}) nor diffusion weights",
                        file.display()
                    )
                })?;
                weights.stamped(stamp.clone()).write(file)?;
                "diffusion"
            }
        };
        println!(
            "{}: {kind} weights recorded as trained for robot {stamp}",
            file.display()
        );
    }
    Ok(())
}
