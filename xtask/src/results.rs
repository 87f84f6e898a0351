//! The shipped result files under `docs/results/`: read back into their typed records, for
//! every shipped arm. The evaluations read their own and each other's files through it, and
//! `cargo xtask report` assembles the sections they write from them.

use std::path::Path;

use anyhow::Context;
use emg_planner::{SHIPPED_ROBOTS, SeedSource, ShippedRobot};
use serde::de::DeserializeOwned;

use crate::workspace;

/// The typed record in the result file `path`.
pub(crate) fn read<T: DeserializeOwned>(path: &Path) -> anyhow::Result<T> {
    let text = std::fs::read_to_string(path).with_context(|| {
        format!(
            "reading {} (run the command that writes it first)",
            path.display()
        )
    })?;
    serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))
}

/// Every shipped arm with a result file `name` under `results` (the FR3's at the top, the
/// others' in their sub-directories), with the typed record that file holds ([`read`]).
pub(crate) fn shipped_results<T: DeserializeOwned>(
    results: &Path,
    name: &str,
) -> anyhow::Result<Vec<(ShippedRobot, T)>> {
    SHIPPED_ROBOTS
        .into_iter()
        .map(|shipped| (shipped, results.join(shipped.data_subdir()).join(name)))
        .filter(|(_, path)| path.exists())
        .map(|(shipped, path)| Ok((shipped, read(&path)?)))
        .collect()
}

/// The name of the DP seed in result files.
pub(crate) fn dp() -> &'static str {
    SeedSource::Dp.name()
}

/// Where a table an evaluation writes over every shipped arm is shown: in its section of
/// `docs/results.md` and between its markers in a summary page.
pub(crate) struct SummaryPlace {
    /// The page the table is copied into, relative to the workspace root (`README.md` or
    /// [`workspace::RESULTS_SUMMARY`]).
    pub page: &'static str,
    /// The marker line the table follows in `page`.
    pub start: &'static str,
    /// The marker line the table precedes in `page`.
    pub end: &'static str,
    /// The section of `docs/results.md` before the table: its heading and the words that
    /// introduce the table.
    pub intro: &'static str,
}

impl SummaryPlace {
    /// A table's place in the results summary ([`workspace::RESULTS_SUMMARY`]) between the
    /// markers `start` and `end`, shown in `docs/results.md` after `intro`.
    pub const fn in_results_summary(
        start: &'static str,
        end: &'static str,
        intro: &'static str,
    ) -> Self {
        Self {
            page: workspace::RESULTS_SUMMARY,
            start,
            end,
            intro,
        }
    }

    /// The section of `docs/results.md` that shows `table`.
    pub fn section(&self, table: &str) -> String {
        format!("{}{table}\n", self.intro)
    }

    /// Copies `table` between the markers in the page.
    pub fn copy_to_page(&self, table: &str) -> anyhow::Result<()> {
        workspace::replace_section(self.page, self.start, self.end, table)
    }
}
