//! The committed task sets of every shipped robot are what `cargo xtask make-tasks` produces: the
//! first evaluation tasks regenerated from the default sampler configuration equal the shipped
//! file bit for bit.

use emg_control::{ClassicalGains, RolloutConfig, SamplerConfig, TaskSampler};
use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_planner::{DataDir, SHIPPED_ROBOTS};

#[test]
fn shipped_evaluation_sets_start_with_the_regenerated_tasks() {
    for shipped in SHIPPED_ROBOTS {
        let robot = Robot::from_chain_file(shipped.path(&data())).expect("robot loads");
        let tasks_dir = shipped.data_dir(&data()).join("tasks");
        let shipped_set = read_tasks(&tasks_dir.join("eval-v1.tasks"), &robot)
            .unwrap_or_else(|e| panic!("{}: shipped set loads: {e}", shipped.name));
        assert_eq!(shipped_set.len(), 10_000, "{}", shipped.name);
        let manifest: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(tasks_dir.join("tasks-v1.manifest.json")).expect("manifest"),
        )
        .expect("manifest parses");
        let sampler: SamplerConfig =
            serde_json::from_value(manifest["sampler"].clone()).expect("sampler config");
        assert_eq!(
            sampler,
            SamplerConfig::default(),
            "{}: the shipped set used the default sampler",
            shipped.name
        );
        let (rollout, gains) = (RolloutConfig::default(), ClassicalGains::default());
        let config = SamplerConfig {
            batch_size: 64,
            ..sampler
        };
        let regenerated =
            TaskSampler::new(&robot, &rollout, &gains, &config).take(150, u64::MAX, &|_| {});
        for (i, (a, b)) in regenerated.iter().zip(&shipped_set).enumerate() {
            let bits = |t: &emg_control::Task| {
                let seed = t.q0_seed.expect("seeded");
                t.p0.iter()
                    .chain(&t.d)
                    .chain(&t.n)
                    .chain(&seed)
                    .map(|v| v.to_bits())
                    .collect::<Vec<_>>()
            };
            assert_eq!(
                bits(a),
                bits(b),
                "{}: task {i} differs from the shipped file",
                shipped.name
            );
        }
    }
}

/// The workspace's shipped data directory.
fn data() -> DataDir {
    DataDir::new(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data"))
}
