//! `emg import-robot`: a vendor robot description (boxes, cylinders, STL/OBJ meshes) written as
//! a capsule URDF with a pen, and a report of what was fitted.

use anyhow::{Context, Result};
use emg_io::{ImportOptions, ImportedRobot, PEN_LINK, Pen, import_robot};
use emg_kinematics::Robot;

use crate::args::ImportArgs;
use crate::output::write_text;

/// Imports, checks that the planners read the result as a 7-DoF chain ending in the pen, writes
/// it and prints the fit report.
pub fn run_import(args: &ImportArgs) -> Result<()> {
    let options = ImportOptions {
        package_paths: args.package_path.clone(),
        tool_link: args.tool_link.clone(),
        base_link: args.base_link.clone(),
        pen: Pen {
            length_m: args.pen_length,
            radius_m: args.pen_radius,
        },
        max_capsules_per_link: usize::from(args.max_capsules),
    };
    let imported = import_robot(&args.file, &options)
        .with_context(|| format!("cannot import {}", args.file.display()))?;
    let base = imported.base_link.clone();
    let robot = Robot::from_urdf_str(&imported.urdf, &base, PEN_LINK).with_context(|| {
        format!("the imported chain from '{base}' to the pen cannot be planned with")
    })?;
    write_text(&args.out, &imported.urdf)?;
    println!("{}", report(&imported, &robot));
    println!(
        "wrote {}; plan with: emg plan --robot {} --base-link {base} --tip-link {PEN_LINK} \
         --controller classical --limits <joint_limits.yaml>",
        args.out.display(),
        args.out.display()
    );
    Ok(())
}

/// The fit report: per link, what it held, the capsules and their volume against it.
fn report(imported: &ImportedRobot, robot: &Robot) -> String {
    let mut text = format!(
        "fitted capsules (pen of {} attached to '{}'; ratio = capsule volume / element volume):\n",
        PEN_LINK, imported.tool_link
    );
    for fit in &imported.fits {
        let ratio = fit.capsule_volume_m3() / fit.source_volume_m3;
        text += &format!(
            "  {:<16} {} capsule{}, ratio {:>5.2}  ({})\n",
            fit.link,
            fit.capsules.len(),
            if fit.capsules.len() == 1 { " " } else { "s" },
            ratio,
            fit.elements.join(", ")
        );
    }
    text += &format!(
        "the chain '{}' → '{}' has {} capsules and {} self-collision pairs (bodies at least 3 \
         links apart)",
        robot.base_link(),
        robot.tip_link(),
        robot.capsules().len(),
        robot.collision_pairs().len()
    );
    let mid = robot.forward(&robot.mid_range());
    if let Some(hit) = robot.first_collision(&mid, 0.0) {
        let capsules = robot.capsules();
        text += &format!(
            "\nwarning: at mid-range the fitted capsules of '{}' and '{}' overlap by {:.1} mm: \
             the fit is loose there, and every configuration near mid-range counts as a collision",
            capsules[hit.pair.first].link,
            capsules[hit.pair.second].link,
            -hit.clearance * 1e3
        );
    }
    text
}
