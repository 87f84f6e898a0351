//! Writing the `--html` page (the result files are written by `emg_planner::PlanFiles`), printing
//! to standard output, and the progress bars of long commands.

use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result};
use emg_io::write_atomically;

/// Writes `text` to `path` atomically, creating parent directories.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomically(path, text).with_context(|| format!("cannot write {}", path.display()))
}

/// A progress bar of `length` `things` (strokes, places), its stage as its message and the unit
/// it counts in as its prefix (set again per stage by [`crate::interrupt::Watched`]).
pub fn progress_bar(length: u64, things: &str) -> indicatif::ProgressBar {
    indicatif::ProgressBar::new(length)
        .with_style(
            indicatif::ProgressStyle::with_template(
                "{msg:>10} [{bar:40}] {pos}/{len} {prefix}, {elapsed}",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        )
        .with_prefix(things.to_string())
}

/// Set once standard output refused a line (its reader has gone): nothing more is printed.
static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);

/// Prints `line` and a newline to standard output (the binary's `println!`). A failure to print
/// is not an error of the command, which goes on writing its files: after a closed pipe (`emg
/// place … | head`) the rest of the output is dropped; any other failure is said once on
/// standard error.
pub fn print_line(line: std::fmt::Arguments<'_>) {
    if STDOUT_CLOSED.load(Ordering::Relaxed) {
        return;
    }
    let mut stdout = std::io::stdout().lock();
    if let Err(error) = stdout
        .write_fmt(line)
        .and_then(|()| stdout.write_all(b"\n"))
    {
        STDOUT_CLOSED.store(true, Ordering::Relaxed);
        if error.kind() != std::io::ErrorKind::BrokenPipe {
            eprintln!(
                "warning: cannot print to standard output ({error}); the files are still written"
            );
        }
    }
}

/// `n` and `noun`, in the plural unless `n` is 1 (`1 stroke`, `2 strokes`, `0 searches`): the
/// noun's last word takes `es` after `s`, `x`, `ch` or `sh`, else `s`.
pub fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        return format!("1 {noun}");
    }
    let es = ["s", "x", "ch", "sh"].iter().any(|end| noun.ends_with(end));
    format!("{n} {noun}{}", if es { "es" } else { "s" })
}

#[cfg(test)]
mod tests {
    use super::count;

    #[test]
    fn counts_are_singular_for_one_only() {
        assert_eq!(count(1, "stroke"), "1 stroke");
        assert_eq!(count(0, "stroke part"), "0 stroke parts");
        assert_eq!(count(2, "search"), "2 searches");
        assert_eq!(count(1, "search"), "1 search");
    }
}
