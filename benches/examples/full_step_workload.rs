//! The `full_step` benchmark's rollout ([`emg_benches::Fixture::long_rollout`]), repeated: the
//! workload whose instructions `cargo xtask bench-report` counts under valgrind.
//!
//! `full_step_workload REPETITIONS` rolls it out REPETITIONS times and prints the steps it
//! accepted in all; the difference of two runs' instruction counts over the difference of their
//! steps is the instruction count of one step, free of the loading both runs share.

use emg_benches::Fixture;
use emg_control::{ClassicalController, RolloutConfig, rollout};

fn main() {
    let repetitions = match std::env::args().nth(1).map(|arg| arg.parse::<usize>()) {
        Some(Ok(repetitions)) => repetitions,
        _ => {
            eprintln!("usage: full_step_workload REPETITIONS (a count of rollouts, e.g. 20)");
            std::process::exit(2);
        }
    };
    let fixture = Fixture::load();
    let long = fixture.long_rollout();
    let config = RolloutConfig::default();
    let mut steps = 0;
    for _ in 0..repetitions {
        let mut controller = ClassicalController::default();
        let trajectory = rollout(
            &fixture.robot,
            long.task,
            &long.seed,
            &mut controller,
            &config,
        );
        steps += trajectory.steps.len() - 1;
    }
    println!("{steps}");
}
