//! A job's program as one native URScript program for a Universal Robots e-Series controller,
//! written as UR integrators write drawing, dispensing and welding programs: the controller
//! moves the tool itself, with its own kinematics, blends and speed slider, through targets
//! taken from the plan.
//!
//! The targets are chosen as for every controller (`crate::controller_targets`):
//!
//! * The moves between strokes: `movej` through the plan's joint vertices (each edge of the
//!   joint-space polyline checked free, [`FreeSpace::edge_free`]; where one is not, through the
//!   plan's own samples thinned to free edges), each corner blended where the joint-space
//!   triangle the blend cuts is free ([`FreeSpace::triangle_free`]); the lift off a stroke's end
//!   and the set-down onto the next start as `movel` where the tool keeps its orientation.
//! * A stroke part: the tool switched on (its [`ToolOutput`], with its lead), a run of `movep`
//!   through poses of the plan's configurations (`p[x, y, z, rx, ry, rz]` in the controller's
//!   Base frame, the rotation vector of the TCP frame), each straight line between two targets
//!   and each corner's blending arc within `CHORD_SHARE` of the line tolerance of the stroke
//!   and its tool axis within the cone; at the plan's tool speed; the tool switched off (after
//!   its lag).
//! * The branch the controller's inverse kinematics follows is the plan's: each stroke starts at
//!   the plan's configuration, reached by a joint move (`movej`) or by a short straight lift
//!   from one, and between two targets of a stroke no joint of the plan turns more than
//!   `MAX_TARGET_TURN_RAD`, so the controller, which solves each pose of the line from the
//!   configuration it stands at, follows the plan's motion between poses of it.
//!
//! The program grows with the drawing's geometry (its targets), not with its duration, and is
//! never split.

use emg_control::Task;
use emg_kinematics::{JointVector, Robot};

use crate::controller_targets::{Corner, Pose, Step, TargetRules, segment_configurations, walk};
use crate::free_space::FreeSpace;
use crate::program::JobFile;
use crate::tool_output::{OutputBank, ToolOutput};

/// The tool's acceleration along `movel` and `movep` (m/s²): URScript's default.
pub const TOOL_ACCELERATION_M_S2: f64 = 1.2;

/// A native UR program and what it holds.
#[derive(Clone, Debug)]
pub struct UrProgram {
    /// The program's text.
    pub text: String,
    /// Stroke parts drawn (each with the tool switched on once).
    pub stroke_parts: usize,
    /// `movej` lines.
    pub movej: usize,
    /// `movel` lines.
    pub movel: usize,
    /// `movep` lines.
    pub movep: usize,
    /// The largest distance (m) from its stroke of the straight lines between a stroke's targets
    /// where they were checked (at each of the plan's samples between them).
    pub worst_chord_m: f64,
}

impl UrProgram {
    /// Motion lines (`movej`, `movel`, `movep`).
    pub fn moves(&self) -> usize {
        self.movej + self.movel + self.movep
    }
}

/// Why a job's program cannot be written as a native UR program.
#[derive(Debug, thiserror::Error)]
pub enum UrProgramError {
    /// Not a six-joint arm.
    #[error("a native UR program needs a six-joint Universal Robots arm; this one has {0} joints")]
    Joints(usize),
    /// A stroke segment without its task.
    #[error("segments[{0}] is a stroke part without its task: plan the job again")]
    NoTask(usize),
}

/// `p[x, y, z, rx, ry, rz]`: position and rotation vector, to a nanometre and nanoradian.
fn pose_text(pose: &Pose) -> String {
    let r = pose.rotation.scaled_axis();
    let p = pose.position;
    format!(
        "p[{:.9}, {:.9}, {:.9}, {:.9}, {:.9}, {:.9}]",
        p.x, p.y, p.z, r.x, r.y, r.z
    )
}

/// `file`'s program exported as one native UR program to `out`, in memory
/// ([`emg_io::Export::write`] writes it): [`ur_program`] for `robot` (the shipped UR5e),
/// recorded in its header as `reference`.
pub fn ur_program_export(
    file: &JobFile,
    robot: &Robot,
    reference: &str,
    out: &std::path::Path,
) -> Result<emg_io::Export, UrProgramError> {
    let tool = file.settings.tool_output;
    let header = vec![
        format!("written by emg from a job's program for robot {reference}"),
        "for a Universal Robots e-Series controller (PolyScope 5): run it in a Script node or \
         send it to port 30002 (docs/robot-export.md)"
            .to_string(),
        "poses p[x, y, z, rx, ry, rz] in the controller's Base frame (m, rotation vector); \
         joints in the pendant's order and zero; the TCP at the tool's tip (set_tcp)"
            .to_string(),
        format!("the tool: {tool}"),
        match &file.home {
            Some(_) => "the program starts at the arm's home, where the arm must stand: it halts \
                        otherwise"
                .to_string(),
            None => {
                "the first movej starts from wherever the arm stands: clear that way".to_string()
            }
        },
    ];
    let program = ur_program(file, robot, &header)?;
    let summary = format!(
        "URScript for a Universal Robots e-Series controller, native: one program of {} moves \
         ({} movej, {} movel, {} movep) for {} stroke parts, each a blended movep run within \
         {:.3} mm of its stroke between targets, the tool on {} digital output {}",
        program.moves(),
        program.movej,
        program.movel,
        program.movep,
        program.stroke_parts,
        program.worst_chord_m * 1e3,
        tool.bank.name(),
        tool.number,
    );
    Ok(emg_io::Export {
        format: emg_io::ExportFormat::UrScript,
        files: vec![(out.to_path_buf(), program.text.into_bytes())],
        thinning: None,
        servoj_targets: 0,
        summary,
    })
}

/// The smallest of `values` (the slowest joint's limit); infinite where there are none.
fn smallest(values: &[f64]) -> f64 {
    values.iter().copied().fold(f64::INFINITY, f64::min)
}

/// `job`'s program as one native URScript program for `robot` (the shipped UR5e: its base
/// frame the controller's Base frame, its last joint's segment the tool flange), with `header`
/// as comment lines.
pub fn ur_program(
    file: &JobFile,
    robot: &Robot,
    header: &[String],
) -> Result<UrProgram, UrProgramError> {
    if robot.dof() != 6 {
        return Err(UrProgramError::Joints(robot.dof()));
    }
    let free = FreeSpace::new(robot, file.surfaces.clone(), &file.constraints);
    let joint_speed = smallest(&file.limits.max_velocity);
    let joint_acceleration = smallest(&file.limits.max_acceleration);
    let mut writer = Writer {
        rules: TargetRules::for_job(file, (robot, &free), Corner::Arc, None),
        tool: file.settings.tool_output,
        joint_speed,
        joint_acceleration,
        program: UrProgram {
            text: String::new(),
            stroke_parts: 0,
            movej: 0,
            movel: 0,
            movep: 0,
            worst_chord_m: 0.0,
        },
    };
    for line in header {
        writer.program.text.push_str(&format!("# {line}\n"));
    }
    writer.program.text.push_str("def emg_job():\n");
    let (offset, offset_rotation) = robot.tcp_offset();
    writer.line(&format!(
        "set_tcp({})",
        pose_text(&Pose::from_matrix(offset, &offset_rotation))
    ));
    writer.switch(false);
    let samples = segment_configurations(file);
    match (&file.home, samples.first().and_then(|s| s.first())) {
        (Some(home), _) => writer.program.text.push_str(&emg_io::home_check(home)),
        (None, Some(first)) => {
            writer.line("# the program's start, from wherever the arm stands: clear that way");
            writer.movej(first, 0.0);
        }
        (None, None) => {}
    }
    walk(file, robot, &samples, |step| match step {
        Step::Stroke { comment, qs, task } => {
            writer.line(&format!("# {comment}"));
            writer.stroke(qs, task);
        }
        Step::Move {
            comment,
            vertices,
            qs,
            off_stroke,
            onto_stroke,
        } => {
            writer.line(&format!("# {comment}"));
            writer.free_move(&vertices, qs, off_stroke, onto_stroke);
        }
    })
    .map_err(UrProgramError::NoTask)?;
    writer.program.text.push_str("end\n");
    Ok(writer.program)
}

/// The program being written, and what it is written from.
struct Writer<'a> {
    rules: TargetRules<'a>,
    tool: ToolOutput,
    /// `movej`'s speed and acceleration: the slowest joint's limits (rad/s, rad/s²).
    joint_speed: f64,
    joint_acceleration: f64,
    program: UrProgram,
}

impl Writer<'_> {
    fn line(&mut self, line: &str) {
        self.program.text.push_str("  ");
        self.program.text.push_str(line);
        self.program.text.push('\n');
    }

    /// The tool's output set to switch it on or off.
    fn switch(&mut self, on: bool) {
        let function = match self.tool.bank {
            OutputBank::Standard => "set_standard_digital_out",
            OutputBank::Tool => "set_tool_digital_out",
        };
        let level = if self.tool.level(on) { "True" } else { "False" };
        self.line(&format!("{function}({}, {level})", self.tool.number));
    }

    /// `movej` to `q`, blended at it by `radius` (m) where that is positive.
    fn movej(&mut self, q: &JointVector, radius: f64) {
        let joints = emg_io::joint_list(self.rules.robot.joints_of(q));
        let (a, v) = (self.joint_acceleration, self.joint_speed);
        let blend = if radius > 0.0 {
            format!(", r={radius:.6}")
        } else {
            String::new()
        };
        self.line(&format!("movej({joints}, a={a:.6}, v={v:.6}{blend})"));
        self.program.movej += 1;
    }

    fn movel(&mut self, q: &JointVector) {
        let pose = pose_text(&Pose::of(self.rules.robot, q));
        let v = self.rules.tool_speed;
        self.line(&format!(
            "movel({pose}, a={TOOL_ACCELERATION_M_S2}, v={v:.6})"
        ));
        self.program.movel += 1;
    }

    /// A move between strokes (or from or to home) through `vertices`, whose samples are `qs`;
    /// `off_stroke` where it starts at a stroke's end, `onto_stroke` where it ends at a stroke's
    /// start: `movel` for a straight lift or set-down, else `movej`.
    fn free_move(
        &mut self,
        vertices: &[JointVector],
        qs: &[JointVector],
        off_stroke: bool,
        onto_stroke: bool,
    ) {
        for target in self.rules.free_move(vertices, qs, off_stroke, onto_stroke) {
            if target.straight {
                self.movel(&target.q);
            } else {
                self.movej(&target.q, target.radius);
            }
        }
    }

    /// A stroke part whose samples are `qs`, along `task`: the tool on, a `movep` run through
    /// its targets, the tool off.
    fn stroke(&mut self, qs: &[JointVector], task: &Task) {
        let run = self.rules.stroke(qs, task);
        self.program.worst_chord_m = self.program.worst_chord_m.max(run.worst_chord_m);
        self.program.stroke_parts += 1;
        self.switch(true);
        if self.tool.lead_s > 0.0 {
            self.line(&format!("sleep({})", self.tool.lead_s));
        }
        for n in 1..run.kept.len() {
            self.line(&format!(
                "movep({}, a={TOOL_ACCELERATION_M_S2}, v={:.6}, r={:.9})",
                pose_text(&run.poses[run.kept[n]]),
                run.speeds[n],
                run.radii[n],
            ));
            self.program.movep += 1;
        }
        if self.tool.lag_s > 0.0 {
            self.line(&format!("sleep({})", self.tool.lag_s));
        }
        self.switch(false);
    }
}
