//! A job's program as one native URScript program for a Universal Robots e-Series controller,
//! written as UR integrators write drawing, dispensing and welding programs: the controller
//! moves the tool itself, with its own kinematics, blends and speed slider, through targets
//! taken from the plan.
//!
//! * The moves between strokes: `movej` through the plan's joint vertices (each edge of the
//!   joint-space polyline checked free, [`FreeSpace::edge_free`]; where one is not, through the
//!   plan's own samples thinned to free edges within [`MOVE_DEVIATION_RAD`] of the planned
//!   path), each corner blended where the joint-space triangle the blend cuts is free
//!   ([`FreeSpace::triangle_free`]); the lift off a stroke's end and the set-down onto the next
//!   start as `movel` where the tool keeps its orientation.
//! * A stroke part: the tool switched on (its [`ToolOutput`], with its lead), a run of `movep`
//!   through poses of the plan's configurations (`p[x, y, z, rx, ry, rz]` in the controller's
//!   Base frame, the rotation vector of the TCP frame), each straight line between two targets
//!   and each corner's blending arc within [`CHORD_SHARE`] of the line tolerance of the stroke
//!   and its tool axis within the cone; at the plan's tool speed; the tool switched off (after
//!   its lag).
//! * The branch the controller's inverse kinematics follows is the plan's: each stroke starts at
//!   the plan's configuration, reached by a joint move (`movej`) or by a short straight lift
//!   from one, and between two targets of a stroke no joint of the plan turns more than
//!   [`MAX_TARGET_TURN_RAD`], so the controller, which solves each pose of the line from the
//!   configuration it stands at, follows the plan's motion between poses of it.
//!
//! The program grows with the drawing's geometry (its targets), not with its duration, and is
//! never split.

use emg_control::{Task, tool_angle_deg};
use emg_kinematics::{JointVector, Robot, Vec3};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion};

use crate::free_space::FreeSpace;
use crate::program::{JobFile, SegmentKind};
use crate::tool_output::{OutputBank, ToolOutput};

/// The tool's acceleration along `movel` and `movep` (m/s²): URScript's default.
pub const TOOL_ACCELERATION_M_S2: f64 = 1.2;
/// Share of the line tolerance that the path the controller interpolates (each straight line
/// between two targets of a stroke, each blend's arc) may lie from the stroke: the rest is left
/// to the controller's tracking.
pub const CHORD_SHARE: f64 = 0.9;
/// Points of a blend's arc checked against the stroke.
const ARC_POINTS: usize = 16;
/// Halvings of a blend's radius tried before the corner is left unblended (the tool stops there).
const BLEND_HALVINGS: usize = 12;
/// A blend's radius is at most this share of the shorter of the two lines it joins, so that no
/// two blends overlap.
pub const BLEND_LENGTH_SHARE: f64 = 0.45;
/// Most any joint of the plan turns between two targets of a stroke (rad).
pub const MAX_TARGET_TURN_RAD: f64 = 0.1;
/// Largest distance (rad) of the plan's path from a `movej` edge where a move's own polyline is
/// not free and its samples are thinned instead.
pub const MOVE_DEVIATION_RAD: f64 = 0.01;
/// An edge off a stroke's end or onto a stroke's start is a straight `movel` where the tool
/// turns less than this along it (rad).
pub const LIFT_TURN_RAD: f64 = 0.01;
/// A `movej` corner's blend radius (m, the TCP's distance from the corner where the blend
/// begins and ends) is at most this share of the TCP's straight distance to either
/// neighbouring vertex.
pub const JOINT_BLEND_LENGTH_SHARE: f64 = 0.4;
/// The largest blend radius of a `movej` corner (m).
pub const MAX_JOINT_BLEND_M: f64 = 0.05;
/// The smallest blend radius written (m): below it the corner is left unblended.
pub const MIN_BLEND_M: f64 = 1e-4;
/// Step (rad, the joint moving most) at which an edge is scanned for where the TCP comes
/// within a blend radius of its end.
const SCAN_STEP_RAD: f64 = 0.005;

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

/// A pose of the tool: position (m) and orientation.
#[derive(Clone, Copy, Debug)]
struct Pose {
    position: Vec3,
    rotation: UnitQuaternion<f64>,
}

impl Pose {
    /// The TCP pose of `q`.
    fn of(robot: &Robot, q: &JointVector) -> Self {
        let kinematics = robot.forward(q);
        Self::from_matrix(kinematics.tcp(), kinematics.tcp_rotation())
    }

    fn from_matrix(position: Vec3, rotation: &Matrix3<f64>) -> Self {
        Self {
            position,
            rotation: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(rotation)),
        }
    }

    /// `p[x, y, z, rx, ry, rz]`: position and rotation vector, to a nanometre and nanoradian.
    fn text(&self) -> String {
        let r = self.rotation.scaled_axis();
        let p = self.position;
        format!(
            "p[{:.9}, {:.9}, {:.9}, {:.9}, {:.9}, {:.9}]",
            p.x, p.y, p.z, r.x, r.y, r.z
        )
    }
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
        robot,
        free: &free,
        tool: file.settings.tool_output,
        tool_speed: file.limits.tool_speed_m_per_s,
        joint_speed,
        joint_acceleration,
        rate_hz: file.rate_hz,
        tolerance: file.constraints.line_tolerance_m,
        cone_deg: file.constraints.theta_max_deg,
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
        Pose::from_matrix(offset, &offset_rotation).text()
    ));
    writer.switch(false);
    let samples: Vec<Vec<JointVector>> = file
        .segments
        .iter()
        .map(|segment| {
            file.segment_samples(segment)
                .iter()
                .map(|sample| sample.q)
                .collect()
        })
        .collect();
    match (&file.home, samples.first().and_then(|s| s.first())) {
        (Some(home), _) => writer.program.text.push_str(&emg_io::home_check(home)),
        (None, Some(first)) => {
            writer.line("# the program's start, from wherever the arm stands: clear that way");
            writer.movej(first, 0.0);
        }
        (None, None) => {}
    }
    let is_stroke = |index: usize| {
        file.segments
            .get(index)
            .is_some_and(|s| matches!(s.kind, SegmentKind::Stroke { .. }))
    };
    for (index, (segment, qs)) in file.segments.iter().zip(&samples).enumerate() {
        match segment.kind {
            SegmentKind::Stroke {
                stroke,
                part,
                from_s,
                backward,
            } => {
                let task = segment.task.as_ref().ok_or(UrProgramError::NoTask(index))?;
                writer.line(&format!(
                    "# stroke {stroke}, part {part}: from {from_s:.4} m along it{}, {:.3} s",
                    if backward {
                        " back toward its start"
                    } else {
                        ""
                    },
                    segment.end_s - segment.start_s
                ));
                writer.stroke(qs, task);
            }
            kind => {
                let vertices: Vec<JointVector> = segment
                    .vertices
                    .iter()
                    .map(|v| robot.joint_vector(v))
                    .collect();
                writer.line(&format!(
                    "# {}: {:.3} s in the plan",
                    match kind {
                        SegmentKind::Retreat => "lift",
                        SegmentKind::Approach => "set-down",
                        _ => "move",
                    },
                    segment.end_s - segment.start_s
                ));
                writer.free_move(
                    &vertices,
                    qs,
                    index > 0 && is_stroke(index - 1),
                    is_stroke(index + 1),
                );
            }
        }
    }
    writer.program.text.push_str("end\n");
    Ok(writer.program)
}

/// The program being written, and what it is written from.
struct Writer<'a> {
    robot: &'a Robot,
    free: &'a FreeSpace<'a>,
    tool: ToolOutput,
    /// The plan's tool speed (m/s).
    tool_speed: f64,
    /// `movej`'s speed and acceleration: the slowest joint's limits (rad/s, rad/s²).
    joint_speed: f64,
    joint_acceleration: f64,
    rate_hz: f64,
    tolerance: f64,
    cone_deg: f64,
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
        let joints = emg_io::joint_list(self.robot.joints_of(q));
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
        let pose = Pose::of(self.robot, q).text();
        let v = self.tool_speed;
        self.line(&format!(
            "movel({pose}, a={TOOL_ACCELERATION_M_S2}, v={v:.6})"
        ));
        self.program.movel += 1;
    }

    /// A move between strokes (or from or to home) through `vertices`, whose samples are `qs`;
    /// `off_stroke` where it starts at a stroke's end, `onto_stroke` where it ends at a stroke's
    /// start.
    fn free_move(
        &mut self,
        vertices: &[JointVector],
        qs: &[JointVector],
        off_stroke: bool,
        onto_stroke: bool,
    ) {
        let polyline_free = vertices.len() >= 2
            && vertices
                .windows(2)
                .all(|edge| self.free.edge_free(&edge[0], &edge[1]));
        let path: Vec<JointVector> = if polyline_free {
            vertices.to_vec()
        } else {
            thinned_joint_path(self.free, qs)
        };
        let edges = path.len().saturating_sub(1);
        // Whether each edge is a straight lift or set-down (`movel`), else a joint move.
        let straight: Vec<bool> = path
            .windows(2)
            .enumerate()
            .map(|(k, edge)| {
                let at_surface = (off_stroke && k == 0) || (onto_stroke && k + 1 == edges);
                at_surface && self.turn(&edge[0], &edge[1]) < LIFT_TURN_RAD
            })
            .collect();
        for k in 0..edges {
            let target = &path[k + 1];
            if straight[k] {
                self.movel(target);
                continue;
            }
            // A corner between two joint moves is blended where the triangle it cuts is free.
            let radius = match (straight.get(k + 1), path.get(k + 2)) {
                (Some(false), Some(next)) => self.joint_blend_radius(&path[k], target, next),
                _ => 0.0,
            };
            self.movej(target, radius);
        }
    }

    /// The blend radius (m) of the `movej` corner `w` between the joint-space edges from `a`
    /// and to `b`: at most [`JOINT_BLEND_LENGTH_SHARE`] of the TCP's distance from `w` to either
    /// and [`MAX_JOINT_BLEND_M`], halved until the joint-space triangle between where the TCP
    /// comes within it of `w` on each edge ([`Writer::entering`]) and `w` is free
    /// ([`FreeSpace::triangle_free`]): any blend the controller makes there keeps inside that
    /// triangle. 0 (no blend) where no radius of at least [`MIN_BLEND_M`] is.
    fn joint_blend_radius(&self, a: &JointVector, w: &JointVector, b: &JointVector) -> f64 {
        let tcp = |q: &JointVector| self.robot.forward(q).tcp();
        let corner = tcp(w);
        let mut radius = (JOINT_BLEND_LENGTH_SHARE
            * (tcp(a) - corner).norm().min((tcp(b) - corner).norm()))
        .min(MAX_JOINT_BLEND_M);
        while radius >= MIN_BLEND_M {
            let (entry, exit) = (self.entering(a, w, radius), self.entering(b, w, radius));
            if self.free.triangle_free(&entry, w, &exit) {
                return radius;
            }
            radius /= 2.0;
        }
        0.0
    }

    /// The configuration on the joint-space edge from `from` to `w` one scan step
    /// ([`SCAN_STEP_RAD`]) before the first one scanned whose TCP lies within `radius` of `w`'s:
    /// at or before where a blend of that radius at `w` can begin.
    fn entering(&self, from: &JointVector, w: &JointVector, radius: f64) -> JointVector {
        let corner = self.robot.forward(w).tcp();
        let steps = ((w - from).amax() / SCAN_STEP_RAD).ceil().max(1.0) as usize;
        let at = |k: usize| from + (w - from) * (k as f64 / steps as f64);
        let first = (0..=steps)
            .find(|&k| (self.robot.forward(&at(k)).tcp() - corner).norm() <= radius)
            .unwrap_or(steps);
        at(first.saturating_sub(1))
    }

    /// The angle (rad) the tool turns from `a` to `b`.
    fn turn(&self, a: &JointVector, b: &JointVector) -> f64 {
        let (a, b) = (Pose::of(self.robot, a), Pose::of(self.robot, b));
        a.rotation.angle_to(&b.rotation)
    }

    /// A stroke part whose samples are `qs`, along `task`: the tool on, a `movep` run through
    /// its targets, the tool off.
    fn stroke(&mut self, qs: &[JointVector], task: &Task) {
        let poses: Vec<Pose> = qs.iter().map(|q| Pose::of(self.robot, q)).collect();
        // Each sample's progress along the task, followed from its start as the reader follows
        // the program's poses.
        let mut s = 0.0;
        let progress: Vec<f64> = poses
            .iter()
            .map(|pose| {
                s = task.along(&pose.position, s).s_m;
                s
            })
            .collect();
        let (kept, worst) =
            stroke_targets(&poses, &progress, qs, task, self.tolerance, self.cone_deg);
        self.program.worst_chord_m = self.program.worst_chord_m.max(worst);
        self.program.stroke_parts += 1;
        self.switch(true);
        if self.tool.lead_s > 0.0 {
            self.line(&format!("sleep({})", self.tool.lead_s));
        }
        for (n, pair) in kept.windows(2).enumerate() {
            let (i, j) = (pair[0], pair[1]);
            let radius = kept.get(n + 2).map_or(0.0, |&m| {
                blend_radius(
                    [&poses[i], &poses[j], &poses[m]],
                    [progress[i], progress[j]],
                    task,
                    self.tolerance,
                    self.cone_deg,
                )
            });
            // The plan's fastest tool speed between the two targets, at most the tool speed.
            let speed = poses[i..=j]
                .windows(2)
                .map(|w| (w[1].position - w[0].position).norm() * self.rate_hz)
                .fold(0.0, f64::max)
                .min(self.tool_speed)
                .max(1e-4);
            self.line(&format!(
                "movep({}, a={TOOL_ACCELERATION_M_S2}, v={speed:.6}, r={radius:.9})",
                poses[j].text()
            ));
            self.program.movep += 1;
        }
        if self.tool.lag_s > 0.0 {
            self.line(&format!("sleep({})", self.tool.lag_s));
        }
        self.switch(false);
    }
}

/// The largest `j` after `i` (up to `last`) for which `fits(j)`, found by doubling the step
/// then halving it; `i + 1` at least.
fn furthest(i: usize, last: usize, mut fits: impl FnMut(usize) -> bool) -> usize {
    let mut good = i + 1;
    let mut step = 1;
    let mut bad = None;
    while good < last {
        let j = (good + step).min(last);
        if fits(j) {
            good = j;
            step *= 2;
        } else {
            bad = Some(j);
            break;
        }
    }
    if let Some(mut bad) = bad {
        while bad - good > 1 {
            let middle = good + (bad - good) / 2;
            if fits(middle) {
                good = middle;
            } else {
                bad = middle;
            }
        }
    }
    good
}

/// The indices of the stroke's samples kept as targets (the first and the last among them) and
/// the largest distance from the stroke found on the lines between them: each line within
/// [`CHORD_SHARE`] of the `tolerance` of `task` and its slerped tool axis within `cone_deg` at
/// every sample between its ends (taken at the sample's projection on it) and at its end,
/// measured from the path point reached, the progress followed along the line from the
/// samples' progress (`progress`) at its start as the reader follows it, as well as from the
/// whole path; following the line reaches as far along the stroke as the samples do at its end
/// (a line that cuts a corner short of where the samples turned would leave the reader's
/// progress before the corner); and no joint turns more than [`MAX_TARGET_TURN_RAD`] from its
/// start to any sample up to its end. The line between two neighbouring samples is followed
/// as the samples are; where even it does not fit, it is kept ([`furthest`]).
fn stroke_targets(
    poses: &[Pose],
    progress: &[f64],
    qs: &[JointVector],
    task: &Task,
    tolerance: f64,
    cone_deg: f64,
) -> (Vec<usize>, f64) {
    let last = poses.len().saturating_sub(1);
    let mut kept = vec![0];
    let mut worst: f64 = 0.0;
    // The largest distance from the stroke of the line from `i` to `j`, if it fits.
    let line = |i: usize, j: usize| -> Option<f64> {
        let (a, b) = (poses[i].position, poses[j].position);
        let chord = b - a;
        let length2 = chord.norm_squared();
        let mut largest: f64 = 0.0;
        let mut s = progress[i];
        for k in i + 1..=j {
            if (qs[k] - qs[i]).amax() > MAX_TARGET_TURN_RAD {
                return None;
            }
            let u = if k == j {
                1.0
            } else if length2 > 0.0 {
                ((poses[k].position - a).dot(&chord) / length2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let point = a + chord * u;
            let along = task.along(&point, s);
            s = along.s_m;
            let distance = task.distance(&point).max(along.lateral.norm());
            let rotation = poses[i]
                .rotation
                .try_slerp(&poses[j].rotation, u, 1e-12)
                .unwrap_or(poses[i].rotation);
            let axis = rotation * Vec3::z();
            if distance > CHORD_SHARE * tolerance || tool_angle_deg(&axis, &task.n) > cone_deg {
                return None;
            }
            largest = largest.max(distance);
        }
        (s >= progress[j] - SAME_PROGRESS_M).then_some(largest)
    };
    let mut i = 0;
    while i < last {
        let j = furthest(i, last, |j| line(i, j).is_some());
        worst = worst.max(line(i, j).unwrap_or(0.0));
        kept.push(j);
        i = j;
    }
    (kept, worst)
}

/// How far (m) following a line between two targets may end behind the samples' progress at
/// its end and still count as reaching it (rounding only).
const SAME_PROGRESS_M: f64 = 1e-9;

/// The radius of the blend at target `j` between the lines from target `i` and to target `m`
/// (m): at most [`BLEND_LENGTH_SHARE`] of the shorter line, halved until its arc ([`blend_arc`])
/// lies within [`CHORD_SHARE`] of the `tolerance` of `task` (measured from the path point
/// reached, followed along the arc from `from_s`, the progress at `a`, and from the whole path)
/// and its tool axis within `cone_deg` of the task's normal, the progress followed to its end
/// reaching `at_b_s`, the samples' progress at `b` (an arc that turns short of a corner the
/// samples came to would leave the reader's progress before it); 0 (no blend) where no radius
/// tried does.
fn blend_radius(
    [a, b, c]: [&Pose; 3],
    [from_s, at_b_s]: [f64; 2],
    task: &Task,
    tolerance: f64,
    cone_deg: f64,
) -> f64 {
    let shorter = (b.position - a.position)
        .norm()
        .min((c.position - b.position).norm());
    let mut radius = BLEND_LENGTH_SHARE * shorter;
    for _ in 0..BLEND_HALVINGS {
        let mut s = from_s;
        let fits = blend_arc([a, b, c], radius).iter().all(|pose| {
            let along = task.along(&pose.position, s);
            s = along.s_m;
            task.distance(&pose.position).max(along.lateral.norm()) <= CHORD_SHARE * tolerance
                && tool_angle_deg(&(pose.rotation * Vec3::z()), &task.n) <= cone_deg
        });
        if fits && s >= at_b_s - SAME_PROGRESS_M {
            return radius;
        }
        radius /= 2.0;
    }
    0.0
}

/// The poses along the blend of radius `radius` at `b` between the lines `a`–`b` and `b`–`c`,
/// as `movep` blends: a circular arc tangent to both lines at `radius` from `b`, the orientation
/// slerped between those of the lines at the two tangent points; [`ARC_POINTS`] + 1 poses,
/// both tangent points included (just those two where the lines run straight on).
fn blend_arc([a, b, c]: [&Pose; 3], radius: f64) -> Vec<Pose> {
    let along = |from: &Pose, to: &Pose, distance: f64| {
        let length = (to.position - from.position).norm();
        let u = if length > 0.0 { distance / length } else { 0.0 };
        Pose {
            position: from.position + (to.position - from.position) * u,
            rotation: from
                .rotation
                .try_slerp(&to.rotation, u, 1e-12)
                .unwrap_or(from.rotation),
        }
    };
    let entry = along(b, a, radius);
    let exit = along(b, c, radius);
    let (into, out) = (
        (b.position - entry.position).normalize(),
        (exit.position - b.position).normalize(),
    );
    let turn = libm::atan2(into.cross(&out).norm(), into.dot(&out));
    let rotation = |t: f64| {
        entry
            .rotation
            .try_slerp(&exit.rotation, t, 1e-12)
            .unwrap_or(entry.rotation)
    };
    if turn < 1e-9 || radius <= 0.0 {
        return vec![entry, exit];
    }
    // The arc's centre lies inside the corner, on its bisector, radius / cos α from `b`.
    let half_opening = (std::f64::consts::PI - turn) / 2.0;
    let bisector = (out - into).normalize();
    let centre = b.position + bisector * (radius / libm::cos(half_opening));
    let (from, to) = (entry.position - centre, exit.position - centre);
    (0..=ARC_POINTS)
        .map(|k| {
            let t = k as f64 / ARC_POINTS as f64;
            let position = centre
                + (from * libm::sin((1.0 - t) * turn) + to * libm::sin(t * turn)) / libm::sin(turn);
            Pose {
                position,
                rotation: rotation(t),
            }
        })
        .collect()
}

/// The samples `qs` of a move thinned to the vertices of a joint-space polyline whose every
/// edge is free ([`FreeSpace::edge_free`]) and within [`MOVE_DEVIATION_RAD`] of the samples
/// between its ends (both ends kept; the first sample left out, as the arm stands there).
fn thinned_joint_path(free: &FreeSpace<'_>, qs: &[JointVector]) -> Vec<JointVector> {
    let last = qs.len().saturating_sub(1);
    let fits = |i: usize, j: usize| {
        let chord = qs[j] - qs[i];
        let length2 = chord.norm_squared();
        (i + 1..j).all(|k| {
            let offset = qs[k] - qs[i];
            let u = if length2 > 0.0 {
                (offset.dot(&chord) / length2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (offset - chord * u).norm() <= MOVE_DEVIATION_RAD
        }) && free.edge_free(&qs[i], &qs[j])
    };
    let mut path = vec![qs[0]];
    let mut i = 0;
    while i < last {
        let j = furthest(i, last, |j| fits(i, j));
        path.push(qs[j]);
        i = j;
    }
    path
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_furthest_fitting_index_is_found_by_doubling_then_halving() {
        for limit in 1..40 {
            assert_eq!(furthest(0, 37, |j| j <= limit), limit.clamp(1, 37));
        }
        assert_eq!(furthest(5, 6, |_| false), 6);
    }

    #[test]
    fn a_blend_is_an_arc_tangent_to_both_lines_at_its_radius() {
        let pose = |x: f64, y: f64| Pose {
            position: Vec3::new(x, y, 0.0),
            rotation: UnitQuaternion::identity(),
        };
        let (a, b) = (pose(-0.01, 0.0), pose(0.0, 0.0));
        for degrees in [10.0_f64, 45.0, 90.0, 135.0] {
            let turn = degrees.to_radians();
            let c = pose(0.02 * libm::cos(turn), 0.02 * libm::sin(turn));
            let arc = blend_arc([&a, &b, &c], 0.004);
            let (first, last) = (arc[0].position, arc[arc.len() - 1].position);
            assert!(
                (first - Vec3::new(-0.004, 0.0, 0.0)).norm() < 1e-12,
                "{degrees}°"
            );
            assert!((last - c.position * 0.2).norm() < 1e-12, "{degrees}°");
            // Every point equally far from one centre, on the bisector inside the corner.
            let middle = arc[ARC_POINTS / 2].position;
            let radius_of = |p: Vec3| {
                let half = (std::f64::consts::PI - turn) / 2.0;
                let bisector = ((c.position - b.position).normalize() - Vec3::x()).normalize();
                (p - bisector * (0.004 / libm::cos(half))).norm()
            };
            for point in &arc {
                assert!((radius_of(point.position) - radius_of(first)).abs() < 1e-12);
            }
            assert!(middle.norm() < 0.004, "{degrees}°: the arc cuts the corner");
        }
    }
}
