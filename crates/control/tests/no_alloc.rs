//! The control step allocates nothing: building a step's context, choosing the classical action,
//! integrating the joint velocity and checking every constraint run with zero heap allocations
//! (counted by a global allocator wrapper, per thread: the test harness's own threads may
//! allocate meanwhile); nor does an episode's step when it corrects its end onto the line
//! (`Tracking::Corrected` at 0.1 mm).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use emg_control::{
    ClassicalController, Episode, NullAction, NullSpaceController, RolloutConfig, SamplerConfig,
    StepContext, Tracking, candidate, first_violation,
};
use emg_kinematics::Robot;

struct CountingAllocator;

thread_local! {
    /// Heap allocations made by the current thread.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // `try_with`: the thread's counter may already be gone while the thread exits.
        let _ = ALLOCATIONS.try_with(|count| count.set(count.get() + 1));
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn classical_control_step_and_constraint_check_do_not_allocate() {
    let robot = Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").expect("robot loads");
    let config = RolloutConfig::default();
    let tasks: Vec<_> = (0..40)
        .filter_map(|i| candidate(&robot, &SamplerConfig::default(), i))
        .collect();
    assert!(tasks.len() > 20);
    let counted = allocations();
    std::hint::black_box(Box::new(1_u64));
    assert_eq!(
        allocations(),
        counted + 1,
        "the counter sees this thread's allocations"
    );
    let mut controller = ClassicalController::default();
    let mut steps = 0;
    for task in &tasks {
        let mut q = task.q0_seed.expect("sampled tasks keep their seed");
        let before = allocations();
        for step in 0..20 {
            let kinematics = robot.forward(&q);
            let context =
                StepContext::new(&robot, task, &config, step, kinematics, NullAction::zeros());
            let (action, _) = controller.act(&context);
            let next = q + context.joint_velocity(&action) * config.dt_s;
            let next_kinematics = robot.forward(&next);
            steps += 1;
            if first_violation(&robot, task, &next_kinematics, &config.constraints).is_some() {
                break;
            }
            q = next;
        }
        assert_eq!(allocations(), before, "the control step allocated");
    }
    assert!(steps > 200, "only {steps} steps exercised");
}

#[test]
fn the_corrected_step_does_not_allocate() {
    let robot = Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").expect("robot loads");
    let mut config = RolloutConfig {
        tracking: Tracking::Corrected,
        ..RolloutConfig::default()
    };
    config.constraints.line_tolerance_m = 1e-4;
    let paper = RolloutConfig {
        tracking: Tracking::FirstOrder,
        ..config.clone()
    };
    let tasks: Vec<_> = (0..20)
        .filter_map(|i| candidate(&robot, &SamplerConfig::default(), i))
        .collect();
    let (mut steps, mut longer) = (0, 0);
    for task in &tasks {
        let seed = task.q0_seed.expect("sampled tasks keep their seed");
        // The episode reserves its record when it starts; its steps allocate nothing.
        let mut episode = Episode::start(&robot, task, &seed, &config);
        let mut controller = ClassicalController::default();
        let before = allocations();
        while let Some(context) = episode.context() {
            let (action, acting) = controller.act(context);
            episode.apply(&action, acting);
            steps += 1;
        }
        assert_eq!(allocations(), before, "the corrected step allocated");
        let corrected = episode.finish();
        let mut controller = ClassicalController::default();
        let first_order = emg_control::rollout(&robot, task, &seed, &mut controller, &paper);
        longer += usize::from(corrected.path_length_m > first_order.path_length_m);
    }
    assert!(steps > 200, "only {steps} steps exercised");
    assert!(
        longer * 2 > tasks.len(),
        "the corrections engaged on {longer} tasks"
    );
}

/// The workspace's shipped data directory.
fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

/// The shipped FR3 robot file.
fn fr3_path() -> std::path::PathBuf {
    data_dir().join("robots/fr3_pen.urdf")
}
