//! The viewer pages in a real browser: headless Chromium draws a planned FR3 motion and a job's
//! program, and the screenshot, the page's render status, its read-out and the browser console
//! are checked (the helpers are in `support/`).
//!
//! The browser is `$EMG_CHROMIUM`, else `chromium` or `chromium-browser` on `PATH`. The tests
//! that need it are ignored (with that reason) unless run with `cargo test -- --include-ignored`,
//! as `.ci/run` does after installing Chromium; so run, without one they print a notice and
//! pass, unless `EMG_REQUIRE_BROWSER=1` (as in CI), where they fail.

mod support;

use emg_control::{
    ActingController, ClassicalController, RolloutConfig, Task, Trajectory, rollout,
};
use emg_kinematics::{Robot, Vec3};
use emg_viewer::{ViewerInput, render_html};

use support::browser::{
    body_data, browser, dump_dom, page_problems, scrub_and_record, with_extra_script,
};
use support::job::{fr3_path, synthetic_job};
use support::screenshot::{blank_screenshot_problem, pixels_of, screenshot, script_colour};

/// A fresh directory under the system temp dir, removed when dropped.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("emg-viewer-{name}-"))
        .tempdir()
        .expect("create temp dir")
}

/// A classical rollout of at most `max_steps` steps of a line along +y from the mid-range
/// configuration, and its page.
fn page_of(max_steps: usize, title: &str) -> (Trajectory, String) {
    let config = RolloutConfig {
        max_steps,
        ..RolloutConfig::default()
    };
    page_with(&config, title)
}

/// The classical rollout of [`page_of`]'s line under `config`, and its page.
fn page_with(config: &RolloutConfig, title: &str) -> (Trajectory, String) {
    let robot =
        Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").expect("the FR3 robot file loads");
    let seed = robot.mid_range();
    let kin = robot.forward(&seed);
    let task =
        Task::new(&robot, kin.tcp(), Vec3::y(), kin.tool_axis(), Some(seed)).expect("a valid task");
    let trajectory = rollout(
        &robot,
        &task,
        &seed,
        &mut ClassicalController::default(),
        config,
    );
    let page = render_html(&ViewerInput {
        robot: &robot,
        task: &task,
        trajectory: &trajectory,
        constraints: &config.constraints,
        title,
    });
    (trajectory, page)
}

/// The full classical rollout of [`page_of`] and its page.
fn planned_page() -> (Trajectory, String) {
    page_of(
        RolloutConfig::default().max_steps,
        "FR3 line along +y (classical)",
    )
}

#[test]
fn the_planned_motion_has_many_steps() {
    let (trajectory, page) = planned_page();
    assert!(
        trajectory.steps.len() >= 40,
        "only {} steps: the browser test needs a longer motion",
        trajectory.steps.len()
    );
    assert_eq!(
        page.matches(r#""controller":"classical""#).count(),
        trajectory
            .steps
            .iter()
            .filter(|s| s.controller.is_some())
            .count()
    );
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn screenshot_shows_the_arm() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("screenshot");
    let dir = tmp.path();
    let (_, page) = planned_page();
    let (width, height, pixels) = screenshot(&browser, dir, &page);
    assert_eq!((width, height), (1000, 700), "screenshot size");
    if let Some(problem) = blank_screenshot_problem(&pixels) {
        panic!(
            "the viewer screenshot looks blank: {problem} (page and screenshot in {})",
            dir.display()
        );
    }
}

/// The planned motion's page with the work surface on and one obstacle of each kind beside the
/// arm.
fn cell_page() -> (Trajectory, String) {
    let scene = r#"{"obstacles": [
        {"name": "floor", "half_space": {"point": [0, 0, -0.1], "normal": [0, 0, 1]}},
        {"name": "fixture", "box": {"centre": [0.2, -0.45, 0.2], "size": [0.2, 0.1, 0.3],
                                    "rpy": [0, 0, 0.4]}},
        {"name": "post", "capsule": {"start": [-0.3, 0.4, 0], "end": [-0.3, 0.4, 0.6],
                                     "radius": 0.05}},
        {"name": "ball", "sphere": {"centre": [-0.3, -0.4, 0.5], "radius": 0.08}}
    ]}"#;
    let mut config = RolloutConfig::default();
    config.constraints.work_surface = emg_kinematics::WorkSurface::HalfSpace;
    config.constraints.scene = serde_json::from_str(scene).expect("a valid scene");
    page_with(&config, "FR3 line in a cell")
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn the_cell_is_drawn() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("cell");
    let dir = tmp.path();
    let (trajectory, page) = cell_page();
    assert!(trajectory.steps.len() > 1, "{}", trajectory.termination);
    for name in ["floor", "fixture", "post", "ball"] {
        assert!(
            page.contains(&format!(r#""name":"{name}""#)),
            "{name} missing"
        );
    }
    assert!(page.contains(r#""work_surface":true"#));
    let run = dump_dom(&browser, dir, &page);
    if let Err(problems) = page_problems(&run) {
        panic!("the cell page did not run cleanly:\n{problems}");
    }
    let (_, _, with_cell) = screenshot(&browser, dir, &page);
    let (_, plain) = planned_page();
    let (_, _, without) = screenshot(&browser, dir, &plain);
    let changed = with_cell
        .iter()
        .zip(&without)
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        changed > 20_000,
        "only {changed} pixels show the cell (page in {})",
        dir.display()
    );
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn screenshot_check_fails_when_the_page_draws_nothing() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("screenshot-blank");
    let dir = tmp.path();
    // Without steps the script stops before drawing anything.
    let (_, page) = planned_page();
    let broken = without_steps(&page);
    assert_ne!(broken, page, "the data blob holds the steps");
    let (_, _, pixels) = screenshot(&browser, dir, &broken);
    assert!(
        blank_screenshot_problem(&pixels).is_some(),
        "a page that draws nothing passed the screenshot check"
    );
}

/// `page` with its motion data emptied of steps (the steps moved to an unused member).
fn without_steps(page: &str) -> String {
    page.replacen(r#""steps":["#, r#""steps":[],"unused":["#, 1)
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn page_reports_rendered_with_a_silent_console() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("dom");
    let dir = tmp.path();
    let (_, page) = planned_page();
    let run = dump_dom(&browser, dir, &page);
    if let Err(problems) = page_problems(&run) {
        panic!("the viewer page did not run cleanly:\n{problems}");
    }
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn status_check_catches_an_error_in_the_viewer_script() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("dom-broken-data");
    let dir = tmp.path();
    let (_, page) = planned_page();
    let broken = without_steps(&page);
    let run = dump_dom(&browser, dir, &broken);
    let problems = page_problems(&run).expect_err("a page whose script throws passed the check");
    assert!(
        problems.contains("error: Uncaught Error: the motion data holds no steps"),
        "the page status names the error: {problems}"
    );
    assert!(
        problems.contains("console:"),
        "the console line is caught too: {problems}"
    );
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn console_check_catches_errors_thrown_after_the_first_frame() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("dom-late-error");
    let dir = tmp.path();
    let (_, page) = planned_page();
    let thrown = with_extra_script(
        &page,
        "setTimeout(() => { throw new Error('deliberate'); }, 100);",
    );
    let problems = page_problems(&dump_dom(&browser, dir, &thrown))
        .expect_err("a page that throws after rendering passed the check");
    assert!(
        problems.contains("error: Uncaught Error: deliberate"),
        "{problems}"
    );
    let rejected = with_extra_script(&page, "Promise.reject(new Error('deliberate rejection'));");
    let problems = page_problems(&dump_dom(&browser, dir, &rejected))
        .expect_err("a page with an unhandled rejection passed the check");
    assert!(
        problems.contains("error: unhandled rejection: deliberate rejection"),
        "{problems}"
    );
    let logged = with_extra_script(&page, "console.error('quiet');");
    let problems = page_problems(&dump_dom(&browser, dir, &logged))
        .expect_err("a page that logs a console error passed the check");
    assert!(problems.contains("\"quiet\""), "{problems}");
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn controls_scrub_orbit_and_zoom_without_errors() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("dom-controls");
    let dir = tmp.path();
    let (trajectory, page) = planned_page();
    // Drive every control, then record what the read-out shows at the end of the motion.
    let exercise = r#"
        const scene = document.getElementById("scene");
        const scrub = document.getElementById("scrub");
        document.getElementById("play").click();
        document.getElementById("speed").value = "4";
        document.getElementById("speed").dispatchEvent(new Event("change"));
        document.getElementById("play").click();
        const at = (type, x, y) => scene.dispatchEvent(new PointerEvent(type, { clientX: x, clientY: y, pointerId: 1, bubbles: true }));
        at("pointerdown", 400, 300);
        at("pointermove", 460, 250);
        at("pointerup", 460, 250);
        scene.dispatchEvent(new WheelEvent("wheel", { deltaY: -240, bubbles: true, cancelable: true }));
        scene.dispatchEvent(new MouseEvent("dblclick", { bubbles: true }));
        document.getElementById("play").click();
        scrub.value = scrub.max;
        scrub.dispatchEvent(new Event("input"));
        scrub.dispatchEvent(new Event("change"));
        // Scrubbing redraws at once: the read-out already shows the end of the motion.
        document.body.dataset.step = document.getElementById("r-step").textContent;
        document.body.dataset.time = document.getElementById("r-time").textContent;
    "#;
    let run = dump_dom(&browser, dir, &with_extra_script(&page, exercise));
    if let Err(problems) = page_problems(&run) {
        panic!("driving the controls broke the page:\n{problems}");
    }
    let last = trajectory.steps.len() - 1;
    let duration = trajectory.steps[last].time_s;
    let acting = match trajectory.steps[last].controller {
        Some(ActingController::Classical) => "classical controller",
        Some(ActingController::Learned) => "learned policy",
        Some(ActingController::Search) => "search detour",
        None => "no command (last step)",
    };
    assert!(
        run.stdout
            .contains(&format!(r#"data-step="{last} of {last}, {acting}""#)),
        "scrubbing to the end shows the last step: {}",
        run.stdout
            .lines()
            .find(|l| l.contains("<body"))
            .unwrap_or("")
    );
    assert!(
        run.stdout.contains(&format!(
            r#"data-time="{duration:.2} s of {duration:.2} s""#
        )),
        "scrubbing to the end shows the full duration"
    );
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn a_motion_of_only_the_seed_renders() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("dom-seed-only");
    let dir = tmp.path();
    let (trajectory, page) = page_of(0, "seed only");
    assert_eq!(trajectory.steps.len(), 1, "only the seed");
    if let Err(problems) = page_problems(&dump_dom(&browser, dir, &page)) {
        panic!("a one-step motion did not render cleanly:\n{problems}");
    }
}

/// A classical rollout round a circle of radius 5 cm on the mid-range pose's tool plane, and
/// its page.
fn circle_page() -> (Trajectory, String) {
    let robot =
        Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").expect("the FR3 robot file loads");
    let seed = robot.mid_range();
    let kin = robot.forward(&seed);
    let (p, n) = (kin.tcp(), kin.tool_axis());
    let across = n.cross(&(Vec3::y() - n * Vec3::y().dot(&n)).normalize());
    let spec = emg_control::PathSpec {
        version: 1,
        start: p.into(),
        normal: n.into(),
        blend_radius_m: 0.0,
        segments: vec![emg_control::SegmentSpec::Arc {
            centre: Some((p + across * 0.05).into()),
            through: None,
            to: None,
            sweep_deg: Some(360.0),
        }],
    };
    let path = emg_control::Path::new(spec).expect("a valid circle");
    let task = Task::on_path(&robot, path, Some(seed)).expect("a valid path task");
    let config = RolloutConfig::default();
    let trajectory = rollout(
        &robot,
        &task,
        &seed,
        &mut ClassicalController::default(),
        &config,
    );
    let page = render_html(&ViewerInput {
        robot: &robot,
        task: &task,
        trajectory: &trajectory,
        constraints: &config.constraints,
        title: "FR3 circle",
    });
    (trajectory, page)
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn a_path_task_draws_its_path() {
    let (trajectory, page) = circle_page();
    assert_eq!(trajectory.termination, emg_control::Termination::Completed);
    assert!(
        page.contains(r#""path":{"length_m":0.31416,"s":[0.0,"#),
        "the page holds the sampled path"
    );
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("path");
    let dir = tmp.path();
    let run = dump_dom(&browser, dir, &page);
    if let Err(problems) = page_problems(&run) {
        panic!("the path page did not run cleanly:\n{problems}");
    }
    let (_, _, pixels) = screenshot(&browser, dir, &page);
    if let Some(problem) = blank_screenshot_problem(&pixels) {
        panic!("{problem} (page in {})", dir.display());
    }
}

/// The job page of [`synthetic_job`].
fn job_page() -> (support::job::SyntheticJob, String) {
    let job = synthetic_job();
    let page = job.page("two strokes");
    (job, page)
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn a_job_page_renders_and_names_the_segment_under_way() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("job-dom");
    let dir = tmp.path();
    let (job, page) = job_page();
    if let Err(problems) = page_problems(&dump_dom(&browser, dir, &page)) {
        panic!("the job page did not run cleanly:\n{problems}");
    }
    let count = job.spans.len();
    let ids = ["r-segment", "r-stroke", "r-angle", "r-time"];
    // Mid-way through each segment, the read-out names it and says whether the pen is down.
    for (index, span) in job.spans.iter().enumerate() {
        let t = 0.5 * (span.start_s + span.end_s);
        let run = dump_dom(
            &browser,
            dir,
            &with_extra_script(&page, &scrub_and_record(t, &ids)),
        );
        if let Err(problems) = page_problems(&run) {
            panic!("scrubbing to {t} s broke the job page:\n{problems}");
        }
        let segment = body_data(&run, "r-segment").expect("the segment is recorded");
        assert_eq!(
            segment,
            format!("{} ({} of {count})", span.kind, index + 1),
            "at {t} s"
        );
        let stroke = body_data(&run, "r-stroke").expect("the stroke read-out is recorded");
        let angle = body_data(&run, "r-angle").expect("the tool angle is recorded");
        if span.task.is_some() {
            assert!(stroke.contains(" m of "), "pen down at {t} s: {stroke}");
            assert!(
                angle.contains("limit"),
                "the cone's limit at {t} s: {angle}"
            );
        } else {
            assert_eq!(stroke, "pen up", "at {t} s");
            assert_eq!(angle, "free (pen up)", "at {t} s");
        }
    }
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn a_job_page_lays_ink_as_it_plays() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("job-ink");
    let dir = tmp.path();
    let (_, page) = job_page();
    // Paused, zoomed in on the work (the view turns and zooms about it).
    let pause = r#"
        document.getElementById("play").click();
        const scene = document.getElementById("scene");
        for (let k = 0; k < 2; k++) {
            scene.dispatchEvent(new WheelEvent("wheel", { deltaY: -700, bubbles: true, cancelable: true }));
        }
    "#;
    let (width, height, at_start) = screenshot(&browser, dir, &with_extra_script(&page, pause));
    assert_eq!((width, height), (1000, 700), "screenshot size");
    if let Some(problem) = blank_screenshot_problem(&at_start) {
        panic!(
            "the job page looks blank: {problem} (page in {})",
            dir.display()
        );
    }
    let to_end = format!(
        "{pause}{}",
        scrub_and_record(1e9, &[]) // clamped to the program's end
    );
    let (_, _, at_end) = screenshot(&browser, dir, &with_extra_script(&page, &to_end));
    // Counted in the scene, above the controls and the legend (which has an ink swatch).
    let scene = |pixels: &[[u8; 3]]| pixels[..1000 * 590].to_vec();
    let ink = script_colour("INK_COLOUR");
    let (before, after) = (
        pixels_of(&scene(&at_start), ink),
        pixels_of(&scene(&at_end), ink),
    );
    assert!(
        before < 10 && after > 300,
        "ink pixels: {before} at the start, {after} at the end (page in {})",
        dir.display()
    );
    let moves = script_colour("MOVE_COLOUR");
    assert!(
        pixels_of(&scene(&at_start), moves) > 100,
        "the pen-up moves are drawn from the start (page in {})",
        dir.display()
    );
}

#[test]
#[ignore = "needs headless Chromium (`chromium` on PATH or EMG_CHROMIUM): `cargo test -- --include-ignored` runs it, as .ci/run does"]
fn a_job_page_without_samples_reports_the_error() {
    let Some(browser) = browser() else { return };
    let tmp = temp_dir("job-broken");
    let dir = tmp.path();
    let (_, page) = job_page();
    let broken = without_steps(&page);
    assert_ne!(broken, page, "the data blob holds the steps");
    let problems = page_problems(&dump_dom(&browser, dir, &broken))
        .expect_err("a job page whose script throws passed the check");
    assert!(
        problems.contains("error: Uncaught Error: the motion data holds no steps"),
        "{problems}"
    );
}
