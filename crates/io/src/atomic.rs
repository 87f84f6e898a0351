//! The workspace's one way of writing a file (never half-written), and of claiming a journal
//! directory for one job.

use std::io::Write;
use std::path::Path;

/// Suffix of the staging files [`write_atomically`] renames into place.
const PARTIAL_SUFFIX: &str = ".partial";

/// Writes `bytes` to `path` through a uniquely named `<file name>.<random>.partial` sibling
/// (synced, then renamed into place), creating missing parent directories, so an interrupted
/// write never leaves a half-written file at `path`, and several processes writing the same
/// file at once (job-array elements on shared storage) each rename a whole file of their own.
/// A crash between the write and the rename leaves only the `.partial` file. The file gets the
/// permissions any new file gets (read-write for all, less the process's umask: 0644 under
/// the usual umask 022), not a temporary file's 0600.
pub fn write_atomically(path: impl AsRef<Path>, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
    let path = path.as_ref();
    let parent = match path.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(parent) => {
            std::fs::create_dir_all(parent)?;
            parent
        }
        None => Path::new("."),
    };
    let mut prefix = path
        .file_name()
        .ok_or_else(|| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("{} names no file", path.display()),
            )
        })?
        .to_os_string();
    prefix.push(".");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(PARTIAL_SUFFIX);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // The kernel clears the umask's bits of the mode a file is created with.
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut staging = builder.tempfile_in(parent)?;
    staging.write_all(bytes.as_ref())?;
    staging.as_file().sync_all()?;
    staging.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// A journal directory that cannot be opened, or was made for other work.
#[derive(Debug, thiserror::Error)]
pub enum JournalError {
    /// Reading or writing the journal failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory.
        path: String,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The journal's identity file holds another job's identity.
    #[error("{path} was made for other work; remove {dir} to start over")]
    Mismatch {
        /// The identity file.
        path: String,
        /// The journal directory.
        dir: String,
    },
}

/// Opens the journal directory `dir` (created if missing) for the job whose identity (task set,
/// settings; any text that differs when the results would) is `identity`: its `journal.json`
/// is written when absent and must equal `identity` otherwise. Elements of a job array that start
/// at once may all find no identity file: each writes it whole, then each reads back what is
/// there, so an element of another job never joins the journal.
pub fn open_journal(dir: &Path, identity: &str) -> Result<(), JournalError> {
    let io = |path: &Path| {
        let path = path.display().to_string();
        move |source| JournalError::Io { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let path = dir.join("journal.json");
    if !path.exists() {
        write_atomically(&path, identity).map_err(io(&path))?;
    }
    if std::fs::read_to_string(&path).map_err(io(&path))? != identity {
        return Err(JournalError::Mismatch {
            path: path.display().to_string(),
            dir: dir.display().to_string(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn writes_into_new_directories_and_leaves_no_partial_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a/b/file.json");
        write_atomically(&path, b"one").unwrap();
        write_atomically(&path, b"two").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        assert_eq!(names(&dir.path().join("a/b")), ["file.json"]);
    }

    #[test]
    fn concurrent_writers_of_one_file_leave_one_whole_version() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("journal.json");
        let versions: Vec<Vec<u8>> = (0..8u8).map(|k| vec![b'a' + k; 1 << 16]).collect();
        let versions = &versions;
        std::thread::scope(|scope| {
            for version in versions {
                let path = &path;
                scope.spawn(move || {
                    for _ in 0..20 {
                        write_atomically(path, version).unwrap();
                        let read = std::fs::read(path).unwrap();
                        assert!(versions.contains(&read), "a torn file was read");
                    }
                });
            }
        });
        assert!(versions.contains(&std::fs::read(&path).unwrap()));
        assert_eq!(names(dir.path()), ["journal.json"]);
    }

    #[test]
    fn a_journal_opens_for_its_own_job_only() {
        let dir = tempfile::tempdir().unwrap();
        let journal = dir.path().join("journal");
        open_journal(&journal, "{\"set\": 1}\n").unwrap();
        open_journal(&journal, "{\"set\": 1}\n").unwrap();
        let error = open_journal(&journal, "{\"set\": 2}\n").unwrap_err();
        assert!(matches!(error, JournalError::Mismatch { .. }), "{error}");
        assert!(error.to_string().contains("remove"), "{error}");
    }

    #[cfg(unix)]
    #[test]
    fn written_files_get_the_permissions_of_new_files() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let (plain, atomic) = (dir.path().join("plain"), dir.path().join("atomic"));
        std::fs::write(&plain, b"x").unwrap();
        write_atomically(&atomic, b"x").unwrap();
        let mode = |path: &Path| std::fs::metadata(path).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&atomic), mode(&plain));
    }

    #[test]
    fn a_path_without_a_file_name_is_refused() {
        let error = write_atomically(Path::new("/"), b"x").unwrap_err();
        assert_eq!(error.kind(), std::io::ErrorKind::InvalidInput);
    }
}
