//! `emg check PROGRAM.script`: a URScript program exported for the UR5e read back against the
//! job's program it was exported from by the independent reader ([`emg_ur_check`]), which shares
//! no code with the exporter: a native program's moves as the controller interpolates them, or
//! a `servoj` stream (all its parts) target by target.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};

use super::exported::Exported;
use emg_io::DriverProfile;
use emg_planner::ShippedRobot;

use crate::options::ChainArgs;
use crate::output::count;
use crate::robot;

/// The job's program a script `file` was exported from by default: the `.json` of its name, a
/// part's suffix `-partN` left out.
fn program_beside(file: &Path) -> PathBuf {
    let stem = file.with_extension("");
    let name = stem.to_string_lossy();
    let whole = match name.rfind("-part") {
        Some(at) if name[at + 5..].parse::<usize>().is_ok() => &name[..at],
        _ => &name[..],
    };
    PathBuf::from(format!("{whole}.json"))
}

/// The scripts of a `servoj` stream `file` belongs to, in order: `file` alone, or where it is a
/// part (`OUT-part1.script`), every part from the first while they exist.
fn stream_parts(file: &Path) -> Vec<PathBuf> {
    let name = file.with_extension("").to_string_lossy().into_owned();
    let Some(at) = name
        .rfind("-part")
        .filter(|&at| name[at + 5..].parse::<usize>().is_ok())
    else {
        return vec![file.to_path_buf()];
    };
    (1..)
        .map(|n| PathBuf::from(format!("{}-part{n}.script", &name[..at])))
        .take_while(|part| part.is_file())
        .collect()
}

/// Runs `emg check` on a URScript program `file`: prints what was read and `OK`, or fails naming
/// the line and what the arm would do wrong there. `program` and `robot` are `--program` and
/// `--robot`, `chain` the chain's ends.
pub fn check_script(
    file: &Path,
    program: Option<&Path>,
    robot: Option<&Path>,
    chain: &ChainArgs,
) -> Result<()> {
    let Exported {
        text,
        job,
        program_path,
        robot_path,
    } = Exported::read(
        file,
        &program_beside(file),
        program,
        robot,
        "URScript program",
    )?;
    let ur5e = ShippedRobot::by_path(&robot_path, &robot::data_dir())
        .and_then(|shipped| DriverProfile::for_shipped(shipped.name))
        .is_some_and(DriverProfile::has_ur_controller_frames);
    if !ur5e {
        bail!(
            "{} is a program for robot {}: URScript programs are read back for the shipped ur5e \
             only (its closed-form kinematics)",
            program_path.display(),
            robot_path.display()
        );
    }
    let (_, model) = chain.robot_and_checker(&robot_path)?;
    let fail = |e: emg_ur_check::ReadError| anyhow!("{} does not hold up: {e}", file.display());
    println!(
        "{}: URScript read back against {}, robot {}",
        file.display(),
        program_path.display(),
        robot_path.display()
    );
    if text.contains("servoj(") {
        let parts = stream_parts(file);
        let texts = parts
            .iter()
            .map(|part| {
                std::fs::read_to_string(part)
                    .with_context(|| format!("cannot read {}", part.display()))
            })
            .collect::<Result<Vec<String>>>()?;
        let scripts: Vec<&str> = texts.iter().map(String::as_str).collect();
        let report = emg_ur_check::read_servoj(&scripts, &job, &model).map_err(fail)?;
        println!(
            "  servoj: {} of {} targets every 2 ms ({:.3} s), each the program's sample at its \
             time; joint speeds ≤ {:.2} and accelerations ≤ {:.2} of the limits{}",
            count(report.programs, "program"),
            report.targets,
            report.duration_s,
            report.worst_speed_fraction,
            report.worst_acceleration_fraction,
            if report.home_checked {
                ", starting at the checked home"
            } else {
                ""
            }
        );
    } else {
        let on_level = job.settings.tool_output.on_high;
        let report = emg_ur_check::read_native(&text, &job, &model, on_level).map_err(fail)?;
        let constraints = &job.constraints;
        println!(
            "  native: {} moves ({} movej, {} movel, {} movep), {:.1} lines per stroke; {} \
             switched on and off where they start and end",
            report.movej + report.movel + report.movep,
            report.movej,
            report.movel,
            report.movep,
            report.lines_per_stroke,
            count(report.stroke_parts, "stroke part"),
        );
        println!(
            "  while the tool is on the TCP stays within {:.3} mm of its stroke (line {} mm) and \
             the tool axis within {:.1}° of its normal (cone {}°); {} followed on the branch \
             each starts on (largest joint step {:.4} rad per 0.1 mm), clear of the arm and the \
             part (least self-clearance {:.1} mm)",
            report.worst_deviation_m * 1e3,
            constraints.line_tolerance_m * 1e3,
            report.worst_tool_angle_deg,
            constraints.theta_max_deg,
            count(report.cartesian_moves, "Cartesian move"),
            report.worst_joint_step_rad,
            report.least_clearance_m * 1e3,
        );
        println!(
            "  the strokes covered {:.4} m of the {:.4} m the program draws",
            report.covered_m, report.drawn_m
        );
    }
    println!("OK");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_script_names_its_program_a_part_its_whole_one() {
        assert_eq!(
            program_beside(Path::new("out/drawing.job.script")),
            Path::new("out/drawing.job.json")
        );
        assert_eq!(
            program_beside(Path::new("drawing.job-part12.script")),
            Path::new("drawing.job.json")
        );
        assert_eq!(
            program_beside(Path::new("my-partner.script")),
            Path::new("my-partner.json")
        );
    }
}
