//! The UR5e's job programs exported both ways in memory, as `emg job --export urscript` and
//! `emg export --urscript servoj` write them (the native program of `emg_job::ur_program`; the
//! joint stream of `emg_io::export`, the default most `servoj` lines per program), and read back
//! against the plan by the independent reader `emg-ur-check`.

use std::path::Path;

use emg_io::{DriverProfile, ExportError, ExportFormat, ExportOptions, ExportRobot, ToolSwitching};
use emg_job::JobFile;
use emg_kinematics::Robot;
use emg_ur_check::{NativeReport, ServojReport, read_native, read_servoj};
use emg_verify::ReferenceModel;
use serde::{Deserialize, Serialize};

/// One job's programs on the UR5e, read back.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct UrRow {
    /// The job, as its row names it.
    pub job: String,
    /// The native program's `movej`, `movel` and `movep` lines.
    pub movej: usize,
    /// See `movej`.
    pub movel: usize,
    /// See `movej`.
    pub movep: usize,
    /// The native program's code lines per stroke.
    pub lines_per_stroke: f64,
    /// Largest distance (m) of the TCP from its stroke while the tool is on, as the reader
    /// interpolates the native moves, and the tolerance.
    pub worst_deviation_m: f64,
    /// See `worst_deviation_m`.
    pub tolerance_m: f64,
    /// Largest angle (degrees) of the tool axis from its stroke's normal while the tool is on,
    /// and the cone.
    pub worst_tool_angle_deg: f64,
    /// See `worst_tool_angle_deg`.
    pub cone_deg: f64,
    /// Length (m) the TCP covers with the tool on, and the length the plan draws.
    pub covered_m: f64,
    /// See `covered_m`.
    pub drawn_m: f64,
    /// Cartesian moves the controller follows, each on one branch of the inverse kinematics
    /// (a change of branch fails the reading).
    pub cartesian_moves: usize,
    /// The joint stream's programs and `servoj` targets.
    pub servoj_programs: usize,
    /// See `servoj_programs`.
    pub servoj_targets: usize,
    /// The longest stretch without rest (`servoj` targets) where it is more than one program
    /// holds by default (2,500): the stream is then written as one program, which the
    /// controller must run (`--max-servoj`); `None` where the default split fits.
    pub servoj_over_limit: Option<usize>,
    /// Why a program was not written or not read back, naming it; `None` where both were.
    pub failure: Option<String>,
}

/// The UR5e as the exports need it.
pub struct UrArm<'a> {
    /// Its kinematics.
    pub robot: &'a Robot,
    /// Its robot file.
    pub robot_file: &'a Path,
    /// Its driver profile (its controller's frames).
    pub profile: &'static DriverProfile,
    /// The independent checker.
    pub checker: &'a ReferenceModel,
}

/// `file` (the job `name`'s program) exported both ways and read back.
pub fn read_back(arm: &UrArm<'_>, name: &str, file: &JobFile) -> UrRow {
    let mut row = UrRow {
        job: name.to_string(),
        movej: 0,
        movel: 0,
        movep: 0,
        lines_per_stroke: 0.0,
        worst_deviation_m: 0.0,
        tolerance_m: file.constraints.line_tolerance_m,
        worst_tool_angle_deg: 0.0,
        cone_deg: file.constraints.theta_max_deg,
        covered_m: 0.0,
        drawn_m: 0.0,
        cartesian_moves: 0,
        servoj_programs: 0,
        servoj_targets: 0,
        servoj_over_limit: None,
        failure: None,
    };
    match native(arm, file) {
        Ok(report) => {
            row.movej = report.movej;
            row.movel = report.movel;
            row.movep = report.movep;
            row.lines_per_stroke = report.lines_per_stroke;
            row.worst_deviation_m = report.worst_deviation_m;
            row.worst_tool_angle_deg = report.worst_tool_angle_deg;
            row.covered_m = report.covered_m;
            row.drawn_m = report.drawn_m;
            row.cartesian_moves = report.cartesian_moves;
        }
        Err(why) => row.failure = Some(format!("{name}, native program: {why}")),
    }
    match servoj(arm, file) {
        Ok((report, over_limit)) => {
            row.servoj_programs = report.programs;
            row.servoj_targets = report.targets;
            row.servoj_over_limit = over_limit;
        }
        Err(why) => {
            let why = format!("{name}, servoj programs: {why}");
            row.failure = Some(
                row.failure
                    .map_or(why.clone(), |before| before + "; " + &why),
            );
        }
    }
    row
}

/// The native program written and read back.
fn native(arm: &UrArm<'_>, file: &JobFile) -> anyhow::Result<NativeReport> {
    let reference = arm.robot_file.display().to_string();
    let export = emg_job::ur_program::ur_program_export(
        file,
        arm.robot,
        &reference,
        Path::new("job.script"),
    )?;
    let [(_, bytes)] = export.files.as_slice() else {
        anyhow::bail!("{} files, not one program", export.files.len());
    };
    let script = std::str::from_utf8(bytes)?;
    Ok(read_native(
        script,
        file,
        arm.checker,
        file.settings.tool_output.on_high,
    )?)
}

/// The joint stream written and read back: at the default most `servoj` lines per program,
/// else, where a stretch without rest is longer, as one program (with that stretch's length).
fn servoj(arm: &UrArm<'_>, file: &JobFile) -> anyhow::Result<(ServojReport, Option<usize>)> {
    let reference = arm.robot_file.display().to_string();
    let (points, switches) = (file.points(), file.tool_switches());
    let output = file.settings.tool_output.to_string();
    let tool = ToolSwitching {
        switches: &switches,
        output: &output,
    };
    let robot = ExportRobot {
        file: &reference,
        reference: &reference,
        shipped: Some(arm.profile),
        kinematics: Some(arm.robot),
    };
    let timed = file.timed_points(&points, tool);
    let export_with = |max_servoj_lines: usize| {
        emg_io::export(
            timed,
            ExportFormat::UrScript,
            Path::new("job.script"),
            &robot,
            &ExportOptions {
                max_servoj_lines,
                ..ExportOptions::default()
            },
        )
    };
    let (export, over_limit) = match export_with(ExportOptions::default().max_servoj_lines) {
        Err(ExportError::TooLong { lines, .. }) => (export_with(usize::MAX)?, Some(lines)),
        written => (written?, None),
    };
    let scripts = export
        .files
        .iter()
        .map(|(_, bytes)| std::str::from_utf8(bytes))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((read_servoj(&scripts, file, arm.checker)?, over_limit))
}

/// The section of `jobs.md`: per program what was written and how it read back.
pub fn markdown(rows: &[UrRow]) -> String {
    let read = rows.iter().filter(|r| r.failure.is_none()).count();
    let mut md = format!(
        "\n## UR programs\n\n\
         Each program above exported both ways on the UR5e, in memory: the native program (`emg \
         job --export urscript`: `movej` between strokes, `movel` and blended `movep` along \
         them) and the joint stream (`--urscript servoj`: a target every 2 ms, at most 2,500 per \
         program, split where the arm rests; where a stretch without rest is longer, one program, \
         marked with that stretch's targets: a controller must run it with a higher \
         `--max-servoj`), both read back by the independent reader (`emg-ur-check`, which shares no \
         code with the exporters) against the plan: the native moves interpolated as the \
         URScript manual defines them and followed by the UR5e's closed-form inverse kinematics, \
         every configuration checked by the checker; every `servoj` target the plan's sample at \
         its time, within the joint limits. **{read} of {} read back both ways.** A change of \
         branch within a Cartesian move fails the reading: each row's Cartesian moves change \
         branch 0 times.\n\n\
         | job | movej / movel / movep | lines per stroke | worst TCP deviation (mm) / tolerance | worst tool angle (°) / cone | covered / drawn (m) | Cartesian moves (branch changes 0) | servoj programs / targets | read back |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        rows.len()
    );
    for r in rows {
        md.push_str(&format!(
            "| {} | {} / {} / {} | {:.1} | {:.4} / {:.1} | {:.2} / {:.0} | {:.3} / {:.3} | {} | {} / {}{} | {} |\n",
            r.job,
            r.movej,
            r.movel,
            r.movep,
            r.lines_per_stroke,
            r.worst_deviation_m * 1e3,
            r.tolerance_m * 1e3,
            r.worst_tool_angle_deg,
            r.cone_deg,
            r.covered_m,
            r.drawn_m,
            r.cartesian_moves,
            r.servoj_programs,
            r.servoj_targets,
            r.servoj_over_limit
                .map_or(String::new(), |lines| format!(" (one program: {lines} without rest)")),
            r.failure.as_deref().map_or("both", |_| "**no**"),
        ));
    }
    md
}
