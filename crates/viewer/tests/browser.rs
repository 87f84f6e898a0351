//! The viewer page in a real browser: headless Chromium draws a planned FR3 motion, and the
//! screenshot, the page's render status and the browser console are checked.
//!
//! The browser is `$EMG_CHROMIUM`, else `chromium` or `chromium-browser` on `PATH`. The tests
//! that need it are ignored (with that reason) unless run with `cargo test -- --include-ignored`,
//! as `.ci/run` does after installing Chromium; so run, without one they print a notice and
//! pass, unless `EMG_REQUIRE_BROWSER=1` (as in CI), where they fail.

use std::collections::HashSet;
use std::io::{BufReader, Read as _};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use emg_control::{
    ActingController, ClassicalController, RolloutConfig, Task, Trajectory, rollout,
};
use emg_kinematics::{Robot, Vec3};
use emg_viewer::{ViewerInput, render_html};

/// The colour the page paints link capsules with, read from the page's own script.
fn link_colour() -> [u8; 3] {
    let script = include_str!("../src/viewer.js");
    let line = script
        .lines()
        .find(|l| l.contains("const LINK_COLOUR = \"#"))
        .expect("viewer.js defines LINK_COLOUR");
    let hex = line.split('#').nth(1).expect("a # colour")[..6].to_owned();
    let channel = |i: usize| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).expect("hex colour");
    [channel(0), channel(1), channel(2)]
}

/// The Chromium binary, or `None` (after a notice) when there is none and none is required.
fn browser() -> Option<PathBuf> {
    if let Some(path) = std::env::var_os("EMG_CHROMIUM").filter(|p| !p.is_empty()) {
        return Some(PathBuf::from(path));
    }
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .flat_map(|dir| ["chromium", "chromium-browser"].map(|name| dir.join(name)))
            .find(|candidate| candidate.is_file())
    });
    if found.is_none() {
        assert!(
            std::env::var("EMG_REQUIRE_BROWSER").as_deref() != Ok("1"),
            "EMG_REQUIRE_BROWSER=1 but no browser was found: install Chromium (`chromium` or \
             `chromium-browser` on PATH) or point EMG_CHROMIUM at its binary"
        );
        eprintln!(
            "notice: skipping the headless-browser check of the viewer page: no `chromium` or \
             `chromium-browser` on PATH and EMG_CHROMIUM is unset (set EMG_REQUIRE_BROWSER=1 to \
             make this a failure)"
        );
    }
    found
}

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

/// What one headless Chromium run left behind.
struct BrowserRun {
    stdout: String,
    stderr: String,
}

/// Runs Chromium headless on `page` (written into `dir`) with the shared flags plus `extra`.
fn run_browser(browser: &Path, dir: &Path, page: &str, extra: &[String]) -> BrowserRun {
    static RUN: AtomicUsize = AtomicUsize::new(0);
    let run = RUN.fetch_add(1, Ordering::Relaxed);
    let page_path = dir.join(format!("page-{run}.html"));
    std::fs::write(&page_path, page).expect("write the page");
    let profile = dir.join(format!("profile-{run}"));
    let mut child = Command::new(browser)
        .args([
            "--headless=new",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
            "--window-size=1000,700",
            "--virtual-time-budget=3000",
            "--no-first-run",
            "--no-default-browser-check",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(format!("file://{}", page_path.display()))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start the browser {}: {e}", browser.display()));
    // Read both pipes on threads so a chatty browser never blocks on a full pipe.
    let drain = |pipe: Option<Box<dyn std::io::Read + Send>>| {
        std::thread::spawn(move || {
            let mut text = String::new();
            if let Some(mut pipe) = pipe {
                let mut bytes = Vec::new();
                let _ = pipe.read_to_end(&mut bytes);
                text = String::from_utf8_lossy(&bytes).into_owned();
            }
            text
        })
    };
    let stdout = drain(child.stdout.take().map(|p| Box::new(p) as _));
    let stderr = drain(child.stderr.take().map(|p| Box::new(p) as _));
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        match child.try_wait().expect("wait for the browser") {
            Some(_) => break,
            None if Instant::now() > deadline => {
                let _ = child.kill();
                let _ = child.wait();
                panic!(
                    "the browser did not finish within 120 s on {}",
                    page_path.display()
                );
            }
            None => std::thread::sleep(Duration::from_millis(50)),
        }
    }
    BrowserRun {
        stdout: stdout.join().expect("stdout reader"),
        stderr: stderr.join().expect("stderr reader"),
    }
}

/// Renders `page` to a PNG screenshot and returns it as RGB pixels `(width, height, rgb)`.
fn screenshot(browser: &Path, dir: &Path, page: &str) -> (u32, u32, Vec<[u8; 3]>) {
    let png_path = dir.join("screenshot.png");
    let _ = std::fs::remove_file(&png_path);
    let run = run_browser(
        browser,
        dir,
        page,
        &[format!("--screenshot={}", png_path.display())],
    );
    let file = std::fs::File::open(&png_path).unwrap_or_else(|e| {
        panic!(
            "no screenshot at {}: {e}\nbrowser stderr:\n{}",
            png_path.display(),
            run.stderr
        )
    });
    let mut decoder = png::Decoder::new(BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().expect("a PNG screenshot");
    let mut buffer = vec![0; reader.output_buffer_size().expect("a sane PNG size")];
    let info = reader
        .next_frame(&mut buffer)
        .expect("decode the screenshot");
    let channels = info.color_type.samples();
    let pixels = buffer[..info.buffer_size()]
        .chunks_exact(channels)
        .map(|px| match channels {
            1 | 2 => [px[0]; 3],
            _ => [px[0], px[1], px[2]],
        })
        .collect();
    (info.width, info.height, pixels)
}

/// Why a screenshot looks blank: too few distinct colours, or too few pixels in the link colour.
fn blank_screenshot_problem(pixels: &[[u8; 3]]) -> Option<String> {
    const MIN_COLOURS: usize = 300;
    const MIN_LINK_PIXELS: usize = 3000;
    let colours = pixels.iter().collect::<HashSet<_>>().len();
    let link = link_colour();
    let link_pixels = pixels
        .iter()
        .filter(|px| (0..3).all(|c| px[c].abs_diff(link[c]) <= 8))
        .count();
    let mut problems = Vec::new();
    if colours < MIN_COLOURS {
        problems.push(format!(
            "{colours} distinct colours (expected at least {MIN_COLOURS})"
        ));
    }
    if link_pixels < MIN_LINK_PIXELS {
        problems.push(format!(
            "{link_pixels} pixels in the link colour {link:?} (expected at least {MIN_LINK_PIXELS})"
        ));
    }
    (!problems.is_empty()).then(|| problems.join("; "))
}

/// Dumps the DOM of `page` after it ran, with the browser's console logged to stderr.
fn dump_dom(browser: &Path, dir: &Path, page: &str) -> BrowserRun {
    run_browser(
        browser,
        dir,
        page,
        &[
            "--dump-dom".into(),
            "--enable-logging=stderr".into(),
            "--v=0".into(),
        ],
    )
}

/// Whether a page ran cleanly: its status is `rendered` and the console stayed silent.
///
/// This Chromium logs every console message of the page, whatever its level, as an
/// `INFO:CONSOLE...` line on stderr (uncaught errors as `"Uncaught ..."`), so the level of a
/// `console.error` cannot be told apart from a `console.log`. The viewer writes nothing to the
/// console, so every console line counts as a problem.
fn page_problems(run: &BrowserRun) -> Result<(), String> {
    let mut problems = Vec::new();
    if !run.stdout.contains(r#"data-status="rendered""#) {
        let status = run
            .stdout
            .split("data-status=\"")
            .nth(1)
            .and_then(|rest| rest.split('"').next())
            .unwrap_or("(no data-status in the dumped DOM)");
        problems.push(format!("page status is '{status}', not 'rendered'"));
    }
    problems.extend(
        run.stderr
            .lines()
            .filter(|line| line.contains("CONSOLE") || line.contains("Uncaught"))
            .map(|line| format!("console: {line}")),
    );
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("\n"))
    }
}

/// The planned page with `script` run after the viewer's own script.
fn with_extra_script(page: &str, script: &str) -> String {
    let end = page.rfind("</body>").expect("the page has a body");
    format!(
        "{}<script>{script}</script>\n{}",
        &page[..end],
        &page[end..]
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

/// The workspace's shipped data directory.
fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

/// The shipped FR3 robot file.
fn fr3_path() -> std::path::PathBuf {
    data_dir().join("robots/fr3_pen.urdf")
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
        page.contains(r#""path":{"step_m":0.005"#),
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
