//! The published search results are what the planner gives now: on the first tasks of every
//! shipped robot's `search.json` (`docs/results/` for the FR3, `docs/results/<robot>/` for the
//! others), the paper's pipeline and the search at every published budget plan the published
//! path lengths. A change of the control step, the models, the seeding or the
//! search that changes any plan fails here, and the results have to be regenerated with
//! `cargo xtask search-eval` (and `cargo xtask eval`, `cargo xtask limit`, which plan with the
//! same code).

use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_planner::{
    DataDir, Models, PlanRequest, Planner, PlannerConfig, PlannerKind, SHIPPED_ROBOTS,
    SearchConfig, ShippedRobot,
};
use serde_json::Value;

/// Tasks re-planned per published row: enough to cover short and long plans, few enough for a
/// debug build.
const TASKS: usize = 6;

/// The published lengths are decimal JSON numbers; parsing them back may cost the last bit.
const TOLERANCE_M: f64 = 1e-12;

fn workspace() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn the_published_search_lengths_are_planned_again() {
    for shipped in SHIPPED_ROBOTS {
        plan_the_published_lengths(shipped);
    }
}

fn plan_the_published_lengths(shipped: ShippedRobot) {
    let path = workspace()
        .join("docs/results")
        .join(shipped.data_subdir())
        .join("search.json");
    let published: Value = serde_json::from_str(
        &std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    )
    .expect("search.json parses");
    let data = DataDir::new(workspace().join("data"));
    let robot = Robot::from_chain_file(shipped.path(&data)).expect("robot loads");
    assert_eq!(
        published["robot"].as_str(),
        Some(robot.name()),
        "{} is {}'s evaluation",
        path.display(),
        shipped.name
    );
    let task_file = workspace().join(published["tasks"].as_str().expect("tasks is a path"));
    let tasks = read_tasks(&task_file, &robot).expect("the published task set loads");
    let search: SearchConfig =
        serde_json::from_value(published["search"].clone()).expect("search settings");
    let models = Models::shipped(&robot, &shipped.data_dir(&data)).expect("shipped models");
    let planner = Planner::new(robot, models, PlannerConfig::default()).expect("valid config");

    let rows = published["rows"].as_array().expect("rows");
    assert!(rows.len() >= 2, "a pipeline row and at least one budget");
    for row in rows {
        let (request, config) = match row["budget_steps"].as_u64() {
            None => (PlanRequest::pipeline(), PlannerConfig::default()),
            Some(budget_steps) => (
                PlanRequest {
                    planner: PlannerKind::Search,
                    ..PlanRequest::pipeline()
                },
                PlannerConfig {
                    search: SearchConfig {
                        budget_steps,
                        ..search.clone()
                    },
                    ..PlannerConfig::default()
                },
            ),
        };
        let planner = planner.with_config(config).expect("valid config");
        let lengths = row["lengths_m"].as_array().expect("per-task lengths");
        for (index, (task, length)) in tasks.iter().zip(lengths).take(TASKS).enumerate() {
            let length = length.as_f64().expect("a length");
            let planned = planner
                .plan(task, &request)
                .expect("plans")
                .trajectory
                .path_length_m;
            assert!(
                (planned - length).abs() <= TOLERANCE_M,
                "{}: {} (budget {}), task {index}: planned {planned} m, published {length} m; \
                 regenerate the results (cargo xtask search-eval --robot {})",
                shipped.name,
                row["planner"],
                row["budget_steps"],
                shipped.name
            );
        }
    }
}
