//! A job's program (an `emg-job/3` file): read back from a file, and its summary printed and
//! the program written and exported as `emg job` and `emg place` write it.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use emg_io::ExportFormat;
use emg_kinematics::Robot;

use crate::exporting::{self, UrScriptArgs};
use crate::job_input::JobInput;
use crate::output::{count, write_text};

/// Where `emg job` and `emg place` write a job's program: to `out` and, where `export` asks,
/// for the robot's own stack beside it (`urscript`'s options).
pub struct ProgramOutput<'a> {
    /// The program file (`--out`).
    out: &'a Path,
    /// The export's format and file (beside `out`), where asked.
    export: Option<(ExportFormat, PathBuf)>,
    /// How a URScript export is written.
    urscript: &'a UrScriptArgs,
}

impl<'a> ProgramOutput<'a> {
    /// The program written to `out`, exported as `export` asks.
    pub fn new(out: &'a Path, export: Option<ExportFormat>, urscript: &'a UrScriptArgs) -> Self {
        let export = export.map(|format| (format, exporting::beside_program(out, format)));
        Self {
            out,
            export,
            urscript,
        }
    }

    /// The export's file as an overwrite refusal names it, where one is asked for.
    pub fn exported(&self) -> (&'static str, Option<&Path>) {
        (
            "--export",
            self.export.as_ref().map(|(_, path)| path.as_path()),
        )
    }

    /// Refuses, before anything is planned, a run that would write `--out` or one of `outputs`
    /// (option and file where asked, in that order) over one of `input`'s files or over one
    /// another, or export the program for a robot it cannot run on.
    pub fn refuse(&self, input: &JobInput, outputs: &[(&str, Option<&Path>)]) -> Result<()> {
        let mut written = vec![("--out", self.out)];
        written.extend(
            outputs
                .iter()
                .filter_map(|&(option, path)| path.map(|path| (option, path))),
        );
        emg_io::refuse_overwriting(&input.files(), &written)?;
        let format = self.export.as_ref().map(|&(format, _)| format);
        exporting::refuse_program_export(format, self.urscript, &input.robot)
    }
}

/// Prints `file`'s summary, writes it where `output` says (the arm `robot` read from
/// `robot_file`).
pub fn write_program(
    file: &emg_job::JobFile,
    output: &ProgramOutput<'_>,
    robot_file: &Path,
    robot: &Robot,
) -> Result<()> {
    print_summary(file);
    write_text(output.out, &(serde_json::to_string(file)? + "\n"))?;
    println!("wrote {}", output.out.display());
    if let Some((format, _)) = output.export {
        let text = exporting::export_program(
            file,
            format,
            output.urscript,
            output.out,
            robot_file,
            robot,
        )?;
        println!("{text}");
    }
    Ok(())
}

/// The job program in `file`, when it is a job's program (refused where it is one of another
/// version).
pub fn read_job_file(file: &Path) -> Result<Option<emg_job::JobFile>> {
    let text =
        std::fs::read_to_string(file).with_context(|| format!("cannot read {}", file.display()))?;
    if !emg_job::JobFile::is_job(&text) {
        return Ok(None);
    }
    let job =
        emg_job::JobFile::parse(&text).map_err(|e| anyhow::anyhow!("{} {e}", file.display()))?;
    Ok(Some(job))
}

/// Prints a planned program's summary: strokes, length drawn, travel, times, what was left out.
pub fn print_summary(file: &emg_job::JobFile) {
    let s = &file.summary;
    println!(
        "{}: {} complete, {} resumed after a reconfiguration, {} short",
        count(file.strokes.len(), "stroke"),
        s.complete,
        s.resumed,
        s.short
    );
    let (merged, into) = file.ordering.merged();
    if merged > 0 {
        println!(
            "{} merged into {into}, meeting end to end",
            count(merged, "stroke")
        );
    }
    println!(
        "pen down {:.4} m of {:.4} m ({:.1} %); pen-up travel {:.3} m in the order drawn ({:.3} m as given)",
        s.drawn_m,
        s.total_m,
        100.0 * s.drawn_m / s.total_m.max(f64::MIN_POSITIVE),
        s.travel_m,
        s.travel_given_m
    );
    println!(
        "program {:.2} s ({:.2} s pen down, {:.2} s pen up; {}, {} found by the sampling \
         planner); planned in {:.2} s ({})",
        s.duration_s,
        s.pen_down_s,
        s.pen_up_s,
        count(s.straight_moves, "straight move"),
        s.sampled_moves,
        s.planning_s,
        count(s.searches, "search")
    );
    println!(
        "at the arm's limits no program drawing these parts lasts less than {:.2} s ({:.2} s pen \
         down, {:.2} s pen up): this one takes {:.2}×",
        s.least_pen_down_s + s.least_pen_up_s,
        s.least_pen_down_s,
        s.least_pen_up_s,
        s.duration_s / (s.least_pen_down_s + s.least_pen_up_s).max(f64::MIN_POSITIVE)
    );
    for stroke in &file.strokes {
        let undrawn = stroke
            .unreached
            .iter()
            .zip(&stroke.unreached_at)
            .zip(&stroke.unreached_causes);
        for ((stretch, at), cause) in undrawn {
            println!(
                "  stroke {}: {:.4} m not drawn from {:.4} m along it, at ({:.3}, {:.3}, {:.3}): {cause}",
                stroke.stroke,
                stretch.length_m(),
                stretch.from_s,
                at[0],
                at[1],
                at[2]
            );
        }
    }
    if file.home.is_none() {
        println!(
            "  the robot has no home: the program starts above its first stroke and ends above \
             its last (give --home)"
        );
    } else if !s.ends_at_home {
        println!(
            "  no free move back to the job's home was found: the program ends above its last stroke"
        );
    }
    for stroke in &file.strokes {
        for why in &stroke.parts_left_out {
            println!("  stroke {}, {why}", stroke.stroke);
        }
    }
}
