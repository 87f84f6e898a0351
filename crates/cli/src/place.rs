//! `emg place`: where to put a job's part so the arm draws the most of it (`emg_job::place_job`):
//! progress bars per stage, the certified places as a table, the program at the chosen place,
//! the heat map, the chosen place as a job file's transform and the program's export.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use emg_job::{
    JOB_FORMAT_VERSION, JobSpec, Moving, PlaceError, PlaceSettings, Placement, Region, Score,
    placement_map,
};

use crate::exporting;
use crate::interrupt::{Interrupt, Watched};
use crate::job_input::{JobInput, Ready};
use crate::output::{progress_bar, write_text};
use crate::program::{ProgramOutput, write_program};

/// Options of `emg place`.
#[derive(Debug, Args)]
pub struct PlaceArgs {
    /// The job and how it is planned.
    #[command(flatten)]
    pub input: JobInput,
    /// What moves: `part` (default: the part on its surface, turned about its normal through
    /// its centre) or `base` (the robot's base on its mount, turned about its z axis; the part
    /// and the cell stay).
    #[arg(
        long = "move",
        value_name = "WHAT",
        value_enum,
        hide_possible_values = true,
        default_value = "part"
    )]
    pub moving: Moving,
    /// The shifts searched along x (the part's: the base's x laid on the surface; the base's
    /// own): MIN,MAX (m).
    #[arg(long, value_name = "MIN,MAX", value_parser = parse_range, allow_hyphen_values = true, default_value = "-0.15,0.15")]
    pub x: [f64; 2],
    /// The shifts searched along y (the part's: normal × x; the base's own): MIN,MAX (m).
    #[arg(long, value_name = "MIN,MAX", value_parser = parse_range, allow_hyphen_values = true, default_value = "-0.15,0.15")]
    pub y: [f64; 2],
    /// The shifts searched along the normal (the part's toward the tool's side; the base's z,
    /// up): MIN,MAX (m).
    #[arg(long, value_name = "MIN,MAX", value_parser = parse_range, allow_hyphen_values = true, default_value = "-0.03,0.03")]
    pub z: [f64; 2],
    /// The turns searched (the part's about its surface normal through its centre, the base's
    /// about its z axis): MIN,MAX (degrees).
    #[arg(long, value_name = "MIN,MAX", value_parser = parse_range, allow_hyphen_values = true, default_value = "-90,90")]
    pub rotation: [f64; 2],
    /// Grid positions along each of x and y.
    #[arg(long, value_name = "N", default_value_t = PlaceSettings::default().positions)]
    pub positions: usize,
    /// Grid heights along the normal.
    #[arg(long, value_name = "N", default_value_t = PlaceSettings::default().heights)]
    pub heights: usize,
    /// Grid turns.
    #[arg(long, value_name = "N", default_value_t = PlaceSettings::default().rotations)]
    pub rotations: usize,
    /// Best refined places planned as full jobs at least; the next ones too while one scores
    /// above the share the best planned place draws.
    #[arg(long, value_name = "N", default_value_t = PlaceSettings::default().certify)]
    pub certify: usize,
    /// What screens a place: `bound` (default: each stroke's reachability bound, how far one
    /// motion could go along it) or `point-ik` (the share of stroke points with an IK solution
    /// in the cone, each on its own, as reachability studies score).
    #[arg(long, value_enum, hide_possible_values = true, default_value = "bound")]
    pub score: Score,
    /// The program planned at the chosen place (an emg-job/3 file; missing parent directories
    /// are created, as for every file written).
    #[arg(long, value_name = "FILE", default_value = "placed.json")]
    pub out: PathBuf,
    /// Also write the heat map (SVG): each position's best score over the heights and turns,
    /// the certified places ranked.
    #[arg(long, value_name = "FILE")]
    pub map: Option<PathBuf>,
    /// Also write the job at the chosen place: a job file (docs/jobs.md) with the strokes as
    /// read and the place as its `transform`, for `emg job`.
    #[arg(long, value_name = "FILE")]
    pub job_out: Option<PathBuf>,
    /// Also export the program for a robot's own stack, as `emg job --export` does:
    /// `ros2-mcap`, `urscript`, `rapid` or `krl`, written beside `--out` (its extension
    /// `.mcap`, `.script`, `.mod` or a KRL program's `.src` and `.dat`; see
    /// docs/robot-export.md).
    #[arg(long, value_name = "FORMAT", value_parser = exporting::parse_format)]
    pub export: Option<emg_io::ExportFormat>,
    /// How a URScript export is written.
    #[command(flatten)]
    pub urscript: exporting::UrScriptArgs,
}

/// Parses a range searched, `MIN,MAX`.
fn parse_range(value: &str) -> Result<[f64; 2], String> {
    let numbers: Vec<f64> = value
        .split(',')
        .map(|part| part.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{value}' is not MIN,MAX (two numbers)"))?;
    match numbers[..] {
        [low, high] => Ok([low, high]),
        _ => Err(format!("'{value}' is not MIN,MAX (two numbers)")),
    }
}

/// Searches the region, prints the certified places and writes the outputs; `interrupt` stops
/// the search, and then nothing is written.
pub fn run(args: &PlaceArgs, interrupt: &Interrupt) -> Result<()> {
    let input = &args.input;
    let program = ProgramOutput::new(&args.out, args.export, &args.urscript);
    program.refuse(
        input,
        &[
            ("--map", args.map.as_deref()),
            ("--job-out", args.job_out.as_deref()),
            program.exported(),
        ],
    )?;
    let region = Region {
        moving: args.moving,
        x_m: args.x,
        y_m: args.y,
        z_m: args.z,
        rotation_deg: args.rotation,
    };
    let settings = PlaceSettings {
        positions: args.positions,
        heights: args.heights,
        rotations: args.rotations,
        certify: args.certify,
        ..PlaceSettings::default()
    };
    region.validate()?;
    settings.validate()?;
    let Ready { job, planner } = input.ready()?;
    let watch = Watched::new(progress_bar(0, "places"), interrupt);
    let placed = planner.place(&job, &region, &settings, args.score, &watch);
    let placement = watch.outcome(placed, |e| matches!(e, PlaceError::Stopped(_)))?;
    print_places(&placement);
    let best = placement.best();
    let chosen_program = best
        .program
        .as_deref()
        .expect("the chosen place was planned");
    write_program(chosen_program, &program, &input.robot, planner.robot())?;
    if let Some(path) = &args.map {
        write_text(path, &placement_map(&placement, args.score))?;
        println!("wrote {}", path.display());
    }
    if let Some(path) = &args.job_out {
        let spec = JobSpec {
            version: JOB_FORMAT_VERSION,
            strokes: job.strokes.iter().map(|s| s.spec().clone()).collect(),
            settings: job.settings.clone(),
            home: job
                .home
                .map(|q| q.as_slice()[..planner.robot().dof()].to_vec()),
            transform: Some(placement.transform()),
        };
        write_text(path, &(serde_json::to_string_pretty(&spec)? + "\n"))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The table of certified places and the chosen one's transform.
fn print_places(placement: &Placement) {
    println!(
        "screened {} places, refined {}, planned {}",
        placement.screened.len(),
        placement.refined.len(),
        placement.certified.len()
    );
    println!(
        "rank  x (m)   y (m)   z (m)   turn (°)  score  drawn (m)  of (m)  complete  program (s)"
    );
    for (rank, place) in placement.certified.iter().enumerate() {
        let p = &place.scored.place;
        println!(
            "{:>4}  {:>6}  {:>6}  {:>6}  {:>8}  {:>5.3}  {:>9.4}  {:>6.4}  {:>4} / {:<3}  {:>10.2}",
            rank + 1,
            rounded(p.x_m, 3),
            rounded(p.y_m, 3),
            rounded(p.z_m, 3),
            rounded(p.rotation_deg, 1),
            place.scored.score,
            place.drawn_m,
            place.total_m,
            place.complete,
            place.strokes,
            place.duration_s
        );
    }
    let best = placement.best();
    let place = &best.scored.place;
    // A place on the region's edge that leaves some of the drawing undrawn may be bettered past
    // that edge.
    if best.drawn_m < best.total_m - emg_job::SAME_LENGTH_M {
        for edge in placement.region.edges_of(place) {
            println!(
                "the best place is on the edge of --{} (its {}, {}): a larger range may draw more",
                edge.range,
                if edge.at_maximum {
                    "maximum"
                } else {
                    "minimum"
                },
                edge.value
            );
        }
    }
    let what = match placement.frame.moving {
        Moving::Part => "the part",
        Moving::Base => "the base",
    };
    // The place to 0.1 mm and 0.1°; the transforms below in full (the shortest text that reads
    // back to the same number), so that what is printed reproduces the place.
    println!(
        "chosen: {what} shifted ({}, {}, {}) m, turned {}°",
        rounded(place.x_m, 4),
        rounded(place.y_m, 4),
        rounded(place.z_m, 4),
        rounded(place.rotation_deg, 1)
    );
    let written = |t: &emg_job::Transform| {
        format!(
            "translation_m [{}, {}, {}], rpy [{}, {}, {}]",
            t.translation_m[0],
            t.translation_m[1],
            t.translation_m[2],
            t.rpy[0],
            t.rpy[1],
            t.rpy[2]
        )
    };
    if let Some(pose) = placement.base_pose() {
        println!(
            "  the base's new pose in its present frame: {}",
            written(&pose)
        );
        println!(
            "  the job's and the scene's transform in the moved base's frame: {}",
            written(&placement.transform())
        );
    } else {
        println!("  the job's transform: {}", written(&placement.transform()));
    }
}

/// `value` to `decimals` decimals, a value that rounds to zero written without a sign.
fn rounded(value: f64, decimals: usize) -> String {
    let scale = 10f64.powi(i32::try_from(decimals).unwrap_or(i32::MAX));
    // Adding +0.0 turns a -0.0 into 0.0.
    format!("{:.*}", decimals, (value * scale).round() / scale + 0.0)
}

#[cfg(test)]
mod tests {
    use super::rounded;

    #[test]
    fn places_are_printed_rounded_without_a_negative_zero() {
        assert_eq!(
            rounded(-0.000_000_000_000_000_006_938_893_903_907_228, 4),
            "0.0000"
        );
        assert_eq!(rounded(-0.03, 4), "-0.0300");
        assert_eq!(rounded(0.123_456, 4), "0.1235");
        assert_eq!(rounded(-22.54, 1), "-22.5");
    }
}
