//! Every command README.md and docs/*.md show, run as written, so that the pages cannot go stale.
//!
//! The convention (also in docs/cli.md, "Commands in these pages"):
//!
//! * Commands live in fenced blocks marked `sh`, `bash` or `shell` (one command per line; `#`
//!   starts a comment; a line ending in `\` goes on on the next) or `console` (a command is a
//!   line starting with `$ `, the lines after it up to the next `$ ` are its output).
//! * An `emg` command runs with this test's binary, in a fresh directory per page holding a copy
//!   of `examples/` and a link to `data/`: a page's commands run in order, as a user runs them
//!   from the repository's root, and write their outputs beside the copy, never into it (a
//!   command that changes or adds a file under `examples/` fails, since it would overwrite the
//!   repository's own). It must exit 0; in a `console` block, it must print the documented
//!   output line for line (stdout, then stderr), where `…` in a line stands for any text and a
//!   line of `…` alone for any number of lines, and output that starts with `error:` means the
//!   command must exit 1.
//! * Any other command is listed in [`NOT_RUN`] with the reason it cannot run in a test, and
//!   checked as far as it can be: the repository paths it names exist, a `cargo xtask`
//!   subcommand exists in xtask, a Slurm pipeline has its sbatch script. A command the list
//!   does not know fails the test.
//! * A line starting with `emg ` in a fenced block of another language fails the test: it would
//!   escape it.
//! * A file a page shows as written by its own commands ([`DOCUMENTED_FILES`]: the example
//!   trajectory files of the format pages) holds what they wrote.
//! * Every file under `examples/` is used by some command, and no page holds an absolute path of
//!   one machine (`/home/…`, `/root/…`, `/tmp/…`, `/work/…`, `/Users/…`).

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use common::{temp_dir, text};

/// Commands the pages show that this test does not run, by their first words, with the reason.
const NOT_RUN: &[(&str, &str)] = &[
    (
        "cargo install",
        "installs into ~/.cargo/bin after a release build of minutes; the `emg` it installs is \
         the binary this test runs, built in the test profile",
    ),
    (
        "cargo test",
        "runs the workspace's tests, this one among them",
    ),
    (
        "cargo xtask",
        "a pipeline of minutes to days; its subcommand is checked to exist in xtask/src",
    ),
    (
        "pip install",
        "builds the Python extension in release mode with maturin from PyPI; .ci/run tests the \
         package (crates/python/tests)",
    ),
    (
        "deploy/slurm/submit.sh",
        "needs a Slurm cluster; deploy/slurm/test.sh, run by .ci/run, submits the pipelines to \
         a one-node cluster; the pipeline's sbatch script is checked to exist",
    ),
    (
        ".ci/run",
        "the whole CI: installs Debian packages as root and downloads wheels from PyPI",
    ),
];

/// Pages whose commands are not run, with the reason (their blocks are still parsed).
const PAGES_NOT_RUN: &[(&str, &str)] = &[(
    "docs/robot-import.md",
    "its commands import a vendor's description that the user downloads (the repository ships \
     none); crates/cli/tests/import.rs imports four such files when CI provides them",
)];

/// How long the slowest command may take before the test says so (debug builds plan slowly).
const SLOW: Duration = Duration::from_secs(60);

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("the repository root")
}

/// README.md and docs/*.md, as paths relative to the root.
fn pages() -> Vec<String> {
    let mut pages = vec!["README.md".to_string()];
    let mut docs: Vec<String> = std::fs::read_dir(root().join("docs"))
        .expect("docs/")
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".md"))
        .map(|name| format!("docs/{name}"))
        .collect();
    docs.sort();
    pages.extend(docs);
    pages
}

/// One command a page shows.
#[derive(Debug)]
struct Shown {
    /// The page, relative to the root.
    page: String,
    /// 1-based line of its first line.
    line: usize,
    /// Its text, continuation lines joined, comment dropped.
    text: String,
    /// Its words, as a shell splits them.
    words: Vec<String>,
    /// In a `console` block, the documented output.
    output: Option<Vec<String>>,
}

impl Shown {
    fn place(&self) -> String {
        format!("{}:{}: `{}`", self.page, self.line, self.text)
    }
}

/// Splits `line` into words as a POSIX shell does for a plain command: single and double
/// quotes, backslash escapes, and `#` at the start of a word starting a comment. Pipes,
/// redirections, variables and the like are refused: a documented command is a plain one.
fn shell_words(line: &str) -> Result<Vec<String>, String> {
    let mut words = Vec::new();
    let mut word: Option<String> = None;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            c if c.is_whitespace() => {
                if let Some(w) = word.take() {
                    words.push(w);
                }
            }
            '#' if word.is_none() => break,
            '\'' => {
                let w = word.get_or_insert_with(String::new);
                loop {
                    match chars.next() {
                        Some('\'') => break,
                        Some(c) => w.push(c),
                        None => return Err("unterminated single quote".into()),
                    }
                }
            }
            '"' => {
                let w = word.get_or_insert_with(String::new);
                loop {
                    match chars.next() {
                        Some('"') => break,
                        Some('\\') => match chars.next() {
                            Some(c @ ('"' | '\\' | '$' | '`')) => w.push(c),
                            Some(c) => {
                                w.push('\\');
                                w.push(c);
                            }
                            None => return Err("unterminated double quote".into()),
                        },
                        Some(c @ ('$' | '`')) => {
                            return Err(format!("shell expansion `{c}` in double quotes"));
                        }
                        Some(c) => w.push(c),
                        None => return Err("unterminated double quote".into()),
                    }
                }
            }
            '\\' => match chars.next() {
                Some(c) => word.get_or_insert_with(String::new).push(c),
                None => return Err("a trailing backslash".into()),
            },
            '|' | '&' | ';' | '<' | '>' | '$' | '`' | '(' | ')' | '*' | '?' => {
                return Err(format!("shell syntax `{c}`: show a plain command"));
            }
            c => word.get_or_insert_with(String::new).push(c),
        }
    }
    words.extend(word);
    Ok(words)
}

/// The language of a fence's info string (`sh`, `console`, `rust,ignore` → `rust`).
fn language(info: &str) -> &str {
    info.split([' ', ',', '{']).next().unwrap_or("")
}

/// The command of one logical line of a block (`None` for a comment or a blank line).
fn command(page: &str, line: usize, text: &str, console: bool) -> Result<Option<Shown>, String> {
    let text = text.trim();
    let words =
        shell_words(text).map_err(|problem| format!("{page}:{line}: `{text}`: {problem}"))?;
    if words.is_empty() {
        return Ok(None);
    }
    let text = text.split(" #").next().unwrap_or(text).trim_end();
    Ok(Some(Shown {
        page: page.to_string(),
        line,
        text: text.to_string(),
        words,
        output: console.then(Vec::new),
    }))
}

/// Every command `page` shows, and what is wrong with how it shows them.
fn extract(page: &str, content: &str) -> (Vec<Shown>, Vec<String>) {
    let mut shown: Vec<Shown> = Vec::new();
    let mut problems = Vec::new();
    // The language of the fenced block the line is in.
    let mut block: Option<String> = None;
    // A command whose last line ended in a backslash: (first line, text so far).
    let mut pending: Option<(usize, String)> = None;
    // How many commands the block shown so far holds.
    let mut in_block = 0;
    for (index, raw) in content.lines().enumerate() {
        let number = index + 1;
        let trimmed = raw.trim_start();
        if let Some(info) = trimmed.strip_prefix("```") {
            if block.take().is_none() {
                block = Some(language(info.trim()).to_string());
                in_block = 0;
            } else if let Some((line, text)) = pending.take() {
                problems.push(format!(
                    "{page}:{line}: `{text}`: the block ends after a continuation backslash"
                ));
            }
            continue;
        }
        let Some(lang) = block.as_deref() else {
            continue;
        };
        match lang {
            "sh" | "bash" | "shell" | "console" => {
                let console = lang == "console";
                let (line, mut text) = match pending.take() {
                    Some((line, text)) => (line, format!("{text} {trimmed}")),
                    None if console && in_block == 0 && trimmed.is_empty() => continue,
                    None if console => match trimmed.strip_prefix("$ ") {
                        Some(command) => (number, command.to_string()),
                        None => {
                            match shown.last_mut().and_then(|s| s.output.as_mut()) {
                                Some(output) if in_block > 0 => {
                                    output.push(raw.trim_end().to_string());
                                }
                                _ => problems.push(format!(
                                    "{page}:{number}: output before any `$ ` command"
                                )),
                            }
                            continue;
                        }
                    },
                    None => (number, trimmed.to_string()),
                };
                if text.trim_end().ends_with('\\') {
                    let cut = text.trim_end().len() - 1;
                    text.truncate(cut);
                    pending = Some((line, text.trim_end().to_string()));
                    continue;
                }
                match command(page, line, &text, console) {
                    Ok(Some(command)) => {
                        shown.push(command);
                        in_block += 1;
                    }
                    Ok(None) => {}
                    Err(problem) => problems.push(problem),
                }
            }
            _ => {
                if trimmed.starts_with("emg ") || trimmed.starts_with("$ emg ") {
                    problems.push(format!(
                        "{page}:{number}: `{}` is in a ```{lang} block, where this test does \
                         not run it: put commands in ```sh or ```console blocks",
                        trimmed.trim_end()
                    ));
                }
            }
        }
    }
    if block.is_some() {
        problems.push(format!("{page}: a fenced block is never closed"));
    }
    // A console command's output, as documented, has no trailing blank lines.
    for command in &mut shown {
        if let Some(output) = &mut command.output {
            while output.last().is_some_and(|l| l.trim().is_empty()) {
                output.pop();
            }
        }
    }
    (shown, problems)
}

/// Whether `actual` matches the documented `pattern`, where `…` stands for any text.
fn line_matches(pattern: &str, actual: &str) -> bool {
    let parts: Vec<&str> = pattern.split('…').collect();
    let [first, middle @ .., last] = parts.as_slice() else {
        return pattern == actual;
    };
    if parts.len() == 1 {
        return pattern == actual;
    }
    let Some(mut rest) = actual.strip_prefix(first) else {
        return false;
    };
    for part in middle {
        match rest.find(part) {
            Some(at) => rest = &rest[at + part.len()..],
            None => return false,
        }
    }
    rest.len() >= last.len() && rest.ends_with(last)
}

/// Whether the documented lines match the actual ones; a documented line of `…` alone matches
/// any number of lines.
fn lines_match(documented: &[String], actual: &[&str]) -> bool {
    match documented.split_first() {
        None => actual.is_empty(),
        Some((first, rest)) if first.trim() == "…" => {
            (0..=actual.len()).any(|skip| lines_match(rest, &actual[skip..]))
        }
        Some((first, rest)) => actual.split_first().is_some_and(|(line, more)| {
            line_matches(first.trim_end(), line.trim_end()) && lines_match(rest, more)
        }),
    }
}

/// Every file under `dir`, relative to it, with its bytes.
fn files_under(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(base: &Path, dir: &Path, files: &mut BTreeMap<PathBuf, Vec<u8>>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(base, &path, files);
            } else {
                let bytes = std::fs::read(&path).unwrap();
                files.insert(path.strip_prefix(base).unwrap().to_path_buf(), bytes);
            }
        }
    }
    let mut files = BTreeMap::new();
    walk(dir, dir, &mut files);
    files
}

/// Copies the files of `from` into `to`.
fn copy_files(files: &BTreeMap<PathBuf, Vec<u8>>, to: &Path) {
    for (name, bytes) in files {
        let path = to.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
}

/// What running one page's commands gave: the failures, and each command's time.
type PageRun = (Vec<String>, Vec<(String, Duration)>);

/// Runs one page's `emg` commands in order in a fresh directory; returns the failures and
/// each command's time.
fn run_page(commands: &[&Shown], examples: &BTreeMap<PathBuf, Vec<u8>>) -> PageRun {
    let mut failures = Vec::new();
    let mut times = Vec::new();
    if commands.is_empty() {
        return (failures, times);
    }
    let dir = temp_dir("docs");
    copy_files(examples, &dir.path().join("examples"));
    std::os::unix::fs::symlink(root().join("data"), dir.path().join("data")).unwrap();
    for command in commands {
        let started = Instant::now();
        let output = Command::new(env!("CARGO_BIN_EXE_emg"))
            .args(&command.words[1..])
            .current_dir(dir.path())
            .env_remove("EMG_DATA")
            .output()
            .expect("run emg");
        let elapsed = started.elapsed();
        times.push((command.place(), elapsed));
        let stdout = text(&output.stdout);
        let stderr = text(&output.stderr);
        let expect_failure = command
            .output
            .as_ref()
            .is_some_and(|lines| lines.iter().any(|l| l.starts_with("error:")));
        let status_ok = if expect_failure {
            output.status.code() == Some(1)
        } else {
            output.status.success()
        };
        if !status_ok {
            failures.push(format!(
                "{} {} (expected {}):\n--- stderr\n{stderr}--- stdout\n{stdout}",
                command.place(),
                output.status,
                if expect_failure {
                    "exit status 1"
                } else {
                    "success"
                },
            ));
            continue;
        }
        if let Some(documented) = &command.output {
            let actual: Vec<&str> = stdout.lines().chain(stderr.lines()).collect();
            if !documented.is_empty() && !lines_match(documented, &actual) {
                failures.push(format!(
                    "{} printed other output than the page shows:\n--- documented\n{}\n--- \
                     printed (stdout, then stderr)\n{}",
                    command.place(),
                    documented.join("\n"),
                    actual.join("\n")
                ));
            }
        }
        let now = files_under(&dir.path().join("examples"));
        if &now != examples {
            let changed: std::collections::BTreeSet<String> = now
                .keys()
                .chain(examples.keys())
                .filter(|name| now.get(*name) != examples.get(*name))
                .map(|name| format!("examples/{}", name.display()))
                .collect();
            failures.push(format!(
                "{} wrote into examples/ ({}): outputs must not overwrite or join the shipped \
                 inputs",
                command.place(),
                changed.into_iter().collect::<Vec<_>>().join(", ")
            ));
            std::fs::remove_dir_all(dir.path().join("examples")).unwrap();
            copy_files(examples, &dir.path().join("examples"));
        }
    }
    failures.extend(check_documented_files(&commands[0].page, dir.path()));
    (failures, times)
}

/// Files a page shows as the output of its own commands: (page, the text before the block (the
/// first ```json block after it for a JSON file), the file the page's commands wrote). A JSON
/// block must hold the file's values (`…` in a string stands for any text, and `points` may
/// show the first points alone); any other block must be the file's text.
const DOCUMENTED_FILES: &[(&str, &str, &str)] = &[
    ("docs/trajectory-format.md", "### Example", "short.json"),
    (
        "docs/trajectory-format.md",
        "The rows of the example above:",
        "short.csv",
    ),
    (
        "docs/joint-trajectory-format.md",
        "### Example",
        "short.joint_trajectory.json",
    ),
];

/// Where the documented value `doc` differs from the written `actual` (`None` when it holds
/// them).
fn json_differs(doc: &serde_json::Value, actual: &serde_json::Value, at: &str) -> Option<String> {
    use serde_json::Value;
    let differs = || {
        Some(format!(
            "{at}: the page shows {doc}, the file holds {actual}"
        ))
    };
    match (doc, actual) {
        (Value::String(d), Value::String(a)) => (!line_matches(d, a)).then(differs).flatten(),
        (Value::Number(d), Value::Number(a)) => (d.as_f64() != a.as_f64()).then(differs).flatten(),
        (Value::Array(d), Value::Array(a)) => {
            let prefix = at.ends_with(".points") && d.len() <= a.len();
            if d.len() != a.len() && !prefix {
                return Some(format!(
                    "{at}: the page shows {} values, the file holds {}",
                    d.len(),
                    a.len()
                ));
            }
            d.iter()
                .zip(a)
                .enumerate()
                .find_map(|(i, (d, a))| json_differs(d, a, &format!("{at}[{i}]")))
        }
        (Value::Object(d), Value::Object(a)) => {
            let keys = |o: &serde_json::Map<String, Value>| o.keys().cloned().collect::<Vec<_>>();
            if keys(d) != keys(a) {
                return Some(format!(
                    "{at}: the page shows the fields {:?}, the file holds {:?}",
                    keys(d),
                    keys(a)
                ));
            }
            d.iter()
                .find_map(|(key, value)| json_differs(value, &a[key], &format!("{at}.{key}")))
        }
        _ => (doc != actual).then(differs).flatten(),
    }
}

/// Compares the files `page` shows with those its commands wrote into `dir`.
fn check_documented_files(page: &str, dir: &Path) -> Vec<String> {
    let content = std::fs::read_to_string(root().join(page)).unwrap();
    let mut failures = Vec::new();
    for (_, marker, file) in DOCUMENTED_FILES.iter().filter(|(p, _, _)| *p == page) {
        let Some(at) = content.find(marker) else {
            failures.push(format!(
                "{page}: no `{marker}` before the file {file} it shows"
            ));
            continue;
        };
        let rest = &content[at..];
        let fence = if file.ends_with(".json") {
            "```json"
        } else {
            "```"
        };
        let open = rest.find(fence).expect("a block after the marker");
        let body = &rest[open..];
        let body = &body[body.find('\n').unwrap() + 1..];
        let shown = &body[..body.find("```").expect("the block's end")];
        let written = match std::fs::read_to_string(dir.join(file)) {
            Ok(text) => text,
            Err(error) => {
                failures.push(format!(
                    "{page}: shows {file}, which its commands did not write: {error}"
                ));
                continue;
            }
        };
        let problem = if file.ends_with(".json") {
            let doc: serde_json::Value = match serde_json::from_str(shown) {
                Ok(value) => value,
                Err(error) => {
                    failures.push(format!("{page}: the block after `{marker}`: {error}"));
                    continue;
                }
            };
            json_differs(&doc, &serde_json::from_str(&written).unwrap(), "")
        } else {
            (shown != written)
                .then(|| format!("the page shows\n{shown}\nthe file holds\n{written}"))
        };
        if let Some(problem) = problem {
            failures.push(format!(
                "{page}: the block after `{marker}` is not the {file} the page's commands wrote: {problem}"
            ));
        }
    }
    failures
}

/// The kebab-case names of the variants of `enum NAME {` in a Rust source.
fn variants(source: &str, name: &str) -> Vec<String> {
    let start = source
        .find(&format!("enum {name} {{"))
        .unwrap_or_else(|| panic!("enum {name} in xtask"));
    let body = &source[start..];
    let body = &body[..body.find("\n}").unwrap()];
    body.lines()
        .filter_map(|line| {
            let line = line.trim();
            let end = line.find(['(', ',', ' '])?;
            let ident = &line[..end];
            (ident.chars().next()?.is_ascii_uppercase()
                && ident.chars().all(|c| c.is_ascii_alphanumeric()))
            .then(|| {
                let mut kebab = String::new();
                for (i, c) in ident.chars().enumerate() {
                    if c.is_ascii_uppercase() && i > 0 {
                        kebab.push('-');
                    }
                    kebab.push(c.to_ascii_lowercase());
                }
                kebab
            })
        })
        .collect()
}

/// Checks a command this test does not run as far as it can be; returns the reason it is not
/// run, or the failure.
fn check_not_run(command: &Shown) -> Result<&'static str, String> {
    let joined = command.words.join(" ");
    let Some((prefix, reason)) = NOT_RUN
        .iter()
        .find(|(prefix, _)| joined == *prefix || joined.starts_with(&format!("{prefix} ")))
    else {
        return Err(format!(
            "{}: neither an `emg` command nor one of NOT_RUN in {}: run it or list it with the \
             reason",
            command.place(),
            file!()
        ));
    };
    let root = root();
    for word in &command.words {
        let path = word.split_once('=').map_or(word.as_str(), |(_, p)| p);
        if path.contains('/') && !path.starts_with('-') && !path.starts_with('~') {
            let path = path.trim_start_matches("./");
            if !root.join(path).exists() {
                return Err(format!("{}: no {path} in the repository", command.place()));
            }
        }
    }
    let args: Vec<&str> = command.words[prefix.split(' ').count()..]
        .iter()
        .map(String::as_str)
        .collect();
    match *prefix {
        "cargo xtask" => {
            let main = std::fs::read_to_string(root.join("xtask/src/main.rs")).unwrap();
            let names = variants(&main, "Command");
            let first = args.iter().find(|a| !a.starts_with('-'));
            if let Some(name) = first {
                if !names.iter().any(|n| n == name) {
                    return Err(format!(
                        "{}: xtask has no subcommand {name} (it has {})",
                        command.place(),
                        names.join(", ")
                    ));
                }
                if *name == "ablate" {
                    let ablate = std::fs::read_to_string(root.join("xtask/src/ablate.rs")).unwrap();
                    let kinds = variants(&ablate, "Variant");
                    let kind = args.iter().skip_while(|a| *a != name).nth(1);
                    if !kind.is_some_and(|k| kinds.iter().any(|n| n == k)) {
                        return Err(format!(
                            "{}: `cargo xtask ablate` takes one of {}",
                            command.place(),
                            kinds.join(", ")
                        ));
                    }
                }
            }
        }
        "deploy/slurm/submit.sh" => {
            let mut rest = args.iter();
            let pipeline = loop {
                match rest.next() {
                    Some(&("--throttle" | "--cpus" | "--logs")) => {
                        rest.next();
                    }
                    Some(option) if option.starts_with('-') => {}
                    Some(pipeline) => break *pipeline,
                    None => return Err(format!("{}: names no pipeline", command.place())),
                }
            };
            let script = format!("deploy/slurm/{pipeline}.sbatch");
            if !root.join(&script).exists() {
                return Err(format!("{}: no {script}", command.place()));
            }
        }
        _ => {}
    }
    Ok(reason)
}

/// Absolute paths of one machine in `content`: `/home/…` and the like, not `target/tmp/`.
fn absolute_paths(page: &str, content: &str) -> Vec<String> {
    let mut found = Vec::new();
    for (index, line) in content.lines().enumerate() {
        for prefix in ["/home/", "/root/", "/tmp/", "/work/", "/Users/"] {
            for (at, _) in line.match_indices(prefix) {
                let before = line[..at].chars().next_back();
                if !before.is_some_and(|c| c.is_alphanumeric() || "._-~/".contains(c)) {
                    found.push(format!("{page}:{}: {}", index + 1, line.trim()));
                }
            }
        }
    }
    found
}

#[test]
fn every_command_the_docs_show_runs_as_written() {
    let root = root();
    let examples = files_under(&root.join("examples"));
    assert!(!examples.is_empty(), "examples/ holds no files");
    let mut problems = Vec::new();
    let mut shown = Vec::new();
    for page in pages() {
        let content = std::fs::read_to_string(root.join(&page)).unwrap();
        problems.extend(absolute_paths(&page, &content));
        let (commands, found) = extract(&page, &content);
        problems.extend(found);
        shown.extend(commands);
    }
    for name in examples.keys() {
        let name = format!("examples/{}", name.display());
        if !shown
            .iter()
            .any(|c| c.words.iter().any(|w| w.contains(&name)))
        {
            problems.push(format!("{name} is used by no command the pages show"));
        }
    }

    let mut not_run = Vec::new();
    let mut by_page: BTreeMap<&str, Vec<&Shown>> = BTreeMap::new();
    for command in &shown {
        if command.words[0] != "emg" {
            match check_not_run(command) {
                Ok(reason) => not_run.push(format!("{}\n    not run: {reason}", command.place())),
                Err(problem) => problems.push(problem),
            }
        } else if let Some((_, reason)) = PAGES_NOT_RUN.iter().find(|(p, _)| *p == command.page) {
            not_run.push(format!("{}\n    not run: {reason}", command.place()));
        } else {
            by_page.entry(&command.page).or_default().push(command);
        }
    }
    let started = Instant::now();
    let results: Vec<PageRun> = std::thread::scope(|scope| {
        let handles: Vec<_> = by_page
            .values()
            .map(|commands| scope.spawn(|| run_page(commands, &examples)))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let mut times = Vec::new();
    for (failures, page_times) in results {
        problems.extend(failures);
        times.extend(page_times);
    }
    eprintln!(
        "{} emg commands run in {:.1} s:",
        times.len(),
        started.elapsed().as_secs_f64()
    );
    for (place, time) in &times {
        let slow = if *time > SLOW { "  (slow)" } else { "" };
        eprintln!("  {:6.1} s  {place}{slow}", time.as_secs_f64());
    }
    eprintln!("{} commands not run:", not_run.len());
    for line in &not_run {
        eprintln!("  {line}");
    }
    assert!(
        times.len() >= 10,
        "only {} emg commands found: is the extraction broken?",
        times.len()
    );
    assert!(
        problems.is_empty(),
        "{} problems with the commands the docs show:\n\n{}",
        problems.len(),
        problems.join("\n\n")
    );
}

#[test]
fn the_extraction_follows_the_convention() {
    let page = "intro\n```sh\nemg plan --out a   # a comment\n# only a comment\nemg check \\\n    a.json\n```\n\
                ```console\n$ emg check a.json\nline one\n…\n$ emg check b.json\nerror: no\n```\n\
                ```text\nemg plan\n```\n";
    let (shown, problems) = extract("p.md", page);
    let words: Vec<String> = shown.iter().map(|s| s.words.join(" ")).collect();
    assert_eq!(
        words,
        [
            "emg plan --out a",
            "emg check a.json",
            "emg check a.json",
            "emg check b.json"
        ]
    );
    assert_eq!(
        shown.iter().map(|s| s.line).collect::<Vec<_>>(),
        [3, 5, 9, 12]
    );
    assert_eq!(shown[0].text, "emg plan --out a");
    assert_eq!(shown[0].output, None);
    assert_eq!(
        shown[2].output.as_deref(),
        Some(&["line one".to_string(), "…".into()][..])
    );
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(problems[0].contains("p.md:16"), "{problems:?}");

    assert_eq!(
        shell_words(r#"emg plan --config '{"search": {"beam_width": 0}}' --out "a b" # c"#)
            .unwrap(),
        [
            "emg",
            "plan",
            "--config",
            r#"{"search": {"beam_width": 0}}"#,
            "--out",
            "a b"
        ]
    );
    assert!(shell_words("emg plan > x").is_err());
    assert!(shell_words("emg plan --out $HOME/x").is_err());

    assert!(line_matches(
        "robot …/data/robots/fr3_pen.urdf",
        "robot /x/y/data/robots/fr3_pen.urdf"
    ));
    assert!(!line_matches(
        "robot …/fr3_pen.urdf",
        "robot /x/ur5e_pen.urdf"
    ));
    assert!(line_matches("a…b…c", "abc"));
    let documented = ["first".to_string(), "…".into(), "last".into()];
    assert!(lines_match(&documented, &["first", "x", "y", "last"]));
    assert!(lines_match(&documented, &["first", "last"]));
    assert!(!lines_match(&documented, &["first", "x"]));

    let found = absolute_paths(
        "p.md",
        "under `target/tmp/` and ~/x\n\"robot\": \"/home/me/x\"",
    );
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].starts_with("p.md:2:"), "{found:?}");

    let main = std::fs::read_to_string(root().join("xtask/src/main.rs")).unwrap();
    let names = variants(&main, "Command");
    assert!(names.iter().any(|n| n == "make-tasks"), "{names:?}");
    assert!(names.iter().any(|n| n == "readme-picture"), "{names:?}");
}

/// The first ```json block of a page, parsed.
fn first_json_block(page: &str) -> serde_json::Value {
    let content = std::fs::read_to_string(root().join(page)).unwrap();
    let start = content.find("```json\n").expect("a JSON block") + "```json\n".len();
    let end = start + content[start..].find("```").unwrap();
    serde_json::from_str(&content[start..end]).unwrap_or_else(|e| panic!("{page}: {e}"))
}

#[test]
fn the_files_the_pages_show_are_the_shipped_examples() {
    for (page, file) in [
        ("docs/paths.md", "examples/slot.json"),
        ("docs/scene.md", "examples/cell.json"),
    ] {
        let shipped: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(root().join(file)).unwrap()).unwrap();
        assert_eq!(
            first_json_block(page),
            shipped,
            "{page} shows another file than {file}"
        );
    }
}
