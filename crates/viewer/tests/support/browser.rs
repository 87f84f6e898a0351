//! Headless Chromium on a viewer page: finding the browser, running it on a page, dumping the
//! DOM after the page ran and judging how it ran. Shared by the viewer's browser tests and
//! `emg job --html`'s (`crates/cli/tests/html.rs` includes this file); needs no crate beyond
//! the standard library.
//!
//! The browser is `$EMG_CHROMIUM`, else `chromium` or `chromium-browser` on `PATH`. The tests
//! that need it are ignored (with that reason) unless run with `cargo test -- --include-ignored`,
//! as `.ci/run` does after installing Chromium; so run, without one they print a notice and
//! pass, unless `EMG_REQUIRE_BROWSER=1` (as in CI), where they fail.
#![allow(dead_code)]

use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// The Chromium binary, or `None` (after a notice) when there is none and none is required.
pub fn browser() -> Option<PathBuf> {
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

/// What one headless Chromium run left behind.
pub struct BrowserRun {
    /// The browser's standard output (the DOM, with `--dump-dom`).
    pub stdout: String,
    /// Its standard error (the page's console, with `--enable-logging=stderr`).
    pub stderr: String,
}

/// Runs Chromium headless on `page` (written into `dir`) with the shared flags plus `extra`.
pub fn run_browser(browser: &Path, dir: &Path, page: &str, extra: &[String]) -> BrowserRun {
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

/// Dumps the DOM of `page` after it ran, with the browser's console logged to stderr.
pub fn dump_dom(browser: &Path, dir: &Path, page: &str) -> BrowserRun {
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
pub fn page_problems(run: &BrowserRun) -> Result<(), String> {
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

/// `page` with `script` run after the viewer's own script.
pub fn with_extra_script(page: &str, script: &str) -> String {
    let end = page.rfind("</body>").expect("the page has a body");
    format!(
        "{}<script>{script}</script>\n{}",
        &page[..end],
        &page[end..]
    )
}

/// The value of the attribute `data-{name}` that a script set on the dumped DOM's `<body>`.
pub fn body_data(run: &BrowserRun, name: &str) -> Option<String> {
    let body = run.stdout.lines().find(|l| l.contains("<body"))?;
    let key = format!("data-{name}=\"");
    let rest = &body[body.find(&key)? + key.len()..];
    Some(rest[..rest.find('"')?].to_string())
}

/// A script that scrubs the page to `t` seconds and records the read-out element `id`'s text as
/// the body's `data-{id}` (read back with [`body_data`]).
pub fn scrub_and_record(t: f64, ids: &[&str]) -> String {
    let mut script = format!(
        r#"
        const scrub = document.getElementById("scrub");
        scrub.value = String({t});
        scrub.dispatchEvent(new Event("input"));
        scrub.dispatchEvent(new Event("change"));
        "#
    );
    for id in ids {
        script.push_str(&format!(
            "document.body.dataset[\"{}\"] = document.getElementById(\"{id}\").textContent;\n",
            camel(id)
        ));
    }
    script
}

/// `r-step` as the `dataset` key `rStep` (the attribute `data-r-step`).
fn camel(id: &str) -> String {
    let mut out = String::new();
    let mut upper = false;
    for c in id.chars() {
        if c == '-' {
            upper = true;
        } else if upper {
            out.extend(c.to_uppercase());
            upper = false;
        } else {
            out.push(c);
        }
    }
    out
}
