//! The search planner on the shipped FR3 models: it evaluates the pipeline's own plan first, so
//! it never returns a shorter one, and it goes further on many tasks, some through the repair
//! stage's detours (recorded as such); every plan passes the independent checker; results do not depend on the thread count; a budget spent by the
//! pipeline's rollout gives exactly the pipeline's plan; with the work surface and an obstacle on
//! the way, every plan still passes the checker told of them; a plan short of its bound is
//! searched wider and goes further, one near its bound is left as it is; the far-end stage finds
//! a motion the search from `p0` misses, and no motion planned back from beyond a plan's end
//! passes `p0`; the beam stage goes on where the widened search still ends short.

use emg_control::{ActingController, CheckRollout, Task};
use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_planner::{
    CHAIN_SOURCE, DataDir, FAR_END_SOURCE, GapProbeOutcome, InPlaceConfig, Models, Plan,
    PlanRequest, Planner, PlannerConfig, PlannerKind, SHORTFALL_SHARE, SearchConfig, ShippedRobot,
    gap_probes,
};
use emg_verify::ReferenceModel;

fn data() -> DataDir {
    DataDir::new(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data"))
}

fn fr3() -> ShippedRobot {
    ShippedRobot::by_name("fr3").expect("the FR3 ships")
}

fn planner(config: PlannerConfig) -> Planner {
    let robot = Robot::from_chain_file(fr3().path(&data())).expect("robot loads");
    let models = Models::shipped(&robot, &fr3().data_dir(&data())).expect("shipped models");
    Planner::new(robot, models, config).expect("valid config")
}

/// A small search, so that the test stays short.
fn small_search() -> PlannerConfig {
    PlannerConfig {
        search: SearchConfig {
            budget_steps: 3_000,
            dp_samples: 8,
            ik_restarts: 16,
            finalists: 2,
            widened_budget_steps: 3_000,
            ..SearchConfig::default()
        },
        ..PlannerConfig::default()
    }
}

fn checker(robot: &Robot) -> ReferenceModel {
    ReferenceModel::from_urdf_file(&fr3().path(&data()), robot.base_link(), robot.tip_link())
        .expect("checker")
}

fn tasks(robot: &Robot, count: usize) -> Vec<Task> {
    let mut tasks = read_tasks(&fr3().data_dir(&data()).join("tasks/eval-v1.tasks"), robot)
        .expect("shipped tasks");
    tasks.truncate(count);
    tasks
}

fn search_request() -> PlanRequest {
    PlanRequest {
        planner: PlannerKind::Search,
        ..PlanRequest::pipeline()
    }
}

#[test]
fn search_never_returns_less_and_often_more() {
    let planner = planner(small_search());
    let robot = planner.robot();
    let checker = checker(robot);
    let constraints = &planner.config().rollout.constraints;
    let (mut pipeline_total, mut search_total, mut longer, mut detoured) = (0.0, 0.0, 0, 0);
    for task in tasks(robot, 10) {
        let pipeline = planner
            .plan(&task, &PlanRequest::pipeline())
            .expect("plans");
        let searched = planner.plan(&task, &search_request()).expect("searches");
        checker
            .check(&task, &searched.trajectory, constraints)
            .expect("every searched plan holds every constraint");
        let (a, b) = (
            pipeline.trajectory.path_length_m,
            searched.trajectory.path_length_m,
        );
        assert!(b >= a, "the search returns {b} m, the pipeline {a} m");
        if b > a + 0.01 {
            longer += 1;
        }
        pipeline_total += a;
        search_total += b;
        let detours = searched
            .trajectory
            .steps
            .iter()
            .filter(|s| s.controller == Some(ActingController::Search))
            .count();
        detoured += usize::from(detours > 0);
    }
    assert!(
        detoured > 0,
        "no searched plan kept a detour of the repair stage"
    );
    assert!(
        longer >= 3,
        "the search goes further on only {longer} of 10 tasks ({search_total} m against \
         {pipeline_total} m)"
    );
}

#[test]
fn long_lines_are_planned_along_the_scans_chains() {
    // The first tasks of the evaluation set whose bound is at least 1 m.
    let planner = planner(small_search());
    let robot = planner.robot();
    let checker = checker(robot);
    let constraints = &planner.config().rollout.constraints;
    let mut followed = 0;
    for task in tasks(robot, 40) {
        if planner.reach(&task, &[]).scanned_m < 1.0 {
            continue;
        }
        let searched = planner.plan(&task, &search_request()).expect("searches");
        checker
            .check(&task, &searched.trajectory, constraints)
            .expect("every searched plan holds every constraint");
        followed += usize::from(searched.seed.source == CHAIN_SOURCE);
    }
    assert!(followed > 0, "no long line was planned along a chain");
}

#[test]
fn a_spent_budget_gives_the_pipeline_plan() {
    let mut config = small_search();
    config.search.budget_steps = 1;
    config.search.widened_budget_steps = 0;
    config.search.far_end_shares.clear();
    config.search.beam_width = 0;
    let planner = planner(config);
    for task in tasks(planner.robot(), 4) {
        let searched = planner.plan(&task, &search_request()).expect("searches");
        let pipeline = planner
            .plan(&task, &PlanRequest::pipeline())
            .expect("plans");
        assert_eq!(
            (searched.seed, searched.trajectory),
            (pipeline.seed, pipeline.trajectory)
        );
    }
}

#[test]
fn search_does_not_depend_on_the_thread_count() {
    let planner = planner(small_search());
    let tasks = tasks(planner.robot(), 6);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| planner.plan_many(&tasks, &search_request()))
    };
    let one: Vec<_> = on(1).into_iter().map(|p| p.expect("searches")).collect();
    let two: Vec<_> = on(2).into_iter().map(|p| p.expect("searches")).collect();
    assert_eq!(one, two);
}

#[test]
fn search_holds_the_work_surface_and_the_scene() {
    let mut config = small_search();
    config.rollout.constraints.work_surface = emg_kinematics::WorkSurface::plate();
    let free = planner(small_search());
    let robot = free.robot();
    let checker = checker(robot);
    let (mut scene_ends, mut moved) = (0, 0);
    for (index, task) in tasks(robot, 12).into_iter().enumerate() {
        // A ball where the unconstrained search's pen tip is a third of the way along.
        let unconstrained = free.plan(&task, &search_request()).expect("searches");
        let steps = &unconstrained.trajectory.steps;
        let mut constrained = config.clone();
        constrained.rollout.constraints.scene = serde_json::from_value(serde_json::json!({
            "obstacles": [{"name": "ball", "clearance_m": 0.005,
                           "sphere": {"centre": steps[steps.len() / 3].tcp, "radius": 0.01}}]
        }))
        .expect("a valid scene");
        let planner = planner(constrained);
        let searched = planner.plan(&task, &search_request()).expect("searches");
        let constraints = &planner.config().rollout.constraints;
        checker
            .check(&task, &searched.trajectory, constraints)
            .unwrap_or_else(|e| panic!("task {index}: {e}"));
        let termination = searched.trajectory.termination.to_string();
        scene_ends += usize::from(termination.contains("ball") || termination.contains("surface"));
        moved += usize::from(searched.trajectory.path_length_m > 0.05);
    }
    assert!(
        scene_ends > 0 && moved > 3,
        "{scene_ends} plans end on the scene, {moved} move"
    );
}

/// The first 1,000 shipped FR3 tasks' `indices`, each planned by the search of `first` and then
/// of `second` (whose plan the checker must pass): both plans and the task's bound.
fn planned_twice(
    first: PlannerConfig,
    second: PlannerConfig,
    indices: &[usize],
) -> Vec<(usize, Plan, Plan, f64)> {
    let (first, second) = (planner(first), planner(second));
    let robot = second.robot();
    let checker = checker(robot);
    let constraints = &second.config().rollout.constraints;
    let tasks = tasks(robot, 1000);
    indices
        .iter()
        .map(|&index| {
            let task = &tasks[index];
            let a = first.plan(task, &search_request()).expect("searches");
            let b = second.plan(task, &search_request()).expect("searches");
            checker
                .check(task, &b.trajectory, constraints)
                .expect("every plan holds every constraint");
            let bound = a.reach.as_ref().expect("the search scans").reachable_m;
            eprintln!(
                "task {index}: {:.3} m → {:.3} m of {bound:.3} m",
                a.trajectory.path_length_m, b.trajectory.path_length_m
            );
            (index, a, b, bound)
        })
        .collect()
}

/// Plans evaluation task 0 and task `short` with `without` a stage of the search and `with`
/// it: task 0 is planned near its bound by both, alike (a plan near its bound runs no stage
/// for short plans); task `short` ends below [`SHORTFALL_SHARE`] × its bound without the stage
/// and reaches that far with it. Returns task `short`'s plans without and with the stage, and
/// its bound.
fn a_stage_reaches_the_bound(
    without: PlannerConfig,
    with: PlannerConfig,
    short: usize,
) -> (Plan, Plan, f64) {
    let mut planned = planned_twice(without, with, &[0, short]);
    let (_, first, second, bound) = planned.swap_remove(1);
    let (_, near_first, near_second, near_bound) = planned.swap_remove(0);
    let near = near_first.trajectory.path_length_m;
    assert!(
        near >= SHORTFALL_SHARE * near_bound,
        "task 0 is planned near its bound"
    );
    assert_eq!(
        near_first, near_second,
        "task 0: the stage runs only where a plan ends short"
    );
    let (a, b) = (
        first.trajectory.path_length_m,
        second.trajectory.path_length_m,
    );
    assert!(
        a < SHORTFALL_SHARE * bound,
        "task {short}: {a} m of {bound} m without the stage"
    );
    assert!(
        b >= SHORTFALL_SHARE * bound,
        "task {short}: {b} m of {bound} m with the stage"
    );
    (first, second, bound)
}

#[test]
fn the_far_end_stage_finds_the_motion_the_search_from_p0_misses() {
    // Evaluation task 7: a line whose bound is 1.11 m, where the search from `p0` (its widened
    // pass included) ends at 0.23 m. The beam is left out of both, so that the far-end stage
    // alone makes the difference.
    let mut without = PlannerConfig::default();
    without.search.far_end_shares.clear();
    without.search.beam_width = 0;
    let mut with = PlannerConfig::default();
    with.search.beam_width = 0;
    let (first, second, bound) = a_stage_reaches_the_bound(without, with, 7);
    assert!(first.trajectory.path_length_m < 0.5 * bound);
    assert_eq!(second.seed.source, FAR_END_SOURCE);
}

#[test]
fn the_beam_stage_goes_on_where_the_search_ends_short() {
    // Evaluation task 593: a line whose bound is 1.28 m, where the default search (its widened
    // pass included, no far end) ends at 0.47 m.
    let mut without = PlannerConfig::default();
    without.search.far_end_shares.clear();
    without.search.beam_width = 0;
    let mut with = without.clone();
    with.search.beam_width = 64;
    with.search.beam_budget_steps = 100_000;
    let (_, second, _) = a_stage_reaches_the_bound(without, with, 593);
    assert!(
        second
            .trajectory
            .steps
            .iter()
            .any(|s| s.controller == Some(ActingController::Search)),
        "the beam's steps are recorded as the search's"
    );
}

#[test]
fn a_plan_short_of_its_bound_is_searched_wider() {
    // Evaluation tasks 137 and 868: lines whose bound is about 1.6–1.7 m, where the first pass
    // of the default search ends below a third of it; and task 0, which it plans to its bound.
    let wide = PlannerConfig {
        search: SearchConfig {
            dp_samples: 8,
            far_end_shares: Vec::new(),
            beam_width: 0,
            ..SearchConfig::default()
        },
        ..PlannerConfig::default()
    };
    let mut narrow = wide.clone();
    narrow.search.widened_budget_steps = 0;
    let mut widened = 0;
    for (index, first, second, bound) in planned_twice(narrow, wide, &[0, 137, 868]) {
        let (a, b) = (
            first.trajectory.path_length_m,
            second.trajectory.path_length_m,
        );
        if a >= SHORTFALL_SHARE * bound {
            assert_eq!(
                first, second,
                "task {index}: a plan near its bound is not widened"
            );
        } else {
            assert!(b >= a, "task {index}: widened {b} m, first pass {a} m");
            widened += usize::from(b >= SHORTFALL_SHARE * bound);
        }
    }
    assert!(
        widened > 0,
        "no short plan reached 0.9 × its bound when widened"
    );
}

#[test]
fn no_motion_planned_back_from_beyond_the_plan_passes_p0() {
    // Evaluation task 221 as gap-eval plans it (the corrected step at 0.5 mm, no surface):
    // the search from `p0` used to end at 0.239 m of a 1.13 m bound, while the motion the
    // planner plans back from 3 grid steps past that end passes `p0`. The far-end stage now
    // asks the line from the same points and takes such a motion read forwards.
    let mut config = PlannerConfig::default();
    config.rollout.constraints.line_tolerance_m = 0.5e-3;
    config.rollout.tracking = emg_control::Tracking::Corrected;
    let planner = planner(config);
    let task = tasks(planner.robot(), 222).swap_remove(221);
    let plan = planner.plan(&task, &PlanRequest::default()).expect("plans");
    let reached = plan.trajectory.path_length_m;
    assert!(reached > 0.269, "{reached} m");
    let probes = gap_probes(
        &planner,
        &task,
        &plan,
        &InPlaceConfig {
            samples: 200,
            ..InPlaceConfig::default()
        },
    );
    assert!(!probes.is_empty());
    for probe in &probes {
        assert_ne!(
            probe.outcome,
            GapProbeOutcome::PassesP0,
            "from {} m back to {} m, the plan {reached} m",
            probe.from_m,
            probe.back_to_m
        );
    }
    checker(planner.robot())
        .check(
            &task,
            &plan.trajectory,
            &planner.config().rollout.constraints,
        )
        .expect("the plan passes the checker");
}
