//! Invariants of the shared rollout loop and of what a controller sees at a step.
//!
//! - Every recorded step holds every constraint by the library's own `first_violation`; times are
//!   `k·Δt`; TCP, tool angle and `ρ` are recorded as FK gives them; the path length is
//!   `(p_last − p0)·d`; a blamed `rejected_q` really breaks the named constraint.
//! - Replaying the loop by hand (`StepContext` → controller → clip → `q + q̇Δt`) reproduces
//!   every recorded configuration exactly; out-of-range actions are clipped; `reset`/`act` see
//!   the right step index and previous action.
//! - The step cap and an invalid start end the rollout as documented.
//! - An episode copied midway and continued goes on from exactly the copied state; an episode
//!   that rejected a step keeps exactly the state of its last accepted step.
//! - In a `StepContext`: the classical action is `clip(Bᵀξ/a_max)` with `ξ` of Eq. 3; `J·B ≈ 0`
//!   and `BᵀB = I`, so the null-space term leaves the TCP velocity unchanged; `J q̇ = ẋ` when
//!   undamped; the gradients match finite differences; the cone gate is 0 below `θmax − 8°`,
//!   1 at `θmax` and linear in between.

mod common;

use emg_control::{
    ActingController, CheckRollout, ClassicalController, ClassicalGains, NullAction,
    NullSpaceController, RolloutConfig, StepContext, Task, Termination, Trajectory, Violation,
    first_contact, first_violation, lead_axis, rollout, tool_angle_deg,
};
use emg_kinematics::{JointVector, Robot, null_space_basis};
use rand::RngExt;

use common::{checker, classical, random_q, rng, robot, tasks};

fn configs() -> [RolloutConfig; 2] {
    [
        RolloutConfig::default(),
        RolloutConfig {
            lateral_gain_per_s: 0.0,
            ..RolloutConfig::default()
        },
    ]
}

/// The recorded invariants of one trajectory that does not start invalid.
fn assert_invariants(robot: &Robot, task: &Task, trajectory: &Trajectory, config: &RolloutConfig) {
    let steps = &trajectory.steps;
    assert!(!steps.is_empty());
    for (k, step) in steps.iter().enumerate() {
        let kin = robot.forward(&step.q);
        if let Some(v) = first_violation(robot, task, &kin, &config.constraints) {
            panic!("step {k} of {} breaks {v}", steps.len());
        }
        if k == 0 {
            assert_eq!(step.time_s, 0.0, "the seed is at time 0");
        } else {
            // A step lasts Δt, or longer when time scaling honours the velocity limits.
            let elapsed = step.time_s - steps[k - 1].time_s;
            assert!(
                elapsed >= config.dt_s * (1.0 - 1e-12),
                "step {k} lasts {elapsed} s"
            );
        }
        assert_eq!(step.tcp, kin.tcp(), "TCP of step {k}");
        assert_eq!(
            step.tool_angle_deg,
            tool_angle_deg(&kin.tool_axis(), &task.n),
            "angle of step {k}"
        );
        assert_eq!(
            step.rho,
            robot.limits().limit_proximity(&step.q),
            "rho of step {k}"
        );
        let last = k + 1 == steps.len();
        let expected = if last && trajectory.termination == Termination::StepCap {
            None
        } else {
            Some(ActingController::Classical)
        };
        assert_eq!(step.controller, expected, "controller of step {k}");
    }
    let last = steps.last().unwrap();
    let length = (last.tcp - task.p0).dot(&task.d);
    assert!(
        (trajectory.path_length_m - length).abs() < 1e-15,
        "{} vs {length}",
        trajectory.path_length_m
    );
    match &trajectory.termination {
        Termination::Violation {
            violation,
            rejected_q,
        } => {
            let kin = robot.forward(rejected_q);
            let found = first_violation(robot, task, &kin, &config.constraints);
            assert_eq!(
                found.as_ref(),
                Some(violation),
                "rejected_q breaks something else"
            );
            // And the violation really exceeds its bound.
            match violation {
                Violation::JointLimit {
                    joint,
                    value_rad,
                    limit_rad,
                } => {
                    assert_eq!(*value_rad, rejected_q[joint - 1]);
                    let (lo, hi) = (
                        robot.limits().lower[joint - 1],
                        robot.limits().upper[joint - 1],
                    );
                    assert!(*value_rad < lo || *value_rad > hi);
                    assert!(*limit_rad == lo || *limit_rad == hi);
                }
                Violation::LineTolerance { distance_m } => {
                    assert!(*distance_m > config.constraints.line_tolerance_m);
                    assert_eq!(*distance_m, task.lateral_error(&kin.tcp()).norm());
                }
                Violation::ToolCone { angle_deg } => {
                    assert!(*angle_deg > config.constraints.theta_max_deg);
                    assert_eq!(*angle_deg, tool_angle_deg(&kin.tool_axis(), &task.n));
                }
                Violation::SelfCollision { clearance_m, .. } => {
                    assert!(*clearance_m < config.constraints.collision_margin_m);
                    assert!(
                        robot
                            .first_collision(&kin, config.constraints.collision_margin_m)
                            .is_some()
                    );
                }
                Violation::SceneContact { .. } => {
                    let contact = first_contact(robot, task, &kin, &config.constraints);
                    assert_eq!(contact.as_ref(), Some(violation));
                }
            }
        }
        Termination::StepCap => assert_eq!(steps.len(), config.max_steps + 1),
        Termination::InvalidStart { .. } => panic!("sampled seeds are valid"),
        Termination::Completed => panic!("a line has no end"),
    }
}

/// Replays the loop by hand with the classical controller and compares every configuration.
fn assert_replay(robot: &Robot, task: &Task, trajectory: &Trajectory, config: &RolloutConfig) {
    let controller = ClassicalController::default();
    let mut q = task.q0_seed.unwrap();
    let mut previous = NullAction::zeros();
    for k in 0..trajectory.steps.len() {
        assert_eq!(trajectory.steps[k].q, q, "configuration of step {k}");
        if trajectory.steps[k].controller.is_none() {
            break;
        }
        let context = StepContext::new(robot, task, config, k, robot.forward(&q), previous);
        let xi = controller.secondary_command(&context);
        let action = context.action_from_secondary(&xi);
        let next = q + context.joint_velocity(&action) * config.dt_s;
        if k + 1 == trajectory.steps.len() {
            let Termination::Violation { rejected_q, .. } = &trajectory.termination else {
                panic!("a last step with a controller must end in a violation");
            };
            assert_eq!(*rejected_q, next, "rejected configuration");
        }
        q = next;
        previous = action;
    }
}

#[test]
fn recorded_steps_hold_every_invariant() {
    let robot = robot();
    let mut labels = std::collections::BTreeSet::new();
    for config in configs() {
        for (_, task) in tasks(&robot, 80) {
            let trajectory = classical(&robot, &task, &config);
            assert_invariants(&robot, &task, &trajectory, &config);
            assert_replay(&robot, &task, &trajectory, &config);
            labels.insert(trajectory.termination.label());
        }
    }
    // The invariants were exercised on more than one kind of ending.
    assert!(labels.len() >= 2, "{labels:?}");
}

#[test]
fn progress_per_step_is_about_v_dt() {
    let robot = robot();
    let config = RolloutConfig::default();
    let mut moves = 0;
    for (_, task) in tasks(&robot, 40) {
        let trajectory = classical(&robot, &task, &config);
        for pair in trajectory.steps.windows(2) {
            let step = task.progress(&pair[1].tcp) - task.progress(&pair[0].tcp);
            let context = StepContext::new(
                &robot,
                &task,
                &config,
                0,
                robot.forward(&pair[0].q),
                NullAction::zeros(),
            );
            if context.pseudo_inverse.lambda == 0.0 {
                // First-order exact; the second-order FK error of a 0.05 s step is small.
                assert!(
                    (step - 0.01).abs() < 2.5e-3,
                    "progress {step} m in one step"
                );
                moves += 1;
            }
        }
    }
    assert!(moves > 200, "{moves}");
}

#[test]
fn lateral_correction_keeps_the_tcp_nearer_the_line() {
    let robot = robot();
    let [with, without] = configs();
    // Mean lateral distance over the steps both rollouts of a task share.
    let (mut drift_with, mut drift_without, mut count) = (0.0, 0.0, 0);
    for (_, task) in tasks(&robot, 40) {
        let (a, b) = (
            classical(&robot, &task, &with),
            classical(&robot, &task, &without),
        );
        for (x, y) in a.steps.iter().zip(&b.steps) {
            drift_with += task.lateral_error(&x.tcp).norm();
            drift_without += task.lateral_error(&y.tcp).norm();
            count += 1;
        }
    }
    let (drift_with, drift_without) = (drift_with / count as f64, drift_without / count as f64);
    assert!(
        drift_with < 0.5 * drift_without,
        "mean lateral error: k_lat = 5: {drift_with} m, k_lat = 0: {drift_without} m"
    );
}

/// A task whose default classical rollout runs at least `min_steps` steps.
fn long_task(robot: &Robot, min_steps: usize) -> (Task, Trajectory) {
    let config = RolloutConfig::default();
    tasks(robot, 100)
        .into_iter()
        .map(|(_, task)| {
            let trajectory = classical(robot, &task, &config);
            (task, trajectory)
        })
        .find(|(_, t)| t.steps.len() >= min_steps)
        .expect("some task runs long")
}

#[test]
fn step_cap_ends_with_the_cap_and_records_the_final_step() {
    let robot = robot();
    let (task, full) = long_task(&robot, 10);
    let config = RolloutConfig {
        max_steps: 3,
        ..RolloutConfig::default()
    };
    let capped = classical(&robot, &task, &config);
    assert_eq!(capped.termination, Termination::StepCap);
    assert_eq!(capped.steps.len(), 4);
    assert_invariants(&robot, &task, &capped, &config);
    for k in 0..4 {
        assert_eq!(
            capped.steps[k].q, full.steps[k].q,
            "capped rollout diverges at step {k}"
        );
    }
    assert_eq!(capped.steps[3].time_s, 3.0 * config.dt_s);
    assert_eq!(capped.steps[3].controller, None);
    assert!(
        capped.path_length_m > 0.02 && capped.path_length_m < 0.04,
        "{}",
        capped.path_length_m
    );
    checker()
        .check(&task, &capped, &config.constraints)
        .expect("checker accepts a capped rollout");

    let config = RolloutConfig {
        max_steps: 0,
        ..RolloutConfig::default()
    };
    let seed_only = classical(&robot, &task, &config);
    assert_eq!(seed_only.termination, Termination::StepCap);
    assert_eq!(seed_only.steps.len(), 1);
    assert_eq!(seed_only.path_length_m, 0.0);
}

#[test]
fn invalid_start_holds_only_the_seed() {
    let robot = robot();
    let config = RolloutConfig::default();
    let sampled = tasks(&robot, 20);
    let task = &sampled[0].1;
    // A seed of another task whose TCP is far from this task's line.
    let far = sampled
        .iter()
        .filter_map(|(_, t)| t.q0_seed)
        .find(|q| task.lateral_error(&robot.forward(q).tcp()).norm() > 0.1)
        .expect("a far seed");
    let trajectory = rollout(
        &robot,
        task,
        &far,
        &mut ClassicalController::default(),
        &config,
    );
    let Termination::InvalidStart {
        violation: Violation::LineTolerance { distance_m },
    } = &trajectory.termination
    else {
        panic!(
            "expected an invalid start at the line tolerance, got {:?}",
            trajectory.termination
        );
    };
    assert_eq!(
        *distance_m,
        task.lateral_error(&robot.forward(&far).tcp()).norm()
    );
    assert_eq!(trajectory.steps.len(), 1);
    assert_eq!(trajectory.steps[0].q, far);
    assert_eq!(trajectory.steps[0].controller, None);
    assert_eq!(
        trajectory.path_length_m,
        task.progress(&robot.forward(&far).tcp())
    );
    assert_eq!(trajectory.termination.label(), "invalid_start");
    checker()
        .check(task, &trajectory, &config.constraints)
        .expect("checker accepts a genuine invalid start");

    // A seed outside a joint limit is blamed on that joint.
    let mut outside = task.q0_seed.unwrap();
    outside[3] = robot.limits().upper[3] + 0.01;
    let trajectory = rollout(
        &robot,
        task,
        &outside,
        &mut ClassicalController::default(),
        &config,
    );
    assert!(
        matches!(
            trajectory.termination,
            Termination::InvalidStart {
                violation: Violation::JointLimit { joint: 4, .. }
            }
        ),
        "{:?}",
        trajectory.termination
    );
    assert_eq!(trajectory.steps.len(), 1);
}

/// A controller that returns a fixed, partly out-of-range action and logs what it is shown.
struct Fixed {
    action: NullAction,
    resets: usize,
    seen: Vec<(usize, NullAction)>,
}

impl NullSpaceController for Fixed {
    fn reset(&mut self, first: &StepContext<'_>) {
        assert_eq!(first.step, 0);
        self.resets += 1;
    }
    fn act(&mut self, step: &StepContext<'_>) -> (NullAction, ActingController) {
        self.seen.push((step.step, step.previous_action));
        (self.action, ActingController::Learned)
    }
}

#[test]
fn actions_are_clipped_and_the_interface_is_honoured() {
    let robot = robot();
    let config = RolloutConfig::default();
    let (task, _) = long_task(&robot, 6);
    let mut controller = Fixed {
        action: NullAction::new(5.0, -3.0, 0.25, 0.0),
        resets: 0,
        seen: Vec::new(),
    };
    let seed = task.q0_seed.unwrap();
    let trajectory = rollout(&robot, &task, &seed, &mut controller, &config);
    assert_eq!(controller.resets, 1);
    let clipped = NullAction::new(1.0, -1.0, 0.25, 0.0);
    let acted = trajectory
        .steps
        .iter()
        .filter(|s| s.controller.is_some())
        .count();
    assert_eq!(controller.seen.len(), acted);
    for (k, (step, previous)) in controller.seen.iter().enumerate() {
        assert_eq!(*step, k);
        assert_eq!(
            *previous,
            if k == 0 { NullAction::zeros() } else { clipped },
            "previous action at step {k}"
        );
    }
    let mut q = seed;
    for (k, record) in trajectory.steps.iter().enumerate() {
        assert_eq!(record.q, q, "step {k}");
        if record.controller.is_none() {
            break;
        }
        assert_eq!(record.controller, Some(ActingController::Learned));
        let context = StepContext::new(
            &robot,
            &task,
            &config,
            k,
            robot.forward(&q),
            NullAction::zeros(),
        );
        q += context.joint_velocity(&clipped) * config.dt_s;
    }
    checker()
        .check(&task, &trajectory, &config.constraints)
        .expect("checker accepts it");
}

/// Step contexts at the recorded configurations of a few classical rollouts.
fn contexts<'a>(
    robot: &'a Robot,
    tasks: &'a [(u64, Task)],
    config: &'a RolloutConfig,
) -> Vec<StepContext<'a>> {
    let mut out = Vec::new();
    for (_, task) in tasks {
        let trajectory = classical(robot, task, config);
        for (k, step) in trajectory.steps.iter().enumerate().step_by(3) {
            out.push(StepContext::new(
                robot,
                task,
                config,
                k,
                robot.forward(&step.q),
                NullAction::zeros(),
            ));
        }
    }
    out
}

/// Checks `act` against Eq. 3 computed by hand; returns (saturated, interior) component counts
/// and how many steps had the cone gate open.
fn check_classical_action(gains: ClassicalGains) -> (usize, usize, usize) {
    let robot = robot();
    let config = RolloutConfig::default();
    let sampled = tasks(&robot, 25);
    let mut controller = ClassicalController::new(gains.clone());
    let limits = robot.limits();
    let (mut saturated, mut interior, mut gated) = (0, 0, 0);
    for context in contexts(&robot, &sampled, &config) {
        let theta = context.tool_angle_deg;
        let gate = ((theta - (30.0 - gains.cone_gate_width_deg)) / gains.cone_gate_width_deg)
            .clamp(0.0, 1.0);
        let xi = context.manipulability_gradient * gains.k_mu
            - (context.q - limits.mid()).component_div(&(limits.upper - limits.lower)) * gains.k_jl
            + context.alignment_gradient * (gains.k_theta * gate);
        assert!((controller.secondary_command(&context) - xi).norm() < 1e-12 * (1.0 + xi.norm()));
        let expected = (context.basis.columns.transpose() * xi / 0.5).map(|a| a.clamp(-1.0, 1.0));
        let (action, acting) = controller.act(&context);
        assert_eq!(acting, ActingController::Classical);
        assert!(
            (action - expected).norm() < 1e-12,
            "{action:?} vs {expected:?}"
        );
        assert!(action.iter().all(|a| a.abs() <= 1.0));
        saturated += action.iter().filter(|a| a.abs() == 1.0).count();
        interior += action.iter().filter(|a| a.abs() < 1.0).count();
        gated += usize::from(gate > 0.0);
    }
    (saturated, interior, gated)
}

#[test]
fn classical_action_is_the_clipped_projection_of_eq3() {
    let defaults = ClassicalGains::default();
    assert_eq!(
        (
            defaults.k_mu,
            defaults.k_jl,
            defaults.k_theta,
            defaults.cone_gate_width_deg
        ),
        (0.8, 0.4, 0.2, 8.0)
    );
    let (_, interior, gated) = check_classical_action(defaults);
    assert!(interior > 0);
    assert!(gated > 0, "the cone term was never active");
    // With large gains the clip is exercised too.
    let strong = ClassicalGains {
        k_mu: 40.0,
        k_jl: 20.0,
        k_theta: 10.0,
        cone_gate_width_deg: 8.0,
        ..ClassicalGains::default()
    };
    let (saturated, interior, _) = check_classical_action(strong);
    assert!(
        saturated > 0 && interior > 0,
        "clipping never/always active: {saturated} {interior}"
    );
}

#[test]
fn null_space_motion_leaves_the_tcp_velocity_unchanged() {
    let robot = robot();
    let config = RolloutConfig::default();
    let sampled = tasks(&robot, 25);
    let mut rng = rng(21);
    let mut undamped = 0;
    for context in contexts(&robot, &sampled, &config) {
        let j = context.kinematics.jacobian();
        let b = &context.basis.columns;
        let scale = j.norm();
        assert!(
            (j * b).norm() < 1e-10 * scale.max(1.0),
            "‖JB‖ = {}",
            (j * b).norm()
        );
        assert!((b.transpose() * b - nalgebra::Matrix4::identity()).norm() < 1e-10);
        let a = NullAction::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let with = j * context.joint_velocity(&a);
        let without = j * context.joint_velocity(&NullAction::zeros());
        assert!(
            (with - without).norm() < 1e-10,
            "null motion moves the TCP by {}",
            (with - without).norm()
        );
        // B a with the action from a secondary command in its span is recovered exactly.
        let c = NullAction::from_fn(|_, _| rng.random_range(-0.9..0.9));
        let xi = b * c * config.null_speed_max_rad_per_s;
        assert!((context.action_from_secondary(&xi) - c).norm() < 1e-12);
        // ẋ = v d + k_lat e, e pointing from the TCP back to the line.
        let task = context.task;
        let offset = task.p0 - context.kinematics.tcp();
        let toward_line = offset - task.d * offset.dot(&task.d);
        let expected = task.d * 0.2 + toward_line * 5.0;
        assert!(
            (context.task_velocity() - expected).norm() < 1e-15,
            "ẋ = {:?}",
            context.task_velocity()
        );
        if context.pseudo_inverse.lambda == 0.0 {
            assert!(
                (without - context.task_velocity()).norm() < 1e-9,
                "J J⁺ ẋ ≠ ẋ"
            );
            undamped += 1;
        }
        // The first column follows the projected manipulability gradient unless it fell back.
        if !context.basis.fallback[0] {
            let n = null_space_basis(&context.kinematics);
            let projected = n * (n.transpose() * context.manipulability_gradient);
            assert!((b.column(0) - projected.normalize()).norm() < 1e-8);
        }
    }
    assert!(undamped > 50, "{undamped}");
}

#[test]
fn step_context_gradients_match_finite_differences() {
    let robot = robot();
    let config = RolloutConfig::default();
    let sampled = tasks(&robot, 10);
    let mut rng = rng(22);
    let h = 1e-6;
    for (_, task) in &sampled {
        let q = random_q(&mut rng, &robot);
        let at = |q: JointVector| {
            StepContext::new(
                &robot,
                task,
                &config,
                0,
                robot.forward(&q),
                NullAction::zeros(),
            )
        };
        let context = at(q);
        let centring = |c: &StepContext<'_>| -c.q_normalised.map(|x| x * x).sum() / 7.0;
        let alignment = |c: &StepContext<'_>| c.kinematics.tool_axis().dot(&task.n);
        for i in 0..7 {
            let (plus, minus) = (
                at(q + JointVector::ith(i, h)),
                at(q - JointVector::ith(i, h)),
            );
            let fd = |f: &dyn Fn(&StepContext<'_>) -> f64| (f(&plus) - f(&minus)) / (2.0 * h);
            let w = fd(&|c| c.manipulability);
            assert!(
                (w - context.manipulability_gradient[i]).abs() < 1e-5 * (1.0 + w.abs()),
                "∇w_d[{i}]"
            );
            assert!(
                (fd(&alignment) - context.alignment_gradient[i]).abs() < 1e-6,
                "∇(z·n)[{i}]"
            );
            assert!(
                (fd(&centring) - context.centring_gradient[i]).abs() < 1e-6,
                "∇(−mean q̄²)[{i}]"
            );
        }
        assert!((context.rho - robot.limits().limit_proximity(&q)).abs() < 1e-15);
        assert_eq!(
            context.tool_angle_deg,
            tool_angle_deg(&context.kinematics.tool_axis(), &task.n)
        );
    }
}

/// The tool axis at `q`.
fn tool_axis(robot: &Robot, q: &JointVector) -> emg_kinematics::Vec3 {
    robot.forward(q).tool_axis()
}

#[test]
fn the_leading_tilt_term_aims_the_tool_ahead_of_its_drift() {
    let robot = robot();
    let config = RolloutConfig::default();
    let sampled = tasks(&robot, 10);
    let gains = ClassicalGains {
        k_lead: 5.0,
        lead_deg: 20.0,
        ..ClassicalGains::default()
    };
    let paper = ClassicalController::default();
    let leading = ClassicalController::new(gains.clone());
    let h = 1e-6;
    let mut checked = 0;
    for context in contexts(&robot, &sampled, &config) {
        let n = context.task.n;
        // The tilt the task command alone causes, by finite differences of the tool axis.
        let task_rate = context.pseudo_inverse.matrix * context.task_velocity();
        let rate = (tool_axis(&robot, &(context.q + task_rate * h))
            - tool_axis(&robot, &(context.q - task_rate * h)))
            / (2.0 * h);
        let tilt = rate - n * n.dot(&rate);
        if tilt.norm() < 1e-3 {
            continue;
        }
        let m = lead_axis(&context, gains.lead_deg);
        assert!((m.norm() - 1.0).abs() < 1e-12);
        assert!((m.dot(&n) - libm::cos(20f64.to_radians())).abs() < 1e-12);
        // Its part across n points against the drift.
        let across = m - n * n.dot(&m);
        let cosine = across.dot(&tilt) / (across.norm() * tilt.norm());
        assert!(cosine < -1.0 + 1e-6, "cos = {cosine}");
        // ξ gains k_lead ∇(z·m), the gradient by finite differences.
        let gradient = JointVector::from_fn(|i, _| {
            let mut e = JointVector::zeros();
            e[i] = h;
            (tool_axis(&robot, &(context.q + e)).dot(&m)
                - tool_axis(&robot, &(context.q - e)).dot(&m))
                / (2.0 * h)
        });
        // The paper's gains otherwise, so the difference is the lead term alone.
        let extra = leading.secondary_command(&context) - paper.secondary_command(&context);
        assert!(
            (extra - gradient * gains.k_lead).amax() < 1e-6,
            "{extra} against {}",
            gradient * gains.k_lead
        );
        checked += 1;
    }
    assert!(checked > 20, "only {checked} steps tilted the tool");
}

#[test]
fn cone_gate_is_zero_then_linear_then_one() {
    let controller = ClassicalController::default();
    let gate = |theta: f64| controller.cone_gate(theta, 30.0);
    for theta in [0.0, 10.0, 21.0, 21.999, 22.0] {
        assert_eq!(gate(theta), 0.0, "g({theta})");
    }
    for (theta, expected) in [(23.0, 0.125), (26.0, 0.5), (29.0, 0.875), (30.0, 1.0)] {
        assert!(
            (gate(theta) - expected).abs() < 1e-12,
            "g({theta}) = {}",
            gate(theta)
        );
    }
    for theta in [30.0, 31.0, 90.0, 180.0] {
        assert_eq!(gate(theta), 1.0, "g({theta})");
    }
    // Monotone and continuous across the band.
    let mut previous = 0.0;
    for i in 0..=400 {
        let g = gate(20.0 + i as f64 * 0.025);
        assert!(g >= previous && g - previous <= 0.025 / 8.0 + 1e-12);
        previous = g;
    }
    // The width and θmax are honoured.
    let wide = ClassicalController::new(ClassicalGains {
        cone_gate_width_deg: 4.0,
        ..ClassicalGains::default()
    });
    assert_eq!(wide.cone_gate(15.9, 20.0), 0.0);
    assert!((wide.cone_gate(18.0, 20.0) - 0.5).abs() < 1e-12);
    assert_eq!(wide.cone_gate(20.0, 20.0), 1.0);
}

/// The classical controller, but tagging its actions as a search's (to tell which controller a
/// continued episode used).
struct Tagged(ClassicalController);

impl NullSpaceController for Tagged {
    fn reset(&mut self, first: &StepContext<'_>) {
        self.0.reset(first);
    }

    fn act(&mut self, step: &StepContext<'_>) -> (NullAction, ActingController) {
        (self.0.act(step).0, ActingController::Search)
    }
}

#[test]
fn an_episode_copied_midway_goes_on_from_exactly_that_state() {
    let robot = robot();
    let config = RolloutConfig::default();
    for (_, task) in tasks(&robot, 6) {
        let seed = task.q0_seed.expect("sampled tasks keep their seed");
        let mut controller = ClassicalController::new(ClassicalGains::default());
        let whole = rollout(&robot, &task, &seed, &mut controller, &config);
        if whole.steps.len() < 6 {
            continue;
        }
        // Drive a fresh episode for a few steps, copy it, and let another controller finish
        // the copy: the first steps are the whole rollout's, the rest the new controller's.
        let mut episode = emg_control::Episode::start(&robot, &task, &seed, &config);
        controller.reset(episode.context().expect("a valid start"));
        for _ in 0..4 {
            let context = episode.context().expect("running");
            let (action, acting) = controller.act(context);
            episode.apply(&action, acting);
        }
        let copy = episode.clone();
        let finished = emg_control::continue_rollout(episode, &mut controller);
        assert_eq!(finished, whole, "continuing the episode changes nothing");
        let mut tagged = Tagged(ClassicalController::new(ClassicalGains::default()));
        let taken_over = emg_control::continue_rollout(copy, &mut tagged);
        assert_eq!(taken_over.steps[..4], whole.steps[..4]);
        assert!(
            taken_over.steps[4..]
                .iter()
                .all(|s| s.controller.is_none_or(|c| c == ActingController::Search)),
            "the copy goes on with the controller that took it over"
        );
    }
}

#[test]
fn a_rejected_step_leaves_the_state_of_the_last_accepted_one() {
    let robot = robot();
    let config = RolloutConfig::default();
    let mut rejected = 0;
    for (_, task) in tasks(&robot, 6) {
        let seed = task.q0_seed.expect("sampled tasks keep their seed");
        let mut controller = ClassicalController::new(ClassicalGains::default());
        let mut episode = emg_control::Episode::start(&robot, &task, &seed, &config);
        controller.reset(episode.context().expect("a valid start"));
        while let Some(context) = episode.context() {
            let (action, acting) = controller.act(context);
            episode.apply(&action, acting);
        }
        let state = episode.state();
        let trajectory = episode.clone().finish();
        if !matches!(trajectory.termination, Termination::Violation { .. }) {
            continue;
        }
        rejected += 1;
        let last = trajectory
            .steps
            .last()
            .expect("a trajectory holds its seed");
        assert_eq!(state.q, last.q, "the state is the last accepted step's");
        let fresh = StepContext::new(
            &robot,
            &task,
            &config,
            state.step,
            robot.forward(&state.q),
            state.previous_action,
        );
        // Debug prints every quantity of the step, each f64 in its shortest exact form.
        assert_eq!(
            format!(
                "{:?}",
                (&state.kinematics, &state.pseudo_inverse, &state.basis)
            ),
            format!(
                "{:?}",
                (&fresh.kinematics, &fresh.pseudo_inverse, &fresh.basis)
            )
        );
        assert_eq!(
            (state.rho, state.tool_angle_deg, state.manipulability),
            (fresh.rho, fresh.tool_angle_deg, fresh.manipulability)
        );
        assert_eq!(
            [
                state.manipulability_gradient,
                state.alignment_gradient,
                state.centring_gradient
            ],
            [
                fresh.manipulability_gradient,
                fresh.alignment_gradient,
                fresh.centring_gradient
            ]
        );
    }
    assert!(rejected > 0, "some rollout ends by rejecting a step");
}
