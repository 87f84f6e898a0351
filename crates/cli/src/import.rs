//! `emg import-robot`: a vendor robot description (boxes, cylinders, STL/OBJ meshes) written as
//! a capsule URDF with a pen, and a report of what was fitted.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use emg_io::{
    DisabledBecause, ImportOptions, ImportedRobot, PEN_LINK, PEN_PROTRUSION_M,
    PEN_REACH_TOLERANCE_M, Pen, ToolLinkChoice, import_robot,
};
use emg_kinematics::{PairRule, Robot, srdf_beside};

use crate::output::write_text;

/// Options of `emg import-robot`.
#[derive(Debug, Args)]
pub struct ImportArgs {
    /// The vendor description (URDF).
    #[arg(value_name = "URDF")]
    pub file: PathBuf,
    /// The URDF to write (capsules as a cylinder plus two sphere caps; the pen's link is
    /// `pen_tip`, the TCP).
    #[arg(long, value_name = "URDF")]
    pub out: PathBuf,
    /// Where `package://NAME/...` meshes are: a directory of packages (DIR/NAME, or a directory
    /// below DIR whose package.xml names NAME), or NAME=DIR for one package. Repeatable.
    #[arg(long, value_name = "DIR|NAME=DIR")]
    pub package_path: Vec<emg_io::PackagePath>,
    /// The link the pen attaches to, along its z axis (default: the file's only leaf link; of
    /// several, `tool0`, else `flange`, as REP 199 names them).
    #[arg(long)]
    pub tool_link: Option<String>,
    /// The chain's base link, checked to reach the pen (default: the file's only root link).
    #[arg(long)]
    pub base_link: Option<String>,
    /// Pen length from the tool link's origin to the tip (m) (default: 0.1 m beyond the tool's
    /// collision geometry along its z axis, the links fixed to it included; 0.1 m when none lies
    /// ahead of its origin).
    #[arg(long, value_name = "M")]
    pub pen_length: Option<f64>,
    /// Pen radius (m).
    #[arg(long, value_name = "M", default_value_t = emg_io::Pen::default().radius_m)]
    pub pen_radius: f64,
    /// An SRDF file (MoveIt's) whose `disable_collisions` pairs are not checked for
    /// self-collision, besides adjacent links and links whose capsules overlap at mid-range.
    #[arg(long, value_name = "SRDF")]
    pub srdf: Option<PathBuf>,
    /// Most capsules fitted to one link (1 to 3): a loose single capsule is split along its
    /// axis when that saves a quarter of its volume.
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u8).range(1..=3))]
    pub max_capsules: u8,
}

/// Imports, checks that the planners read the result as a chain of six or seven joints ending in
/// the pen, writes it and prints the fit report.
pub fn run(args: &ImportArgs) -> Result<()> {
    let srdf = srdf_beside(&args.out);
    let limits = emg_planner::limits_file_beside(&args.out);
    let mut inputs = vec![("vendor URDF", args.file.as_path())];
    inputs.extend(args.srdf.as_deref().map(|file| ("--srdf", file)));
    emg_io::refuse_overwriting(
        &inputs,
        &[
            ("--out", args.out.as_path()),
            ("--out (its SRDF)", srdf.as_path()),
            ("--out (its joint limits)", limits.as_path()),
        ],
    )?;
    let options = ImportOptions {
        package_paths: args.package_path.clone(),
        tool_link: args.tool_link.clone(),
        base_link: args.base_link.clone(),
        pen_length_m: args.pen_length,
        pen_radius_m: args.pen_radius,
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
    write_text(&args.out, &imported.urdf)?;
    write_text(&srdf, &imported.srdf)?;
    write_text(&limits, &joint_limits_yaml(&args.file, &robot))?;
    println!("{}", report(&imported, &robot));
    if let Some(warning) = pen_warning(&imported) {
        eprintln!("warning: {warning}");
    }
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

/// Where the tool's collision geometry ends along the pen axis, in words.
fn reach_words(imported: &ImportedRobot) -> String {
    let reach = &imported.tool_reach;
    let quoted: Vec<String> = reach.links.iter().map(|l| format!("'{l}'")).collect();
    let links = match quoted.as_slice() {
        [only] => only.clone(),
        [tool, rest @ ..] => format!(
            "{tool} and what is fixed or merged to it ({})",
            rest.join(", ")
        ),
        [] => String::new(),
    };
    let ahead = |z: f64| {
        let side = if z < 0.0 { "behind" } else { "ahead of" };
        format!("{:.4} m {side}", z.abs())
    };
    if reach.reach_m.is_finite() {
        format!(
            "the collision geometry of {links} ends {} '{}''s origin along its z axis, its \
             capsules {} it",
            ahead(reach.reach_m),
            imported.tool_link,
            ahead(reach.capsule_reach_m)
        )
    } else {
        format!("{links} hold no collision geometry")
    }
}

/// The warning when the pen's tip does not reach beyond the tool's own geometry (a given
/// length), or beyond the capsules fitted to it (any length).
fn pen_warning(imported: &ImportedRobot) -> Option<String> {
    let reach = &imported.tool_reach;
    let tip = format!(
        "the pen's tip ({:.4} m from '{}''s origin{})",
        imported.pen.length_m,
        imported.tool_link,
        if imported.pen_length_given {
            ", --pen-length"
        } else {
            ""
        }
    );
    if !imported.pen_protrudes() {
        Some(format!(
            "{tip} does not protrude beyond the tool's collision geometry: {}, so the tool \
             touches the work surface before the tip; a pen longer than {:.4} m clears it and the \
             capsules fitted to it, e.g. --pen-length {:.3} (the default, {PEN_PROTRUSION_M} m \
             beyond it)",
            reach_words(imported),
            reach.reach_m.max(reach.capsule_reach_m),
            Pen::default_length_m(reach.reach_m)
        ))
    } else if !imported.pen_clears_capsules() {
        Some(format!(
            "{tip} protrudes beyond the tool's collision geometry but not beyond the capsules \
             fitted to it, which the planners and the checker test against the work surface: \
             {}; a pen longer than {:.4} m clears them",
            reach_words(imported),
            reach.capsule_reach_m
        ))
    } else {
        None
    }
}

/// The fit report: how the tool link and the pen were chosen; per link, what it held, the
/// capsules and their volume against it.
fn report(imported: &ImportedRobot, robot: &Robot) -> String {
    let mut text = String::new();
    if let ToolLinkChoice::Rep199 { leaves } = &imported.tool_link_choice {
        text += &format!(
            "tool link '{}': of the leaf links [{}], the tool frame REP 199 names (tool0, else \
             flange); name another with --tool-link\n",
            imported.tool_link,
            leaves.join(", ")
        );
    }
    let reach = reach_words(imported);
    let why = if imported.pen_length_given {
        format!("--pen-length; {reach}")
    } else if imported.tool_reach.reach_m >= PEN_REACH_TOLERANCE_M {
        format!("the default: {PEN_PROTRUSION_M} m beyond the tool's geometry; {reach}")
    } else {
        format!(
            "the default: nothing of the tool lies more than {} mm ahead of its origin; {reach}",
            PEN_REACH_TOLERANCE_M * 1e3
        )
    };
    text += &format!(
        "pen: {:.3} m from '{}''s origin along its z axis to the tip '{PEN_LINK}', radius {} m \
         ({why})\n",
        imported.pen.length_m, imported.tool_link, imported.pen.radius_m
    );
    text += &format!(
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
