//! The 31-value observation (Eq. 6), checked element by element against its definition.

mod common;

use emg_control::{ActingController, Episode, NullAction, RolloutConfig};
use emg_policy::{OBSERVATION_DIM, observe};

#[test]
fn observation_layout_element_by_element() {
    let robot = common::robot();
    let task = &common::tasks(&robot, 1)[0];
    let config = RolloutConfig::default();
    let seed = task.q0_seed.expect("sampled tasks keep their seed");
    let mut episode = Episode::start(&robot, task, &seed, &config);
    let first = episode.context().expect("a valid seed");
    let mut at_reset = [f32::NAN; OBSERVATION_DIM];
    observe(first, &mut at_reset);
    assert!(
        at_reset[27..].iter().all(|&a| a == 0.0),
        "previous action is 0 at reset"
    );

    let action = NullAction::new(0.3, -0.7, 0.1, 0.9);
    episode.apply(&action, ActingController::Learned);
    let context = episode.context().expect("one small step stays valid");
    let mut obs = [f32::NAN; OBSERVATION_DIM];
    observe(context, &mut obs);

    let limits = robot.limits();
    let q_bar = (context.q - limits.mid()).component_div(&limits.half_range());
    let z = robot.forward(&context.q).tool_axis();
    let n = task.n;
    let close = |got: f32, want: f64, what: &str| {
        assert!(
            (f64::from(got) - want).abs() < 1e-6,
            "{what}: observation holds {got}, expected {want}"
        );
    };
    for i in 0..7 {
        close(obs[i], q_bar[i], &format!("q̄[{i}]"));
        close(obs[7 + i], q_bar[i] * q_bar[i], &format!("q̄²[{i}]"));
    }
    for i in 0..3 {
        close(obs[14 + i], task.d[i], &format!("d[{i}]"));
        close(obs[17 + i], n[i], &format!("n[{i}]"));
        close(obs[20 + i], z[i], &format!("z[{i}]"));
    }
    close(obs[23], z[0] * n[0] + z[1] * n[1] + z[2] * n[2], "z·n");
    close(obs[24], z[1] * n[2] - z[2] * n[1], "(z×n)x");
    close(obs[25], z[2] * n[0] - z[0] * n[2], "(z×n)y");
    close(obs[26], z[0] * n[1] - z[1] * n[0], "(z×n)z");
    for i in 0..4 {
        close(obs[27 + i], action[i], &format!("previous action[{i}]"));
    }
}
