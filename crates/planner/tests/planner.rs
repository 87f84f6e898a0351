//! The planner end to end on the shipped FR3 models: each controller kind plans exactly what its
//! controller rolls out by hand, every plan passes the independent checker, `plan_many` is the
//! same on one and two threads, and bad requests fail with errors that say what is missing.

use emg_control::{CheckRollout, ClassicalController, RolloutConfig, Task, rollout};
use emg_hybrid::{HybridController, HysteresisSwitch};
use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_planner::{
    ControllerKind, DataDir, Models, PlanError, PlanRequest, Planner, PlannerConfig,
    SHIPPED_ROBOTS, SeedError, SeedSource, ShippedRobot, demo_task,
};
use emg_verify::ReferenceModel;

fn data() -> DataDir {
    DataDir::new(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data"))
}

fn fr3() -> ShippedRobot {
    ShippedRobot::by_name("fr3").expect("the FR3 ships")
}

fn robot() -> Robot {
    Robot::from_chain_file(fr3().path(&data())).expect("robot loads")
}

fn planner(models: Models) -> Planner {
    Planner::new(robot(), models, PlannerConfig::default()).expect("default config is valid")
}

fn shipped_models() -> Models {
    Models::shipped(&robot(), &fr3().data_dir(&data())).expect("shipped models load")
}

fn checker(robot: &Robot) -> ReferenceModel {
    ReferenceModel::from_urdf_file(&fr3().path(&data()), robot.base_link(), robot.tip_link())
        .expect("checker loads")
}

fn eval_tasks(robot: &Robot, count: usize) -> Vec<Task> {
    let mut tasks = read_tasks(&fr3().data_dir(&data()).join("tasks/eval-v1.tasks"), robot)
        .expect("shipped tasks load");
    tasks.truncate(count);
    tasks
}

#[test]
fn each_kind_plans_what_its_controller_rolls_out() {
    let planner = planner(shipped_models());
    let robot = planner.robot();
    let config = RolloutConfig::default();
    let policy = planner.models().policy.clone().expect("shipped policy");
    let switch = PlannerConfig::default().switch;
    for task in eval_tasks(robot, 6) {
        let seed = task.q0_seed.expect("shipped tasks carry q0_seed");
        for kind in ControllerKind::ALL {
            let request = PlanRequest {
                seed: Some(SeedSource::Generating),
                controller: kind,
                ..PlanRequest::pipeline()
            };
            let plan = planner.plan(&task, &request).expect("plans");
            assert_eq!(plan.seed.q, seed);
            assert_eq!(plan.seed.source, "generating");
            let by_hand = match kind {
                ControllerKind::Classical => rollout(
                    robot,
                    &task,
                    &seed,
                    &mut ClassicalController::default(),
                    &config,
                ),
                ControllerKind::Rl => rollout(robot, &task, &seed, &mut policy.clone(), &config),
                ControllerKind::Hybrid => rollout(
                    robot,
                    &task,
                    &seed,
                    &mut HybridController::new(
                        policy.clone(),
                        ClassicalController::default(),
                        HysteresisSwitch::new(switch.clone()).unwrap(),
                        Default::default(),
                    ),
                    &config,
                ),
            };
            assert_eq!(plan.trajectory, by_hand, "{kind}");
        }
    }
}

#[test]
fn plans_pass_the_checker_and_do_not_depend_on_the_thread_count() {
    let planner = planner(shipped_models());
    let tasks = eval_tasks(planner.robot(), 24);
    let request = PlanRequest::pipeline();
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| planner.plan_many(&tasks, &request))
    };
    let one: Vec<_> = on(1).into_iter().map(|p| p.expect("plans")).collect();
    let two: Vec<_> = on(2).into_iter().map(|p| p.expect("plans")).collect();
    assert_eq!(one, two);
    let checker = checker(planner.robot());
    let constraints = &planner.config().rollout.constraints;
    for (task, plan) in tasks.iter().zip(&one) {
        assert_eq!(
            *plan,
            planner.plan(task, &request).unwrap(),
            "in task order"
        );
        checker
            .check(task, &plan.trajectory, constraints)
            .expect("every plan holds every constraint");
    }
    assert!(
        one.iter().any(|p| p.seed.source == "dp"),
        "the default seed is the diffusion seeder's"
    );
}

#[test]
fn the_demo_plans_on_every_shipped_robot() {
    for shipped in SHIPPED_ROBOTS {
        let robot = Robot::from_chain_file(shipped.path(&data())).expect("robot loads");
        let models = Models::shipped(&robot, &shipped.data_dir(&data())).expect("models load");
        let planner = Planner::new(robot, models, PlannerConfig::default()).unwrap();
        let task = demo_task(planner.robot()).expect("demo task");
        let plan = planner.plan(&task, &PlanRequest::pipeline()).unwrap();
        assert!(plan.trajectory.path_length_m > 0.1, "{}", shipped.name);
    }
}

#[test]
fn missing_models_and_seeds_are_named() {
    let planner = planner(Models::default());
    let task = demo_task(planner.robot()).unwrap();
    let learned = PlanRequest {
        seed: None,
        controller: ControllerKind::Rl,
        ..PlanRequest::pipeline()
    };
    let error = planner.plan(&task, &learned).unwrap_err();
    assert!(matches!(error, PlanError::Controller(_)), "{error}");
    assert!(error.to_string().contains("policy"), "{error}");

    let dp = PlanRequest {
        seed: Some(SeedSource::Dp),
        controller: ControllerKind::Classical,
        ..PlanRequest::pipeline()
    };
    let error = planner.plan(&task, &dp).unwrap_err();
    assert!(
        matches!(error, PlanError::Seed(SeedError::NoSeeder)),
        "{error}"
    );

    let unseeded = Task {
        q0_seed: None,
        ..task.clone()
    };
    let generating = PlanRequest {
        seed: Some(SeedSource::Generating),
        controller: ControllerKind::Classical,
        ..PlanRequest::pipeline()
    };
    let error = planner.plan(&unseeded, &generating).unwrap_err();
    assert!(error.to_string().contains("q0_seed"), "{error}");
    // Without a seeder or a q0_seed the default seed is the mid-range configuration.
    let default = PlanRequest {
        seed: None,
        controller: ControllerKind::Classical,
        ..PlanRequest::pipeline()
    };
    let plan = planner.plan(&unseeded, &default).unwrap();
    assert_eq!(plan.seed.source, "home");
}

#[test]
fn names_parse_back() {
    for kind in ControllerKind::ALL {
        assert_eq!(kind.name().parse::<ControllerKind>().unwrap(), kind);
    }
    let error = "pid".parse::<ControllerKind>().unwrap_err().to_string();
    assert!(error.contains("classical, rl or hybrid"), "{error}");
    for source in [
        SeedSource::Dp,
        SeedSource::Generating,
        SeedSource::Home,
        SeedSource::QMu,
        SeedSource::QJl,
    ] {
        assert_eq!(source.name().parse::<SeedSource>().unwrap(), source);
    }
    let given: SeedSource = "q=0,0.1,0,-1.5,0,1.5,0.7".parse().unwrap();
    assert_eq!(given.name(), "given");
    // One value per joint: the count is checked against the arm when the seed is prepared;
    // more than any arm has is refused at once.
    assert_eq!(
        "q=0,1,2,3,4,5".parse::<SeedSource>().unwrap(),
        SeedSource::Given(vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0])
    );
    let error = "q=0,1,2,3,4,5,6,7"
        .parse::<SeedSource>()
        .unwrap_err()
        .to_string();
    assert!(error.contains("expected 7"), "{error}");
}

#[test]
fn a_bad_config_file_names_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plan.json");
    std::fs::write(&path, r#"{"rollout": {"dt": 0.1}}"#).unwrap();
    let error = PlannerConfig::read(&path).unwrap_err().to_string();
    assert!(
        error.contains("dt") && error.contains("plan.json"),
        "{error}"
    );
    let config: PlannerConfig =
        serde_json::from_str(r#"{"switch": {"tau_enter": 0.9, "tau_exit": 0.8}}"#).unwrap();
    assert_eq!(config.switch.tau_exit, 0.8);
    assert_eq!(config.rollout, RolloutConfig::default());
}

#[test]
fn out_of_range_values_are_refused_naming_field_value_and_range() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plan.json");
    for (json, expected) in [
        (
            r#"{"rollout": {"max_steps": 1000000000}}"#,
            "rollout.max_steps must be in [1, 100000], got 1000000000",
        ),
        (
            r#"{"rollout": {"max_steps": 0}}"#,
            "rollout.max_steps must be in [1, 100000], got 0",
        ),
        (
            r#"{"rollout": {"dt_s": -0.05}}"#,
            "rollout.dt_s must be in (0, ∞), got -0.05",
        ),
        (
            r#"{"rollout": {"speed_m_per_s": 0}}"#,
            "rollout.speed_m_per_s must be in (0, ∞), got 0",
        ),
        (
            r#"{"rollout": {"constraints": {"theta_max_deg": 0}}}"#,
            "constraints.theta_max_deg must be in (0, 90), got 0",
        ),
        (
            r#"{"rollout": {"constraints": {"theta_max_deg": 90}}}"#,
            "constraints.theta_max_deg must be in (0, 90), got 90",
        ),
        (
            r#"{"rollout": {"constraints": {"line_tolerance_m": 0}}}"#,
            "constraints.line_tolerance_m must be in (0, ∞), got 0",
        ),
        (
            r#"{"gains": {"k_mu": -1}}"#,
            "gains.k_mu must be in [0, ∞), got -1",
        ),
        (
            r#"{"gains": {"lead_deg": 90}}"#,
            "gains.lead_deg must be in [0, 90), got 90",
        ),
        (
            r#"{"search": {"classical_gains": {"k_lead": -5}}}"#,
            "search.classical_gains.k_lead must be in [0, ∞), got -5",
        ),
        (
            r#"{"search": {"widened_breadth": 0}}"#,
            "search.widened_breadth must be in [1, 16], got 0",
        ),
        (
            r#"{"search": {"widened_budget_steps": 20000000}}"#,
            "search.widened_budget_steps must be in [0, 10000000], got 20000000",
        ),
        (
            r#"{"search": {"beam_width": 5000}}"#,
            "search.beam_width must be in [0, 4096], got 5000",
        ),
        (
            r#"{"search": {"beam_budget_steps": 20000000}}"#,
            "search.beam_budget_steps must be in [0, 10000000], got 20000000",
        ),
        (
            r#"{"search": {"beam_below_share": 0}}"#,
            "search.beam_below_share must be in (0, 1], got 0",
        ),
        (
            r#"{"search": {"far_end_shares": [0.9, 1.5]}}"#,
            "search.far_end_shares must be in (0, 1], got 1.5",
        ),
        (
            r#"{"search": {"far_end_shares": [0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1]}}"#,
            "search.far_end_shares (how many) must be in [0, 8], got 9",
        ),
        (
            r#"{"measure": {"kind": "all_constraints", "clearance_scale_m": 0}}"#,
            "measure.clearance_scale_m must be in (0, ∞), got 0",
        ),
        (r#"{"switch": {"tau_enter": 0.5, "tau_exit": 0.9}}"#, "tau"),
    ] {
        std::fs::write(&path, json).unwrap();
        let error = PlannerConfig::read(&path).unwrap_err().to_string();
        assert!(error.contains(expected), "{json}: {error}");
    }
    let mut config = PlannerConfig::default();
    config.rollout.dt_s = f64::NAN;
    let error = Planner::new(robot(), Models::default(), config)
        .err()
        .unwrap();
    assert!(error.to_string().contains("rollout.dt_s"), "{error}");
}

#[test]
fn models_trained_for_another_arm_are_refused_naming_both_robots() {
    let fr3 = robot();
    let iiwa = ShippedRobot::by_name("iiwa14").unwrap();
    let models = iiwa.data_dir(&data()).join("models");
    for file in [
        emg_planner::POLICY_WEIGHTS_FILE,
        emg_planner::DIFFUSION_WEIGHTS_FILE,
    ] {
        let path = models.join(file);
        let error = if file == emg_planner::POLICY_WEIGHTS_FILE {
            Models::load(&fr3, None, Some(&path))
        } else {
            Models::load(&fr3, Some(&path), None)
        }
        .err()
        .expect("the iiwa's weights are refused on the FR3");
        let message = error.to_string();
        assert!(
            message.contains("trained for robot 'iiwa14_pen'")
                && message.contains("not for robot 'fr3_pen'"),
            "{message}"
        );
    }
    // A file that records no robot is refused too, and says how to stamp it.
    let dir = tempfile::tempdir().unwrap();
    let unstamped = dir.path().join("policy.weights");
    let weights =
        emg_policy::PolicyWeights::read(&fr3_models().join(emg_planner::POLICY_WEIGHTS_FILE))
            .unwrap();
    let mut header = weights.header().clone();
    header.robot = None;
    emg_policy::PolicyWeights::new(header, weights.values().to_vec())
        .unwrap()
        .write(&unstamped)
        .unwrap();
    let message = Models::load(&fr3, None, Some(&unstamped))
        .err()
        .unwrap()
        .to_string();
    assert!(
        message.contains("records no robot") && message.contains("stamp-weights"),
        "{message}"
    );
}

fn fr3_models() -> std::path::PathBuf {
    fr3().data_dir(&data()).join("models")
}
