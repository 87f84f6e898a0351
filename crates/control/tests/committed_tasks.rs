//! The committed task sets are what `cargo xtask make-tasks` produces: the first evaluation tasks
//! regenerated from the default sampler configuration equal the shipped file bit for bit.

use emg_control::{ClassicalGains, RolloutConfig, SamplerConfig, TaskSampler, read_tasks};
use emg_kinematics::Robot;

#[test]
fn shipped_evaluation_set_starts_with_the_regenerated_tasks() {
    let robot = Robot::from_urdf_file(emg_kinematics::default_robot_path(), "link0", "pen_tip")
        .expect("robot loads");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let shipped =
        read_tasks(&root.join("data/tasks/eval-v1.tasks"), &robot).expect("shipped set loads");
    assert_eq!(shipped.len(), 10_000);
    let manifest: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root.join("data/tasks/tasks-v1.manifest.json")).expect("manifest"),
    )
    .expect("manifest parses");
    let sampler: SamplerConfig =
        serde_json::from_value(manifest["sampler"].clone()).expect("sampler config");
    assert_eq!(
        sampler,
        SamplerConfig::default(),
        "the shipped set used the default sampler"
    );
    let (rollout, gains) = (RolloutConfig::default(), ClassicalGains::default());
    let config = SamplerConfig {
        batch_size: 64,
        ..sampler
    };
    let regenerated = TaskSampler::new(&robot, &rollout, &gains, &config).take(150, &|_| {});
    for (i, (a, b)) in regenerated.iter().zip(&shipped).enumerate() {
        let bits = |t: &emg_control::Task| {
            let seed = t.q0_seed.expect("seeded");
            t.p0.iter()
                .chain(&t.d)
                .chain(&t.n)
                .chain(&seed)
                .map(|v| v.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(a), bits(b), "task {i} differs from the shipped file");
    }
}
