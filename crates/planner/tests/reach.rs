//! The reachability bound: every witness it gives is checked by the independent checker (TCP on
//! the line within the tolerance at its grid point, tool axis inside the cone, joints inside the
//! limits, no self-collision); no plan goes further than the bound (it is a necessary
//! condition); a start out of the arm's reach has none; the bound does not depend on the number
//! of threads that try a point's restarts.

use emg_control::Task;
use emg_io::read_tasks;
use emg_kinematics::{Robot, Vec3};
use emg_planner::{
    CONTINUITY_RESTARTS, ControllerKind, DataDir, FAR_END_SHARE, Models, PlanRequest, Planner,
    PlannerConfig, Reach, SHORTFALL_SHARE, SeedSource, ShippedRobot, far_end_chains,
    witness_chains,
};
use emg_verify::ReferenceModel;

fn data() -> DataDir {
    DataDir::new(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data"))
}

fn fr3() -> ShippedRobot {
    ShippedRobot::by_name("fr3").expect("the FR3 ships")
}

fn planner() -> Planner {
    let robot = Robot::from_chain_file(fr3().path(&data())).expect("robot loads");
    let models = Models::load(&robot, None, None).expect("no models");
    Planner::new(robot, models, PlannerConfig::default()).expect("default config")
}

fn checker(robot: &Robot) -> ReferenceModel {
    ReferenceModel::from_urdf_file(&fr3().path(&data()), robot.base_link(), robot.tip_link())
        .expect("checker loads")
}

/// The FR3's shipped evaluation tasks.
fn eval_tasks(robot: &Robot) -> Vec<Task> {
    read_tasks(&fr3().data_dir(&data()).join("tasks/eval-v1.tasks"), robot).expect("shipped tasks")
}

/// The classical controller from the task's generating configuration (no models needed).
fn classical_from_generating() -> PlanRequest {
    PlanRequest {
        seed: Some(SeedSource::Generating),
        controller: ControllerKind::Classical,
        ..PlanRequest::pipeline()
    }
}

/// Checks every witness of `reach` for `task` with the independent checker.
fn check_witnesses(planner: &Planner, checker: &ReferenceModel, task: &Task, reach: &Reach) {
    let constraints = &planner.config().rollout.constraints;
    let limits = checker.limits();
    assert_eq!(
        reach.witnesses.len() as f64,
        (reach.scanned_m / reach.grid_m).round() + f64::from(u8::from(reach.reachable_p0)),
        "one witness per grid point"
    );
    for (k, q) in reach.witnesses.iter().enumerate() {
        let (tcp, axis) = checker.tcp_pose(q);
        let offset = tcp - task.p0;
        let along = offset.dot(&task.d);
        let across = (offset - task.d * along).norm();
        assert!(
            (along - k as f64 * reach.grid_m).abs() < 1e-3,
            "witness {k} lies at s = {along}, not on its grid point"
        );
        assert!(
            across <= constraints.line_tolerance_m,
            "witness {k}: {across} m off the line"
        );
        let angle = libm::acos(axis.dot(&task.n).clamp(-1.0, 1.0)).to_degrees();
        assert!(
            angle <= constraints.theta_max_deg + 1e-9,
            "witness {k}: tool {angle}° from n"
        );
        for (j, (lower, upper)) in limits.iter().enumerate() {
            assert!(
                (*lower..=*upper).contains(&q[j]),
                "witness {k}: joint {j} outside its limits"
            );
        }
        let (clearance, a, b) = checker.min_clearance(q);
        assert!(
            clearance >= constraints.collision_margin_m,
            "witness {k}: {a} and {b} collide"
        );
    }
}

#[test]
fn no_plan_goes_beyond_the_bound_and_every_witness_holds() {
    let planner = planner();
    let robot = planner.robot();
    let checker = checker(robot);
    let tasks = eval_tasks(robot);
    let request = classical_from_generating();
    let mut beyond_plan = 0;
    for task in &tasks[..8] {
        let plan = planner.plan(task, &request).expect("plans");
        let reach = planner.reach(task, &[plan.seed.q]);
        assert!(reach.reachable_p0, "p0 of a sampled task is reachable");
        check_witnesses(&planner, &checker, task, &reach);
        let length = plan.trajectory.path_length_m;
        assert!(
            length <= reach.reachable_m + reach.grid_m,
            "the plan travels {length} m, beyond the bound {} m",
            reach.reachable_m
        );
        if reach.reachable_m > length + 0.05 {
            beyond_plan += 1;
        }
    }
    // The bound is informative: on some tasks the arm could be placed well past where the
    // classical controller stops.
    assert!(beyond_plan > 0, "the bound never exceeds the plan");
}

#[test]
fn the_bound_of_a_search_never_reads_below_its_plan_and_its_chains_hold() {
    let planner = planner();
    let robot = planner.robot();
    let checker = checker(robot);
    let tasks = eval_tasks(robot);
    let request = PlanRequest {
        planner: emg_planner::PlannerKind::Search,
        controller: ControllerKind::Classical,
        ..PlanRequest::pipeline()
    };
    let constraints = &planner.config().rollout.constraints;
    let mut joined_tasks = 0;
    for task in &tasks[..6] {
        let plan = planner.plan(task, &request).expect("searches");
        let reach = plan.reach.clone().expect("the search scans the bound");
        assert_eq!(
            planner.reach_of(task, &plan),
            reach,
            "the plan's own bound is reused"
        );
        let length = plan.trajectory.path_length_m;
        assert!(
            reach.reachable_m >= length,
            "bound {reach:?} below the plan {length} m"
        );
        assert!(reach.reachable_m >= reach.scanned_m);
        // Every chain the search may follow is a chain of valid configurations from `p0`, one
        // per grid point, on one self-motion branch.
        let jump = planner.config().search.chain_jump_rad;
        let chains = witness_chains(
            robot,
            task,
            constraints,
            &planner.config().reach,
            &reach,
            jump,
        );
        assert!(!chains.is_empty(), "the scan's first chain starts at p0");
        // The chains joined back from near the far end likewise, each ending at its grid
        // point at FAR_END_SHARE of the scan.
        let far = ((reach.witnesses.len() - 1) as f64 * FAR_END_SHARE) as usize;
        let joined = far_end_chains(
            robot,
            task,
            constraints,
            &planner.config().reach,
            &reach,
            jump,
            16,
        );
        joined_tasks += usize::from(!joined.is_empty());
        for chain in &joined {
            assert_eq!(chain.len(), far + 1);
        }
        for chain in chains.iter().chain(&joined) {
            let grid: Vec<_> = chain.to_vec();
            let as_scan = Reach {
                reachable_m: (grid.len() - 1) as f64 * reach.grid_m,
                scanned_m: (grid.len() - 1) as f64 * reach.grid_m,
                witnesses: grid,
                ..reach.clone()
            };
            check_witnesses(&planner, &checker, task, &as_scan);
            for pair in chain.windows(2) {
                assert!((pair[1] - pair[0]).amax() <= jump, "a chain jumps branches");
            }
        }
    }
    assert!(joined_tasks > 0, "no chain joined back to p0 on any task");
}

#[test]
fn a_plan_short_of_its_bound_says_whether_the_bound_joins_p0() {
    let planner = planner();
    let robot = planner.robot();
    let tasks = eval_tasks(robot);
    // The classical controller from the generating configuration stops short on many tasks.
    let request = classical_from_generating();
    let config = planner.config();
    let mut short = 0;
    for task in &tasks[..12] {
        let plan = planner.plan(task, &request).expect("plans");
        let note = planner.bound_note(task, &plan);
        let reach = planner.reach_of(task, &plan);
        assert_eq!(note.reachable_m, reach.reachable_m);
        let length = plan.trajectory.path_length_m;
        if length >= SHORTFALL_SHARE * reach.reachable_m {
            assert_eq!(note.shortfall, None, "{length} m of {}", reach.reachable_m);
            assert!(!note.likely_loose);
            continue;
        }
        short += 1;
        let joined = !far_end_chains(
            robot,
            task,
            &config.rollout.constraints,
            &config.reach,
            &reach,
            config.search.chain_jump_rad,
            CONTINUITY_RESTARTS,
        )
        .is_empty();
        assert_eq!(note.likely_loose, !joined);
        let text = note.shortfall.expect("a short plan says so");
        assert!(text.contains(&format!("ends at {length:.2} m")), "{text}");
        assert!(
            text.contains(&plan.trajectory.termination.to_string()),
            "{text}"
        );
        let says = if joined {
            "a longer motion may exist"
        } else {
            "the bound is likely loose here"
        };
        assert!(text.contains(says), "{text}");
    }
    assert!(short > 0, "no plan ended short of its bound");
}

#[test]
fn a_start_out_of_reach_has_no_bound() {
    let planner = planner();
    let task = Task::new(
        planner.robot(),
        // Inside the sphere the links could span (so the task is valid) but past the arm's
        // real reach.
        Vec3::new(1.15, 0.0, 0.333),
        Vec3::y(),
        -Vec3::z(),
        None,
    )
    .expect("a valid task");
    let reach = planner.reach(&task, &[]);
    assert!(!reach.reachable_p0 && reach.reachable_m == 0.0 && reach.witnesses.is_empty());
}

#[test]
fn the_bound_does_not_depend_on_the_thread_count() {
    let planner = planner();
    let tasks = read_tasks(
        &fr3().data_dir(&data()).join("tasks/eval-v1.tasks"),
        planner.robot(),
    )
    .expect("shipped tasks");
    let scan = |threads: usize| -> Vec<Reach> {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
            .install(|| {
                tasks[..4]
                    .iter()
                    .map(|task| planner.reach(task, &[]))
                    .collect()
            })
    };
    let one = scan(1);
    // A scan tries its last point, where every restart fails, in parallel.
    assert!(one.iter().all(|reach| reach.reachable_p0));
    assert_eq!(one, scan(3));
}

/// How many of the configurations the scan's IK finds at `task`'s start hold every constraint
/// of `planner` ([`Planner::start_blockers`]: the same seeded IK solutions whatever the plate).
fn valid_starts(planner: &Planner, task: &Task) -> usize {
    let blockers = planner.start_blockers(task);
    blockers.found - blockers.contacts.iter().map(|c| c.count).sum::<usize>()
}

/// The default plate is a part: on lines heading every way from points around the FR3 (eight
/// headings and the one straight at its base) and on the path population, no task is refused
/// at its start over the default plate unless it is over a plate of exactly its own extent too
/// (no margins: a line's start point, a path's extent).
#[test]
fn the_default_plate_refuses_no_start_that_a_plate_of_the_tasks_own_extent_allows() {
    use emg_kinematics::{Plate, WorkSurface};
    let default = planner()
        .with_config(PlannerConfig::cell())
        .expect("the cell's config");
    let mut own = PlannerConfig::cell();
    own.rollout.constraints.work_surface = WorkSurface::Plate(Plate {
        half_width_m: 0.0,
        behind_m: 0.0,
        ahead_m: 0.0,
        thickness_m: Plate::default().thickness_m,
    });
    let own = default
        .with_config(own)
        .expect("a plate of the task's extent");
    let robot = default.robot();
    let mut tasks = Vec::new();
    for (x, y) in [(0.3, 0.2), (0.3, -0.2), (0.5, 0.0), (0.2, 0.25)] {
        let p0 = Vec3::new(x, y, 0.2);
        let at_base = Vec3::new(-x, -y, 0.0).normalize();
        let headings = (0..8).map(|k| {
            let (sin, cos) = libm::sincos(f64::from(k) * std::f64::consts::FRAC_PI_4);
            Vec3::new(cos, sin, 0.0)
        });
        for d in headings.chain([at_base]) {
            tasks.extend(Task::new(robot, p0, d, -Vec3::z(), None).ok());
        }
    }
    let anchors: Vec<Task> = eval_tasks(robot).into_iter().take(30).collect();
    let paths = emg_control::path_tasks(robot, &anchors, 7).expect("the path population");
    tasks.extend(paths.into_iter().map(|(_, task)| task));
    let mut refused = 0;
    for (index, task) in tasks.iter().enumerate() {
        let over_default = valid_starts(&default, task);
        let over_own = valid_starts(&own, task);
        if over_default == 0 {
            refused += 1;
            assert_eq!(
                over_own,
                0,
                "task {index} ({:?} along {:?}) is refused over the default plate alone: {:?}",
                task.p0,
                task.d,
                default.start_blockers(task).contacts
            );
        }
    }
    assert!(
        refused < tasks.len() / 4,
        "{refused} of {} refused",
        tasks.len()
    );
}

/// The bound counts a grid point as reachable when a point of the tolerance disc around it has
/// a valid configuration: on a line whose exact points are blocked over a stretch (a rod of
/// 3 mm radius lying on it, which the whole arm, pen included, keeps clear of), and that a
/// 1 cm lateral offset clears, the bound goes on past the stretch, its witnesses there off the
/// line by more than the rod's radius and within the tolerance; and no plan reads above it.
#[test]
fn the_bound_reaches_past_a_stretch_only_the_tolerance_disc_clears() {
    use emg_kinematics::{Obstacle, Shape};
    let task_line = |robot: &Robot| {
        Task::new(
            robot,
            Vec3::new(0.45, -0.2, 0.25),
            Vec3::y(),
            -Vec3::z(),
            None,
        )
        .expect("the README's line")
    };
    let (from_m, to_m, radius_m) = (0.25, 0.35, 0.003);
    let mut config = PlannerConfig::default();
    let rod = {
        let robot = planner();
        let task = task_line(robot.robot());
        Shape::Capsule {
            start: task.point_at(from_m),
            end: task.point_at(to_m),
            radius: radius_m,
        }
    };
    config.rollout.constraints.scene.obstacles.push(Obstacle {
        name: "rod".to_string(),
        shape: rod.clone(),
        clearance_m: 0.0,
        tool_may_touch: false,
    });
    let planner = planner().with_config(config).expect("a scene with a rod");
    let robot = planner.robot();
    let task = task_line(robot);
    let reach = planner.reach(&task, &[]);
    assert!(
        reach.reachable_m > to_m + 0.1,
        "the bound stops at the rod: {} m",
        reach.reachable_m
    );
    let tolerance = planner.config().rollout.constraints.line_tolerance_m;
    for (k, q) in reach.witnesses.iter().enumerate() {
        let s = k as f64 * reach.grid_m;
        let tcp = robot.forward(q).tcp();
        let off_line = task.lateral_error(&tcp).norm();
        assert!(
            off_line <= tolerance,
            "witness {k} is {off_line} m off the line"
        );
        if (from_m..=to_m).contains(&s) {
            assert!(
                off_line > radius_m,
                "witness {k} at {s} m stands on the rod"
            );
        }
    }
    let request = PlanRequest {
        planner: emg_planner::PlannerKind::Search,
        seed: Some(SeedSource::Home),
        controller: ControllerKind::Classical,
    };
    let plan = planner.plan(&task, &request).expect("the search plans");
    assert!(plan.reach.expect("the search's bound").reachable_m >= plan.trajectory.path_length_m);
}
