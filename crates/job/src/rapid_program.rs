//! A job's program as one RAPID module for an ABB controller (IRC5 / OmniCore), written as ABB
//! integrators write dispensing and welding programs: the controller moves the tool itself, with
//! its own kinematics and corner zones, through targets taken from the plan
//! ([`crate::controller_targets`], chosen as for every controller, each zone's corner path taken
//! as a parabola inside the triangle of its ends and its target).
//!
//! * `tooldata tEmgTool`: the TCP (the pen's tip) in the flange frame `tool0`, along its z axis
//!   (axis 6), the tool's frame `tool0` moved there (as `emg import-robot` attaches the pen);
//!   a tool whose TCP is not on axis 6 is refused. `wobjdata
//!   wEmgPart`: the part's frame (where the job has one work surface: its origin the surface's
//!   point, z out of the part, x along the surface's direction; else the base frame). Every
//!   Cartesian target is given in it, in millimetres, its orientation a quaternion in ABB's
//!   order `[q1, q2, q3, q4]` = `[w, x, y, z]`, with the configuration data
//!   ([`AbbConfiguration`]) of the plan's joints there, so that `ConfL\On` holds the controller
//!   to the plan's solution.
//! * The moves between strokes: `MoveAbsJ` through the plan's joint vertices (axes in degrees),
//!   each corner's zone where the joint-space triangle it cuts is free; the lift off a stroke
//!   and the set-down onto the next as `MoveL ... fine`.
//! * A stroke part: at rest on its start, the tool switched on (`SetDO`, then `WaitTime` its
//!   lead), a run of `MoveL` through its targets at the plan's tool speed, each corner with the
//!   zone the targets allow (`fine` at the end), then `WaitTime` its lag and the tool off.
//!   Zones: the largest size of a short series (1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 times a power
//!   of ten, in mm) within the corner's radius, ABB's predefined `z0` or `z1` where it is theirs,
//!   else one declared (`zEmg2_5` for 2.5 mm), its orientation and external-axis zones as large
//!   as its TCP zone; no zone reaches past half of either neighbouring line
//!   ([`crate::controller_targets::BLEND_LENGTH_SHARE`]).
//! * No two consecutive targets of a stroke lie closer than [`crate::industrial::MIN_TARGET_SPACING_M`]: a closer
//!   inner target is left out (the reader checks the path that leaves, within the whole
//!   tolerance).
//!
//! The frames and joint values are the controller's where the description is ROS-Industrial's
//! ABB description (its base frame ABB's base frame, its joint values and zeros ABB's axes').

use emg_control::Task;
use emg_kinematics::{JointVector, Robot, Vec3};
use nalgebra::{Isometry3, Translation3};

use crate::abb_configuration::AbbConfiguration;
use crate::controller_targets::{
    Corner, Pose, StepWriter, TargetRules, segment_configurations, write_steps,
};
use crate::free_space::FreeSpace;
use crate::industrial::{fixed, part_frame, spaced};
use crate::program::JobFile;
use crate::reach::WristReach;
use crate::tool_output::ToolOutput;

/// `MoveAbsJ`'s speed between strokes (ABB's predefined speeddata): the axes' own limits bound
/// it.
const FREE_SPEED: &str = "v1000";

/// ABB's predefined zones whose orientation and external-axis zones are no larger than their
/// TCP zone, with that zone's radius (mm): `[FALSE, r, r, r, r/10, r, r/10]`, as the zones
/// declared here.
const PREDEFINED_ZONES: [(&str, f64); 2] = [("z0", 0.3), ("z1", 1.0)];

/// The zone sizes written within each decade (mm, times a power of ten): a corner's zone is
/// the largest of them within its radius, so that a program holds a few zones, not one per
/// corner.
const ZONE_STEPS: [f64; 10] = [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0];

/// The smallest zone written (mm): below it the corner is `fine`.
const MIN_ZONE_MM: f64 = 0.01;

/// The largest zone size of the series [`ZONE_STEPS`] (mm) within `radius_m` (m): a smaller
/// zone's corner path stays inside the larger one's triangle, so within the tolerance the
/// radius was chosen for. `None` below [`MIN_ZONE_MM`].
fn zone_size_mm(radius_m: f64) -> Option<f64> {
    let radius_mm = radius_m * 1e3;
    if radius_mm.is_nan() || radius_mm < MIN_ZONE_MM {
        return None;
    }
    let decade = libm::floor(libm::log10(radius_mm)) as i32;
    (decade - 1..=decade)
        .rev()
        .flat_map(|d| ZONE_STEPS.iter().rev().map(move |step| (step, d)))
        .map(|(step, d)| {
            // Rounded to the series' digits, so that 10^d·step prints as it reads.
            let size = step * 10f64.powi(d);
            (size * 1e3).round() / 1e3
        })
        .find(|&size| size <= radius_mm + 1e-12 && size >= MIN_ZONE_MM)
}

/// A RAPID module and what it holds.
#[derive(Clone, Debug)]
pub struct RapidProgram {
    /// The module's text.
    pub text: String,
    /// Stroke parts drawn (each with the tool switched on once).
    pub stroke_parts: usize,
    /// `MoveAbsJ` instructions.
    pub move_abs_j: usize,
    /// `MoveL` instructions.
    pub move_l: usize,
    /// The largest distance (m) from its stroke of the straight lines between a stroke's targets.
    pub worst_chord_m: f64,
}

/// Why a job's program cannot be written as a RAPID module.
#[derive(Debug, thiserror::Error)]
pub enum RapidProgramError {
    /// Not a six-joint arm.
    #[error("a RAPID module needs a six-joint ABB arm; this one has {0} joints")]
    Joints(usize),
    /// The TCP does not lie on axis 6, or the tool axis does not run along it.
    #[error(
        "a RAPID module's tooldata holds a tool along the flange's axis (its TCP on axis 6, its \
         axis along it, as `emg import-robot` attaches the pen); this arm's tool axis is \
         ({:.4}, {:.4}, {:.4}) and its TCP lies ({:.4}, {:.4}, {:.4}) m from axis 6's origin at \
         the calibration pose",
        .tool_axis.x, .tool_axis.y, .tool_axis.z, .offset.x, .offset.y, .offset.z
    )]
    Tool {
        /// The tool axis (base frame).
        tool_axis: Vec3,
        /// The TCP's offset from axis 6's origin (m, base frame).
        offset: Vec3,
    },
    /// A stroke segment without its task.
    #[error("segments[{0}] is a stroke part without its task: plan the job again")]
    NoTask(usize),
}

/// `file`'s program exported as one RAPID module to `out`, in memory
/// ([`emg_io::Export::write`] writes it), recorded in its header as written for `reference`.
pub fn rapid_program_export(
    file: &JobFile,
    robot: &Robot,
    reference: &str,
    out: &std::path::Path,
) -> Result<emg_io::Export, RapidProgramError> {
    let tool = file.settings.tool_output;
    let header = vec![
        format!("written by emg from a job's program for robot {reference}"),
        "for an ABB controller (IRC5, OmniCore): load the module and run main \
         (docs/robot-export.md)"
            .to_string(),
        "targets in mm in wobjdata wEmgPart, orientations as quaternions [q1, q2, q3, q4] = \
         [w, x, y, z], configuration data [cf1, cf4, cf6, cfx] of the planned joints; axes in \
         degrees"
            .to_string(),
        format!(
            "the tool: {tool}; digital output signal doEmgTool{} switches it: define it in \
             the I/O configuration or rename it",
            tool.number
        ),
        match &file.home {
            Some(_) => "the module starts with MoveAbsJ to the arm's home, from wherever the arm \
                        stands: clear that way"
                .to_string(),
            None => {
                "the first MoveAbsJ starts from wherever the arm stands: clear that way".to_string()
            }
        },
    ];
    let program = rapid_program(file, robot, &header)?;
    let summary = format!(
        "RAPID for an ABB controller: one module of {} moves ({} MoveAbsJ, {} MoveL) for {} \
         stroke parts, each a MoveL run within {:.3} mm of its stroke between targets, the \
         tool on doEmgTool{}",
        program.move_abs_j + program.move_l,
        program.move_abs_j,
        program.move_l,
        program.stroke_parts,
        program.worst_chord_m * 1e3,
        tool.number,
    );
    Ok(emg_io::Export {
        format: emg_io::ExportFormat::Rapid,
        files: vec![(out.to_path_buf(), program.text.into_bytes())],
        thinning: None,
        servoj_targets: 0,
        summary,
    })
}

/// How far (m) the TCP lies beyond axis 6's origin (ABB's `tool0`, the flange) along the
/// tool axis, where the TCP lies on axis 6 with the tool axis along it (the pen
/// `emg import-robot` attaches, a straight torch or dispenser); else the tool axis's direction
/// and the TCP's offset from axis 6's origin, both in the base frame at the calibration pose.
fn tool_length(robot: &Robot) -> Result<f64, RapidProgramError> {
    let kinematics = robot.forward(&robot.joint_vector(&[0.0; 6]));
    let (axis, flange, tcp) = (
        kinematics.joint_axis(5),
        kinematics.joint_origin(5),
        kinematics.tcp(),
    );
    let (tool_axis, offset) = (kinematics.tool_axis(), tcp - flange);
    if tool_axis.cross(&axis).norm() > 1e-9 || offset.cross(&axis).norm() > 1e-9 {
        return Err(RapidProgramError::Tool { tool_axis, offset });
    }
    Ok(offset.dot(&tool_axis))
}

/// `[x, y, z], [q1, q2, q3, q4]` of `pose` (mm to a nanometre, ABB's quaternion order).
fn pose_text(pose: &Isometry3<f64>) -> String {
    let (p, q) = (pose.translation.vector * 1e3, pose.rotation);
    format!(
        "[{}, {}, {}], [{}, {}, {}, {}]",
        fixed(p.x, 6),
        fixed(p.y, 6),
        fixed(p.z, 6),
        fixed(q.w, 9),
        fixed(q.i, 9),
        fixed(q.j, 9),
        fixed(q.k, 9)
    )
}

/// `q`'s axes in degrees as a `jointtarget`, no external axes.
fn joint_target(robot: &Robot, q: &JointVector) -> String {
    let axes: Vec<String> = robot
        .joints_of(q)
        .iter()
        .map(|v| fixed(v.to_degrees(), 6))
        .collect();
    format!("[[{}], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]]", axes.join(", "))
}

/// `job`'s program as one RAPID module for `robot` (six joints, ROS-Industrial's ABB frames),
/// with `header` as comment lines.
pub fn rapid_program(
    file: &JobFile,
    robot: &Robot,
    header: &[String],
) -> Result<RapidProgram, RapidProgramError> {
    if robot.dof() != 6 {
        return Err(RapidProgramError::Joints(robot.dof()));
    }
    let tool_length = tool_length(robot)?;
    let free = FreeSpace::new(robot, file.surfaces.clone(), &file.constraints);
    let mut writer = Writer {
        rules: TargetRules::for_job(
            file,
            (robot, &free),
            Corner::Parabola,
            WristReach::of(robot),
        ),
        part: part_frame(file),
        tool: file.settings.tool_output,
        tool_length,
        body: String::new(),
        zones: Vec::new(),
        program: RapidProgram {
            text: String::new(),
            stroke_parts: 0,
            move_abs_j: 0,
            move_l: 0,
            worst_chord_m: 0.0,
        },
    };
    let samples = segment_configurations(file);
    writer.line("ConfJ \\On;");
    writer.line("ConfL \\On;");
    writer.switch(false);
    let start = file
        .home
        .as_ref()
        .map(|home| robot.joint_vector(home))
        .or_else(|| samples.first().and_then(|s| s.first()).copied());
    if let Some(start) = start {
        writer.line("! the program's start, from wherever the arm stands: clear that way");
        writer.move_abs_j(&start, 0.0);
    }
    write_steps(file, robot, &samples, &mut writer).map_err(RapidProgramError::NoTask)?;
    writer.finish(header);
    Ok(writer.program)
}

/// The module being written, and what it is written from.
struct Writer<'a> {
    rules: TargetRules<'a>,
    /// `wEmgPart` in the base frame.
    part: Isometry3<f64>,
    tool: ToolOutput,
    /// The TCP's distance beyond the flange along axis 6 (m).
    tool_length: f64,
    /// The instructions of `main`.
    body: String,
    /// The zones declared, by name, with their radius (mm).
    zones: Vec<(String, f64)>,
    program: RapidProgram,
}

impl StepWriter for Writer<'_> {
    fn rules(&self) -> &TargetRules<'_> {
        &self.rules
    }

    fn comment(&mut self, text: &str) {
        self.line(&format!("! {text}"));
    }

    fn stroke(&mut self, qs: &[JointVector], task: &Task) {
        self.stroke_part(qs, task);
    }

    fn straight_move(&mut self, q: &JointVector, speed: f64) {
        self.move_l(q, speed, 0.0);
    }

    fn joint_move(&mut self, q: &JointVector, radius: f64) {
        self.move_abs_j(q, radius);
    }
}

impl Writer<'_> {
    fn line(&mut self, line: &str) {
        self.body.push_str("    ");
        self.body.push_str(line);
        self.body.push('\n');
    }

    /// The tool's output set to switch it on or off.
    fn switch(&mut self, on: bool) {
        let level = i32::from(self.tool.level(on));
        self.line(&format!("SetDO doEmgTool{}, {level};", self.tool.number));
    }

    /// The zone of the largest size of [`zone_size_mm`] within the corner radius `radius_m`
    /// (m): `fine` where none is; ABB's `z0` or `z1` where the size is theirs, else one
    /// declared for the size (`zEmg2_5` for 2.5 mm).
    fn zone(&mut self, radius_m: f64) -> String {
        let Some(size) = zone_size_mm(radius_m) else {
            return "fine".to_string();
        };
        if let Some((name, _)) = PREDEFINED_ZONES.iter().find(|(_, known)| *known == size) {
            return name.to_string();
        }
        let name = format!("zEmg{}", size.to_string().replace('.', "_"));
        if !self.zones.iter().any(|(known, _)| *known == name) {
            self.zones.push((name.clone(), size));
        }
        name
    }

    /// `MoveAbsJ` to `q`, with the zone of `radius` (m) there.
    fn move_abs_j(&mut self, q: &JointVector, radius: f64) {
        let target = joint_target(self.rules.robot, q);
        let zone = self.zone(radius);
        self.line(&format!(
            "MoveAbsJ {target}, {FREE_SPEED}, {zone}, tEmgTool \\WObj:=wEmgPart;"
        ));
        self.program.move_abs_j += 1;
    }

    /// `MoveL` to the TCP pose of `q` at `speed` (m/s), with the zone of `radius` (m) there.
    fn move_l(&mut self, q: &JointVector, speed: f64, radius: f64) {
        let robot = self.rules.robot;
        let kinematics = robot.forward(q);
        let tcp = Pose::from_matrix(kinematics.tcp(), kinematics.tcp_rotation());
        let in_part = self.part.inverse()
            * Isometry3::from_parts(Translation3::from(tcp.position), tcp.rotation);
        let configuration = AbbConfiguration::of(robot, q).text();
        let zone = self.zone(radius);
        self.line(&format!(
            "MoveL [{}, {configuration}, [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], [{}, 500, 5000, \
             1000], {zone}, tEmgTool \\WObj:=wEmgPart;",
            pose_text(&in_part),
            fixed(speed * 1e3, 3),
        ));
        self.program.move_l += 1;
    }

    /// A stroke part whose samples are `qs`, along `task`, the tool at rest on its start: the
    /// tool on, a `MoveL` run through its targets held [`crate::industrial::MIN_TARGET_SPACING_M`] apart
    /// ([`spaced`]), the tool off.
    fn stroke_part(&mut self, qs: &[JointVector], task: &Task) {
        let run = self.rules.stroke(qs, task);
        self.program.worst_chord_m = self.program.worst_chord_m.max(run.worst_chord_m);
        self.program.stroke_parts += 1;
        self.switch(true);
        if self.tool.lead_s > 0.0 {
            self.line(&format!("WaitTime {};", self.tool.lead_s));
        }
        for n in spaced(&run.poses, &run.kept) {
            self.move_l(&qs[run.kept[n]], run.speeds[n], run.radii[n]);
        }
        if self.tool.lag_s > 0.0 {
            self.line(&format!("WaitTime {};", self.tool.lag_s));
        }
        self.switch(false);
    }

    /// The module's text: `header` as comments, the tool, the part's frame and the declared
    /// zones, then `main`.
    fn finish(&mut self, header: &[String]) {
        let mut text = String::from("MODULE EmgJob\n");
        for line in header {
            text.push_str(&format!("  ! {line}\n"));
        }
        let tool = Isometry3::translation(0.0, 0.0, self.tool_length);
        text.push_str(&format!(
            "  PERS tooldata tEmgTool := [TRUE, [{}], [0.1, [0, 0, 1], [1, 0, 0, 0], 0, 0, 0]];\n",
            pose_text(&tool)
        ));
        text.push_str(&format!(
            "  PERS wobjdata wEmgPart := [FALSE, TRUE, \"\", [{}], [[0, 0, 0], [1, 0, 0, 0]]];\n",
            pose_text(&self.part)
        ));
        for (name, size) in &self.zones {
            let orientation = (size * 1e4).round() / 1e5;
            text.push_str(&format!(
                "  CONST zonedata {name} := [FALSE, {size}, {size}, {size}, {orientation}, \
                 {size}, {orientation}];\n"
            ));
        }
        text.push_str("\n  PROC main()\n");
        text.push_str(&self.body);
        text.push_str("  ENDPROC\nENDMODULE\n");
        self.program.text = text;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_zone_is_the_largest_size_of_the_series_within_the_radius() {
        for (radius_m, expected) in [
            (0.0, None),
            (0.9e-5, None),
            (1e-5, Some(0.01)),
            (0.000_299_9, Some(0.25)),
            (0.0003, Some(0.3)),
            (0.000_999, Some(0.8)),
            (0.001, Some(1.0)),
            (0.0049, Some(4.0)),
            (0.0195, Some(15.0)),
            (0.05, Some(50.0)),
            (f64::NAN, None),
        ] {
            assert_eq!(zone_size_mm(radius_m), expected, "{radius_m}");
        }
    }
}
