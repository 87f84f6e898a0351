//! `emg import-robot`: a vendor robot description (boxes, cylinders, STL/OBJ meshes) written as
//! a capsule URDF with a pen, and a report of what was fitted.

use anyhow::{Context, Result};
use emg_io::{DisabledBecause, ImportOptions, ImportedRobot, PEN_LINK, Pen, import_robot};
use emg_kinematics::{PairRule, Robot, srdf_beside};

use crate::args::ImportArgs;
use crate::output::write_text;

/// Imports, checks that the planners read the result as a chain of six or seven joints ending in
/// the pen, writes it and prints the fit report.
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
        srdf: args.srdf.clone(),
    };
    let imported = import_robot(&args.file, &options)
        .with_context(|| format!("cannot import {}", args.file.display()))?;
    let base = imported.base_link.clone();
    let rule = PairRule::AllExcept(
        imported
            .disabled
            .iter()
            .map(|(a, b, _)| (a.clone(), b.clone()))
            .collect(),
    );
    let robot = Robot::from_urdf_str_with_rule(&imported.urdf, &base, PEN_LINK, rule)
        .with_context(|| {
            format!("the imported chain from '{base}' to the pen cannot be planned with")
        })?;
    let srdf = srdf_beside(&args.out);
    let limits = emg_planner::limits_file_beside(&args.out);
    write_text(&args.out, &imported.urdf)?;
    write_text(&srdf, &imported.srdf)?;
    write_text(&limits, &joint_limits_yaml(&args.file, &robot))?;
    println!("{}", report(&imported, &robot));
    println!(
        "wrote {}, {} and {} (velocities from the vendor file, acceleration and jerk limits \
         assumed: replace them with the vendor's values); plan with: emg plan --robot {}",
        args.out.display(),
        srdf.display(),
        limits.display(),
        args.out.display()
    );
    Ok(())
}

/// The MoveIt joint_limits.yaml of an imported robot: the vendor file's velocity limits, and
/// acceleration and jerk limits marked as assumed (a URDF holds none).
fn joint_limits_yaml(vendor: &std::path::Path, robot: &Robot) -> String {
    let header = format!(
        "Joint limits written by `emg import-robot` from {}, in MoveIt's joint_limits.yaml \
         layout.\nmax_velocity: the vendor file's <limit velocity> of each joint.\n\
         max_acceleration {} rad/s² and max_jerk {} rad/s³: ASSUMED, conservative values \
         (docs/robot-import.md), since a URDF holds no acceleration or jerk limits; replace them \
         with the vendor's published values.",
        vendor.display(),
        emg_timing::ASSUMED_ACCELERATION_RAD_S2,
        emg_timing::ASSUMED_JERK_RAD_S3
    );
    emg_timing::DynamicLimits::assumed(robot).to_yaml(robot, &header)
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
    let count = |why: DisabledBecause| imported.disabled.iter().filter(|d| d.2 == why).count();
    let colliding: Vec<String> = imported
        .disabled
        .iter()
        .filter(|d| d.2 == DisabledBecause::CollidingAtMidRange)
        .map(|(a, b, _)| format!("{a}–{b}"))
        .collect();
    if !imported.held_joints.is_empty() {
        text += &format!(
            "joints off the chain held at 0 (their links' geometry merged): {}\n",
            imported.held_joints.join(", ")
        );
    }
    text += &format!(
        "self-collision rule: every two links that move relative to each other, except {} \
         adjacent pairs, {} pairs whose capsules overlap at mid-range{} and {} pairs of the given \
         SRDF: {} capsule pairs checked on the chain '{}' → '{}' ({} capsules)",
        count(DisabledBecause::Adjacent),
        count(DisabledBecause::CollidingAtMidRange),
        if colliding.is_empty() {
            String::new()
        } else {
            format!(" ({})", colliding.join(", "))
        },
        count(DisabledBecause::Given),
        robot.collision_pairs().len(),
        robot.base_link(),
        robot.tip_link(),
        robot.capsules().len(),
    );
    text
}
