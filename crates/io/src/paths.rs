//! Where the files of a planned task go: `<stem>.json`, `<stem>.csv`,
//! `<stem>.joint_trajectory.json`, and `-00007` before the extension for task 7 of a multi-task
//! run.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// The paths of one planned task's files.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlanPaths {
    /// `emg-trajectory/1` JSON.
    pub json: PathBuf,
    /// The CSV table.
    pub csv: PathBuf,
    /// `emg-joint-trajectory/2` JSON.
    pub joint_trajectory: PathBuf,
}

impl PlanPaths {
    /// The files for `stem`: `<stem>.json`, or `<stem>-00007.json` for task 7 of a multi-task
    /// run (`index = Some(7)`), and likewise `.csv` and `.joint_trajectory.json`.
    pub fn new(stem: &Path, index: Option<usize>) -> Self {
        Self {
            json: suffixed(stem, index, ".json"),
            csv: suffixed(stem, index, ".csv"),
            joint_trajectory: suffixed(stem, index, ".joint_trajectory.json"),
        }
    }
}

/// `stem`, then `-iiiii` for task `index`, then `ext`, appended as text.
fn suffixed(stem: &Path, index: Option<usize>, ext: &str) -> PathBuf {
    let mut name = OsString::from(stem.as_os_str());
    if let Some(i) = index {
        name.push(format!("-{i:05}"));
    }
    name.push(ext);
    PathBuf::from(name)
}

/// The viewer page path for `--html <path>`: `path` itself, or for task 7 of a multi-task run
/// `path` without its extension, then `-00007`, then the extension (`.html` when it has none).
pub fn html_path(path: &Path, index: Option<usize>) -> PathBuf {
    let Some(i) = index else {
        return path.to_path_buf();
    };
    let mut name = OsString::from(path.with_extension("").as_os_str());
    name.push(format!("-{i:05}."));
    name.push(path.extension().unwrap_or("html".as_ref()));
    PathBuf::from(name)
}

/// An output of a run that would replace one of its inputs, or another of its outputs.
#[derive(Debug, thiserror::Error)]
#[error(
    "{output} would write {}, which is {what}: nothing was written; give {output} another name",
    path.display()
)]
pub struct OutputClash {
    /// The option that names the output, e.g. `--out trajectory`.
    pub output: String,
    /// The file it would write.
    pub path: PathBuf,
    /// What that file already is, e.g. `the --path file` or `written by --html too`.
    pub what: String,
}

/// Refuses a run whose `outputs` (option, file) would replace one of its `inputs` (option,
/// file) or one another, before anything is written. Paths are compared canonically: relative
/// to the working directory, with `.`, `..` and symbolic links resolved, a file not yet
/// written by way of its nearest existing ancestor.
pub fn refuse_overwriting(
    inputs: &[(&str, &Path)],
    outputs: &[(&str, &Path)],
) -> Result<(), OutputClash> {
    let inputs: Vec<_> = inputs
        .iter()
        .map(|(option, path)| (*option, canonical(path)))
        .collect();
    let mut written: Vec<(&str, PathBuf)> = Vec::with_capacity(outputs.len());
    for (output, path) in outputs {
        let target = canonical(path);
        let clash = |what: String| OutputClash {
            output: output.to_string(),
            path: path.to_path_buf(),
            what,
        };
        if let Some((input, _)) = inputs.iter().find(|(_, input)| *input == target) {
            return Err(clash(format!("the {input} file")));
        }
        if let Some((other, _)) = written.iter().find(|(_, other)| *other == target) {
            return Err(clash(format!("written by {other} too")));
        }
        written.push((output, target));
    }
    Ok(())
}

/// `path` made absolute with its existing part resolved ([`std::fs::canonicalize`]) and the
/// rest appended as given (after `.` and `..` are applied to it).
fn canonical(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut existing = absolute.as_path();
    let mut rest = Vec::new();
    loop {
        if let Ok(resolved) = std::fs::canonicalize(existing) {
            let mut full = resolved;
            for part in rest.iter().rev() {
                match part {
                    std::path::Component::ParentDir => {
                        full.pop();
                    }
                    std::path::Component::CurDir => {}
                    other => full.push(other),
                }
            }
            return full;
        }
        match (existing.parent(), existing.components().next_back()) {
            (Some(parent), Some(last)) => {
                rest.push(last);
                existing = parent;
            }
            _ => return absolute,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_output_naming_an_input_another_way_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("slot.json");
        std::fs::write(&input, "{}").unwrap();
        let plan = PlanPaths::new(&dir.path().join("sub/../slot"), None);
        let error = refuse_overwriting(
            &[("--path", &input)],
            &[("--out", &plan.csv), ("--out", &plan.json)],
        )
        .unwrap_err();
        assert_eq!(error.output, "--out");
        assert!(error.to_string().contains("the --path file"), "{error}");
        let elsewhere = PlanPaths::new(&dir.path().join("runs/slot"), None);
        refuse_overwriting(&[("--path", &input)], &[("--out", &elsewhere.json)]).unwrap();
    }

    #[test]
    fn two_outputs_of_one_file_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let plan = PlanPaths::new(&dir.path().join("line"), None);
        let error =
            refuse_overwriting(&[], &[("--out", &plan.json), ("--html", &plan.json)]).unwrap_err();
        assert!(
            error.to_string().contains("written by --out too"),
            "{error}"
        );
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_to_an_input_is_the_input() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("robot.urdf");
        std::fs::write(&input, "<robot/>").unwrap();
        let link = dir.path().join("link.html");
        std::os::unix::fs::symlink(&input, &link).unwrap();
        let error = refuse_overwriting(&[("--robot", &input)], &[("--html", &link)]).unwrap_err();
        assert!(error.to_string().contains("the --robot file"), "{error}");
    }
}
