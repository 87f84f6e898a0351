//! The corpus's drawings fetched from the registries at pinned versions, into a cache directory
//! (never committed: their licences are their own): icon sets from npm, Hershey's fonts from
//! PyPI, rendered to strokes by the package's own code.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::Context;

/// An npm package of SVG icons: its name, pinned version, and the folder of its icons.
pub struct IconSet {
    /// The set's name in the table.
    pub name: &'static str,
    /// The npm package.
    pub package: &'static str,
    /// Its pinned version.
    pub version: &'static str,
}

/// The icon sets: every icon of each.
pub const ICON_SETS: [IconSet; 2] = [
    IconSet {
        name: "lucide",
        package: "lucide-static",
        version: "0.469.0",
    },
    IconSet {
        name: "bootstrap",
        package: "bootstrap-icons",
        version: "1.11.3",
    },
];

/// The PyPI package of Hershey's fonts and its pinned version.
pub const HERSHEY: (&str, &str) = ("Hershey-Fonts", "2.1.0");

/// The Hershey fonts set in the corpus: simplex, duplex, script, serif, cursive, gothic.
pub const FONTS: [&str; 6] = [
    "futural",
    "rowmans",
    "scripts",
    "timesr",
    "cursive",
    "gothiceng",
];

/// The lines of text set in each font.
pub const LINES: [&str; 4] = [
    "Sphinx of black quartz, judge my vow",
    "THE FIVE BOXING WIZARDS JUMP QUICKLY",
    "0123456789 (+-*/=) ?!&%",
    "Extreme motion along lines and paths",
];

fn run(command: &mut Command) -> anyhow::Result<()> {
    let shown = format!("{command:?}");
    let status = command
        .status()
        .with_context(|| format!("cannot run {shown}"))?;
    anyhow::ensure!(status.success(), "{shown} failed ({status})");
    Ok(())
}

/// The icons of `set` (their files, in name order), fetched into `cache` unless there already.
pub fn icons(set: &IconSet, cache: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let dir = cache.join(format!("{}-{}", set.package, set.version));
    let icons = dir.join("package/icons");
    if !icons.is_dir() {
        std::fs::create_dir_all(&dir)?;
        let spec = format!("{}@{}", set.package, set.version);
        run(Command::new("npm")
            .args(["pack", &spec, "--silent", "--pack-destination"])
            .arg(&dir)
            .stdout(Stdio::null()))?;
        let archive = dir.join(format!("{}-{}.tgz", set.package, set.version));
        run(Command::new("tar")
            .arg("xzf")
            .arg(&archive)
            .arg("-C")
            .arg(&dir))?;
        std::fs::remove_file(&archive)?;
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(&icons)
        .with_context(|| format!("reading {}", icons.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.extension().is_some_and(|ext| ext == "svg"))
        .collect();
    files.sort();
    Ok(files)
}

/// Renders every line of [`LINES`] in every font of [`FONTS`] with the Hershey-Fonts package
/// (its `strokes_for_text`), as JSON: `{font: [[stroke, …] per line]}`, each stroke a list of
/// `[x, y]` points (font units, y up).
const RENDER: &str = r#"
import json, sys
sys.path.insert(0, sys.argv[1])
from HersheyFonts import HersheyFonts
fonts, lines = sys.argv[3].split(","), json.loads(sys.argv[4])
out = {}
for name in fonts:
    font = HersheyFonts()
    font.load_default_font(name)
    out[name] = [[[list(p) for p in stroke] for stroke in font.strokes_for_text(line)]
                 for line in lines]
json.dump(out, open(sys.argv[2], "w"))
"#;

/// One font's lines: per line, its strokes, each a list of points (font units, y up).
pub type FontLines = Vec<Vec<Vec<[f64; 2]>>>;

/// The lines of text of [`LINES`] in each font of [`FONTS`], rendered by the Hershey-Fonts
/// package fetched from PyPI into `cache` unless there already.
pub fn hershey_lines(cache: &Path) -> anyhow::Result<Vec<(String, FontLines)>> {
    let (package, version) = HERSHEY;
    let dir = cache.join(format!("{package}-{version}"));
    let unpacked = dir.join("unpacked");
    let rendered = dir.join("lines.json");
    if !unpacked.join("HersheyFonts").is_dir() {
        std::fs::create_dir_all(&dir)?;
        run(Command::new("python3")
            .args(["-m", "pip", "download", "--quiet", "--no-deps", "--dest"])
            .arg(&dir)
            .arg(format!("{package}=={version}")))?;
        let wheel = std::fs::read_dir(&dir)?
            .filter_map(|entry| entry.ok().map(|e| e.path()))
            .find(|path| path.extension().is_some_and(|ext| ext == "whl"))
            .context("pip downloaded no wheel")?;
        run(Command::new("python3")
            .args(["-m", "zipfile", "-e"])
            .arg(&wheel)
            .arg(&unpacked))?;
    }
    run(Command::new("python3")
        .args(["-c", RENDER])
        .arg(&unpacked)
        .arg(&rendered)
        .arg(FONTS.join(","))
        .arg(serde_json::to_string(&LINES)?))?;
    let text = std::fs::read_to_string(&rendered)?;
    let mut all: std::collections::BTreeMap<String, FontLines> = serde_json::from_str(&text)?;
    Ok(FONTS
        .iter()
        .filter_map(|font| all.remove(*font).map(|lines| (font.to_string(), lines)))
        .collect())
}
