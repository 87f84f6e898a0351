//! A native program read back: its moves interpreted as the Universal Robots URScript manual
//! defines them (`movej` linear in joint space, `movel` on a straight line with its orientation
//! slerped, runs of `movep` on straight lines joined by circular blends), each Cartesian move
//! followed by the UR5e's closed-form inverse kinematics as the controller follows it, and what
//! the program makes the arm do checked against the job's plan with the independent checker.

use std::f64::consts::PI;

use emg_job::JobFile;
use emg_kinematics::Vec3;
use emg_program_check::{Drawing, PlanChecks};
use emg_verify::ReferenceModel;

use crate::error::{ReadError, fail};
use crate::geometry::{Pose, Rotation};
use crate::script::{Form, Output, Statement, parse_program};
use crate::ur5e::{checker_tcp, largest_change, ur5e_flange, ur5e_follow};

/// Largest spacing (m) of the TCP samples along an interpolated Cartesian path.
pub const PATH_STEP_M: f64 = 1e-4;

/// Largest turn (rad) of the TCP frame between two samples of an interpolated Cartesian path.
pub const TURN_STEP_RAD: f64 = 1e-3;

/// Largest change (rad) of the joint that moves most between two samples of a `movej`.
pub const JOINT_STEP_RAD: f64 = 0.01;

/// Largest change (rad) of any joint between two consecutive samples of a Cartesian move the
/// controller follows: more is a change of branch or a singularity.
pub const MAX_JOINT_JUMP_RAD: f64 = 0.05;

/// How closely (rad per joint) a `movej` target must equal a configuration of the plan.
pub const JOINT_MATCH_RAD: f64 = 1e-9;

/// How closely (m, and rad of rotation) a Cartesian target must equal the TCP pose of a
/// configuration of the plan.
pub const POSE_MATCH: f64 = 1e-6;

/// One piece of an interpolated Cartesian path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Piece {
    /// The stretch from fraction `from` to fraction `to` of the straight line from `a` to
    /// `b`, its orientation slerped from `a`'s to `b`'s by the same fraction.
    Line {
        /// The line's start.
        a: Pose,
        /// The line's end.
        b: Pose,
        /// Where the stretch starts (fraction of the line).
        from: f64,
        /// Where it ends.
        to: f64,
    },
    /// A circular blend: from `start` about `centre`, swept by `sweep_rad` about the unit
    /// `axis`, its orientation slerped from `from_rotation` to `to_rotation` by the fraction
    /// of the sweep.
    Arc {
        /// The circle's centre.
        centre: Vec3,
        /// Where the arc starts.
        start: Vec3,
        /// The unit axis it turns about (right hand).
        axis: Vec3,
        /// The angle swept (rad, positive).
        sweep_rad: f64,
        /// The orientation at its start.
        from_rotation: Rotation,
        /// The orientation at its end.
        to_rotation: Rotation,
    },
}

impl Piece {
    /// The pose a fraction `f` of the way along the piece.
    pub fn at(&self, f: f64) -> Pose {
        match *self {
            Self::Line { a, b, from, to } => {
                let s = from + (to - from) * f;
                Pose {
                    position: a.position + (b.position - a.position) * s,
                    rotation: a.rotation.slerp(&b.rotation, s),
                }
            }
            Self::Arc {
                centre,
                start,
                axis,
                sweep_rad,
                from_rotation,
                to_rotation,
            } => Pose {
                position: centre
                    + Rotation::from_rotation_vector(&(axis * (sweep_rad * f)))
                        .apply(&(start - centre)),
                rotation: from_rotation.slerp(&to_rotation, f),
            },
        }
    }

    /// Its length (m) and the angle its orientation turns through (rad).
    pub fn extent(&self) -> (f64, f64) {
        let (start, end) = (self.at(0.0), self.at(1.0));
        let length = match *self {
            Self::Line { a, b, from, to } => (b.position - a.position).norm() * (to - from),
            Self::Arc {
                centre,
                start,
                sweep_rad,
                ..
            } => (start - centre).norm() * sweep_rad,
        };
        (length, start.rotation.angle_to(&end.rotation))
    }

    /// Samples of the piece after its start, at most [`PATH_STEP_M`] apart along it and
    /// [`TURN_STEP_RAD`] apart in orientation, its end the last.
    pub fn samples(&self) -> Vec<Pose> {
        let (length, turn) = self.extent();
        let count = (length / PATH_STEP_M)
            .max(turn / TURN_STEP_RAD)
            .ceil()
            .max(1.0) as usize;
        (1..=count)
            .map(|k| self.at(k as f64 / count as f64))
            .collect()
    }
}

/// Refuses a blend radius `radius` at a run's last target (line `line`): the run ends there, at
/// rest.
fn unblended_end(radius: f64, line: usize) -> Result<(), ReadError> {
    if radius > 0.0 {
        return fail(
            line,
            format!("a blend radius of {radius} m at a run's last target"),
        );
    }
    Ok(())
}

/// The path of a run of `movep` targets (`targets`: each pose, its blend radius and its line)
/// from `start`: straight lines between the targets, each corner with a radius `r > 0` replaced
/// by the circular arc tangent to both lines `r` before and after the target. Each piece comes
/// with the line of the target whose line or blend it belongs to.
pub fn movep_path(
    start: &Pose,
    targets: &[(Pose, f64, usize)],
) -> Result<Vec<(Piece, usize)>, ReadError> {
    let mut pieces = Vec::new();
    let Some(&(_, last_radius, last_line)) = targets.last() else {
        return Ok(pieces);
    };
    unblended_end(last_radius, last_line)?;
    let corners: Vec<Pose> = std::iter::once(*start)
        .chain(targets.iter().map(|t| t.0))
        .collect();
    let length = |i: usize| (corners[i + 1].position - corners[i].position).norm();
    // The fraction of line i (from corner i to corner i + 1) where the path leaves it.
    let mut from = 0.0;
    for (i, &(target, radius, line)) in targets.iter().enumerate() {
        let a = corners[i];
        let incoming = length(i);
        if radius > 0.0 {
            let outgoing = length(i + 1);
            if radius > incoming / 2.0 + 1e-12 || radius > outgoing / 2.0 + 1e-12 {
                return fail(
                    line,
                    format!(
                        "blend radius {radius} m exceeds half of an adjacent line ({incoming} m \
                         in, {outgoing} m out)"
                    ),
                );
            }
        }
        let to = if radius > 0.0 {
            1.0 - radius / incoming
        } else {
            1.0
        };
        pieces.push((
            Piece::Line {
                a,
                b: target,
                from,
                to,
            },
            line,
        ));
        from = 0.0;
        if radius > 0.0 {
            let next = corners[i + 2];
            let outgoing = length(i + 1);
            let u1 = (target.position - a.position) / incoming;
            let u2 = (next.position - target.position) / outgoing;
            let entry = Piece::Line {
                a,
                b: target,
                from: to,
                to,
            }
            .at(0.0);
            let leave = radius / outgoing;
            let exit = Piece::Line {
                a: target,
                b: next,
                from: leave,
                to: leave,
            }
            .at(0.0);
            let cross = u1.cross(&u2);
            let turn = libm::atan2(cross.norm(), u1.dot(&u2));
            let blend = if !(1e-9..=PI - 1e-9).contains(&turn) {
                Piece::Line {
                    a: entry,
                    b: exit,
                    from: 0.0,
                    to: 1.0,
                }
            } else {
                let axis = cross / cross.norm();
                let bend = radius * (1.0 + libm::cos(turn)) / libm::sin(turn);
                Piece::Arc {
                    centre: entry.position + axis.cross(&u1) * bend,
                    start: entry.position,
                    axis,
                    sweep_rad: turn,
                    from_rotation: entry.rotation,
                    to_rotation: exit.rotation,
                }
            };
            pieces.push((blend, line));
            from = leave;
        }
    }
    Ok(pieces)
}

/// One piece of a joint-space path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointPiece {
    /// The stretch from fraction `from` to fraction `to` of the straight joint line from `a`
    /// to `b`.
    Line {
        /// The line's start.
        a: [f64; 6],
        /// The line's end.
        b: [f64; 6],
        /// Where the stretch starts (fraction of the line).
        from: f64,
        /// Where it ends.
        to: f64,
    },
    /// A blend at constant joint acceleration (parabolic in time, a quadratic Bézier curve in
    /// joint space) from `entry` on the line into the `corner` to `exit` on the line out of it.
    Blend {
        /// Where the blend leaves the incoming line.
        entry: [f64; 6],
        /// The target blended past.
        corner: [f64; 6],
        /// Where the blend joins the outgoing line.
        exit: [f64; 6],
    },
}

impl JointPiece {
    /// The joints a fraction `f` of the way along the piece.
    pub fn at(&self, f: f64) -> [f64; 6] {
        match *self {
            Self::Line { a, b, from, to } => {
                let s = from + (to - from) * f;
                std::array::from_fn(|i| a[i] + (b[i] - a[i]) * s)
            }
            Self::Blend {
                entry,
                corner,
                exit,
            } => std::array::from_fn(|i| {
                (1.0 - f) * (1.0 - f) * entry[i] + 2.0 * f * (1.0 - f) * corner[i] + f * f * exit[i]
            }),
        }
    }

    /// An upper bound of the largest change of any joint along the piece (rad).
    pub fn extent(&self) -> f64 {
        match *self {
            Self::Line { .. } => largest_change(&self.at(0.0), &self.at(1.0)),
            Self::Blend {
                entry,
                corner,
                exit,
            } => largest_change(&entry, &corner) + largest_change(&corner, &exit),
        }
    }
}

/// Where on the joint line from `a` to `b` (fraction from `a`) the TCP (`tcp_of`) first lies
/// `radius` (m) from its place at the line's end `b` (`corner_at_b`) or start `a`, seen from
/// that corner: the point a blend of that radius there leaves or joins the line; `None` where
/// the whole line lies within it.
fn blend_point(
    a: &[f64; 6],
    b: &[f64; 6],
    corner_at_b: bool,
    radius: f64,
    tcp_of: &dyn Fn(&[f64; 6]) -> Vec3,
) -> Option<f64> {
    let line = JointPiece::Line {
        a: *a,
        b: *b,
        from: 0.0,
        to: 1.0,
    };
    let corner = tcp_of(if corner_at_b { b } else { a });
    // The fraction measured from the corner.
    let from_corner = |u: f64| if corner_at_b { 1.0 - u } else { u };
    let within = |u: f64| (tcp_of(&line.at(from_corner(u))) - corner).norm() < radius;
    let steps = (line.extent() / JOINT_STEP_RAD).ceil().max(1.0) as usize;
    let outside = (1..=steps)
        .map(|k| k as f64 / steps as f64)
        .find(|u| !within(*u))?;
    let (mut inside, mut outside) = (outside - 1.0 / steps as f64, outside);
    for _ in 0..50 {
        let middle = 0.5 * (inside + outside);
        if within(middle) {
            inside = middle;
        } else {
            outside = middle;
        }
    }
    Some(from_corner(outside))
}

/// The path of a run of `movej` targets (`targets`: each configuration, its blend radius and
/// its line) from `start`: straight joint lines between the targets, each target with a radius
/// `r > 0` blended past from where the TCP comes within `r` of its place at the target on the
/// line in to where it leaves that distance on the line out ([`JointPiece::Blend`]); `tcp_of`
/// gives the TCP of a configuration. Each piece comes with the line of the target whose line or
/// blend it belongs to.
pub fn movej_path(
    start: &[f64; 6],
    targets: &[([f64; 6], f64, usize)],
    tcp_of: &dyn Fn(&[f64; 6]) -> Vec3,
) -> Result<Vec<(JointPiece, usize)>, ReadError> {
    let mut pieces = Vec::new();
    let Some(&(_, last_radius, last_line)) = targets.last() else {
        return Ok(pieces);
    };
    unblended_end(last_radius, last_line)?;
    let corners: Vec<[f64; 6]> = std::iter::once(*start)
        .chain(targets.iter().map(|t| t.0))
        .collect();
    // The fraction of line i (from corner i to corner i + 1) where the path leaves it.
    let mut from = 0.0;
    for (i, &(target, radius, line)) in targets.iter().enumerate() {
        let a = corners[i];
        let (to, exit) = if radius > 0.0 {
            let next = corners[i + 2];
            let too_wide = || ReadError {
                program: None,
                line,
                problem: format!(
                    "blend radius {radius} m holds a whole joint move next to its target"
                ),
            };
            let to = blend_point(&a, &target, true, radius, tcp_of).ok_or_else(too_wide)?;
            let exit = blend_point(&target, &next, false, radius, tcp_of).ok_or_else(too_wide)?;
            (to, Some((next, exit)))
        } else {
            (1.0, None)
        };
        if to < from {
            return fail(
                line,
                format!("the blend at this target overlaps the one before it (radius {radius} m)"),
            );
        }
        pieces.push((
            JointPiece::Line {
                a,
                b: target,
                from,
                to,
            },
            line,
        ));
        from = 0.0;
        if let Some((next, leave)) = exit {
            let point = |a: &[f64; 6], b: &[f64; 6], s: f64| {
                JointPiece::Line {
                    a: *a,
                    b: *b,
                    from: s,
                    to: s,
                }
                .at(0.0)
            };
            pieces.push((
                JointPiece::Blend {
                    entry: point(&a, &target, to),
                    corner: target,
                    exit: point(&target, &next, leave),
                },
                line,
            ));
            from = leave;
        }
    }
    Ok(pieces)
}

/// The plan's configurations, sorted by their first joint, for finding a `movej` target.
struct JointIndex(Vec<[f64; 6]>);

impl JointIndex {
    /// Whether some configuration equals `q` to [`JOINT_MATCH_RAD`] per joint.
    fn holds(&self, q: &[f64; 6]) -> bool {
        let first = self.0.partition_point(|c| c[0] < q[0] - JOINT_MATCH_RAD);
        self.0[first..]
            .iter()
            .take_while(|c| c[0] <= q[0] + JOINT_MATCH_RAD)
            .any(|c| largest_change(c, q) <= JOINT_MATCH_RAD)
    }
}

/// The TCP poses of the plan's configurations and vertices (by the checker), sorted by x, for
/// finding a Cartesian target.
struct PoseIndex(Vec<Pose>);

impl PoseIndex {
    /// Whether some pose equals `pose` to [`POSE_MATCH`] (m and rad).
    fn holds(&self, pose: &Pose) -> bool {
        let x = pose.position.x;
        let first = self.0.partition_point(|p| p.position.x < x - POSE_MATCH);
        self.0[first..]
            .iter()
            .take_while(|p| p.position.x <= x + POSE_MATCH)
            .any(|p| {
                let (distance, angle) = p.difference(pose);
                distance <= POSE_MATCH && angle <= POSE_MATCH
            })
    }

    /// The pose whose position lies nearest `pose`'s, for a refusal's message.
    fn nearest(&self, pose: &Pose) -> Option<Pose> {
        self.0.iter().copied().min_by(|a, b| {
            let distance = |p: &Pose| (p.position - pose.position).norm();
            distance(a).total_cmp(&distance(b))
        })
    }
}

/// What the reader found.
#[derive(Clone, Debug, PartialEq)]
pub struct NativeReport {
    /// `movej` lines.
    pub movej: usize,
    /// `movel` lines.
    pub movel: usize,
    /// `movep` lines.
    pub movep: usize,
    /// Lines holding code.
    pub code_lines: usize,
    /// Strokes of the plan.
    pub strokes: usize,
    /// Code lines per stroke.
    pub lines_per_stroke: f64,
    /// Stroke parts drawn (tool switched on).
    pub stroke_parts: usize,
    /// Configurations checked along the moves.
    pub samples: usize,
    /// Largest distance (m) of the interpolated TCP from its task while the tool is on.
    pub worst_deviation_m: f64,
    /// Largest angle (degrees) of the tool axis from its task's normal while the tool is on.
    pub worst_tool_angle_deg: f64,
    /// Cartesian moves (a `movel`, or a run of `movep`) the controller follows, each on the
    /// branch of the inverse kinematics it starts on (the reader refuses a change of branch).
    pub cartesian_moves: usize,
    /// Largest change of any joint (rad) between consecutive samples of a Cartesian move.
    pub worst_joint_step_rad: f64,
    /// Smallest self-clearance (m) along the moves.
    pub least_clearance_m: f64,
    /// Per stroke, the length of its path the interpolated TCP covers while the tool is on and
    /// the length the plan says is drawn (m).
    pub per_stroke: Vec<(f64, f64)>,
    /// Total covered (m).
    pub covered_m: f64,
    /// Total the plan draws (m).
    pub drawn_m: f64,
    /// The home check's tolerance (rad), if the program checks its home.
    pub home_tolerance_rad: Option<f64>,
}

/// What a reading needs of the plan and the checker.
struct Reading<'a> {
    model: &'a ReferenceModel,
    /// The plan's side: its stroke parts and the checks against them.
    plan: PlanChecks<'a>,
    joints_index: JointIndex,
    poses_index: PoseIndex,
    /// The level of the tool output that switches the tool on.
    on_level: bool,
}

/// The state of the controller as the program runs.
struct State {
    /// The TCP in the flange frame.
    tcp: Option<Pose>,
    /// The joints (once known).
    joints: Option<[f64; 6]>,
    /// The commanded TCP pose (once known).
    pose: Option<Pose>,
    /// The tool output.
    output: Option<Output>,
    /// What the arm has drawn so far.
    drawing: Drawing,
    /// The pending `movep` run: each target, its radius and its line.
    run: Vec<(Pose, f64, usize)>,
    /// The pending run of blended `movej`: each target, its radius and its line.
    joint_run: Vec<([f64; 6], f64, usize)>,
    report: NativeReport,
}

/// Reads the program `text` against the job's plan `file` with the checker `model` of the
/// UR5e (base `base_link`, tip `pen_tip`); `on_level` is the tool output's level that switches
/// the tool on.
pub fn read_native(
    text: &str,
    file: &JobFile,
    model: &ReferenceModel,
    on_level: bool,
) -> Result<NativeReport, ReadError> {
    let program = parse_program(text, Form::Native)?;
    let reading = Reading::new(file, model, on_level)?;
    let mut state = State {
        tcp: None,
        joints: None,
        pose: None,
        output: None,
        drawing: reading.plan.start(file.strokes.len()),
        run: Vec::new(),
        joint_run: Vec::new(),
        report: NativeReport {
            movej: 0,
            movel: 0,
            movep: 0,
            code_lines: program.code_lines,
            strokes: file.strokes.len(),
            lines_per_stroke: program.code_lines as f64 / file.strokes.len().max(1) as f64,
            stroke_parts: 0,
            samples: 0,
            worst_deviation_m: 0.0,
            worst_tool_angle_deg: 0.0,
            cartesian_moves: 0,
            worst_joint_step_rad: 0.0,
            least_clearance_m: f64::INFINITY,
            per_stroke: Vec::new(),
            covered_m: 0.0,
            drawn_m: 0.0,
            home_tolerance_rad: None,
        },
    };
    for (line, statement) in &program.statements {
        reading.execute(&mut state, *line, statement)?;
    }
    reading.end_run(&mut state)?;
    reading.end_joint_run(&mut state)?;
    let last_line = text.lines().count();
    let drawing = &state.drawing;
    reading
        .plan
        .finish(drawing)
        .or_else(|problem| fail(last_line, problem))?;
    let covered = reading
        .plan
        .covered(drawing, file)
        .or_else(|problem| fail(0, problem))?;
    let mut report = state.report;
    report.stroke_parts = drawing.parts_on;
    report.samples = drawing.samples;
    report.worst_deviation_m = drawing.worst_deviation_m;
    report.worst_tool_angle_deg = drawing.worst_tool_angle_deg;
    report.least_clearance_m = drawing.least_clearance_m;
    report.per_stroke = covered.per_stroke;
    report.covered_m = covered.covered_m;
    report.drawn_m = covered.drawn_m;
    Ok(report)
}

impl<'a> Reading<'a> {
    /// What the reading needs of `file` and `model`.
    fn new(file: &JobFile, model: &'a ReferenceModel, on_level: bool) -> Result<Self, ReadError> {
        let plan = PlanChecks::new(file, model).or_else(|problem| fail(0, problem))?;
        let configurations: Vec<[f64; 6]> = file
            .points()
            .iter()
            .map(|p| std::array::from_fn(|i| p.positions[i]))
            .collect();
        // The samples, then the vertices of the moves' joint-space polylines (which a blended
        // move's samples pass by, not through).
        let mut joints: Vec<[f64; 6]> = configurations;
        for segment in &file.segments {
            for vertex in &segment.vertices {
                if vertex.len() >= 6 {
                    joints.push(std::array::from_fn(|i| vertex[i]));
                }
            }
        }
        let mut poses: Vec<Pose> = joints.iter().map(|q| checker_tcp(model, q)).collect();
        joints.sort_by(|a, b| a[0].total_cmp(&b[0]));
        poses.sort_by(|a, b| a.position.x.total_cmp(&b.position.x));
        Ok(Self {
            model,
            plan,
            joints_index: JointIndex(joints),
            poses_index: PoseIndex(poses),
            on_level,
        })
    }

    /// Runs one statement.
    fn execute(
        &self,
        state: &mut State,
        line: usize,
        statement: &Statement,
    ) -> Result<(), ReadError> {
        if !matches!(statement, Statement::MoveP { .. }) {
            self.end_run(state)?;
        }
        if !matches!(statement, Statement::MoveJ { .. }) {
            self.end_joint_run(state)?;
        }
        match *statement {
            Statement::SetTcp(tcp) => {
                if state.joints.is_some() {
                    return fail(line, "set_tcp after the first move");
                }
                // The TCP the controller is told is the tool's: the checker's tip at a
                // configuration of the plan.
                let q = self.joints_index.0.first().copied().unwrap_or([0.0; 6]);
                let (distance, angle) = ur5e_flange(&q)
                    .then(&tcp)
                    .difference(&checker_tcp(self.model, &q));
                if distance > POSE_MATCH || angle > POSE_MATCH {
                    return fail(
                        line,
                        format!(
                            "the TCP set is not the tool's tip ({distance:.3e} m, {angle:.3e} rad \
                             away)"
                        ),
                    );
                }
                state.tcp = Some(tcp);
            }
            Statement::DigitalOut { output, level } => {
                if *state.output.get_or_insert(output) != output {
                    return fail(line, format!("writes {output:?}, not the tool's output"));
                }
                // Writing the level the output holds changes nothing.
                let on = level == self.on_level;
                if on && !state.drawing.tool_on {
                    self.switch_on(state, line)?;
                } else if !on && state.drawing.tool_on {
                    self.switch_off(state, line)?;
                }
            }
            Statement::HomeCheck {
                home,
                tolerance_rad,
            } => {
                if state.joints.is_some() {
                    return fail(line, "the home check after the first move");
                }
                if !self.joints_index.holds(&home) {
                    return fail(line, "the home checked is no configuration of the plan");
                }
                state.report.home_tolerance_rad = Some(tolerance_rad);
                self.arrive(state, home, line)?;
            }
            Statement::MoveJ { q, radius_m } => {
                state.report.movej += 1;
                if state.drawing.tool_on {
                    return fail(line, "movej with the tool on");
                }
                if !self.joints_index.holds(&q) {
                    return fail(
                        line,
                        format!("movej target {q:?} is no configuration of the plan"),
                    );
                }
                state.joint_run.push((q, radius_m, line));
                if radius_m == 0.0 {
                    self.end_joint_run(state)?;
                }
            }
            Statement::MoveL { pose } => {
                state.report.movel += 1;
                self.target(pose, line)?;
                let start = self.current_pose(state, line)?;
                let piece = Piece::Line {
                    a: start,
                    b: pose,
                    from: 0.0,
                    to: 1.0,
                };
                self.follow(state, &[(piece, line)], line, pose)?;
            }
            Statement::MoveP { pose, radius_m } => {
                state.report.movep += 1;
                self.target(pose, line)?;
                state.run.push((pose, radius_m, line));
            }
            Statement::Sleep => {}
            Statement::ServoJ { .. } | Statement::StopJ => {
                return fail(line, "a joint stream's statement in a native program");
            }
        }
        Ok(())
    }

    /// The commanded TCP pose, which a Cartesian move starts from.
    fn current_pose(&self, state: &State, line: usize) -> Result<Pose, ReadError> {
        if state.tcp.is_none() {
            return fail(line, "a Cartesian move before set_tcp");
        }
        state.pose.ok_or_else(|| ReadError {
            program: None,
            line,
            problem: "a Cartesian move before the arm's joints are known (no home check \
                          and no movej before it)"
                .to_string(),
        })
    }

    /// Checks that a Cartesian target is the TCP pose of a configuration (a sample or a move's
    /// vertex) of the plan.
    fn target(&self, pose: Pose, line: usize) -> Result<(), ReadError> {
        if self.poses_index.holds(&pose) {
            return Ok(());
        }
        let nearest = self.poses_index.nearest(&pose).map_or_else(
            || "the plan has none".to_string(),
            |nearest| {
                let (distance, angle) = nearest.difference(&pose);
                format!(
                    "the nearest, {:?}, lies {distance:.3e} m and {angle:.3e} rad away",
                    nearest.to_ur()
                )
            },
        );
        fail(
            line,
            format!(
                "target {:?} is not the TCP pose of any configuration of the plan ({nearest})",
                pose.to_ur()
            ),
        )
    }

    /// Runs the pending `movep` run, if any.
    fn end_run(&self, state: &mut State) -> Result<(), ReadError> {
        if state.run.is_empty() {
            return Ok(());
        }
        let run = std::mem::take(&mut state.run);
        let first_line = run[0].2;
        let start = self.current_pose(state, first_line)?;
        let pieces = movep_path(&start, &run)?;
        let end = run[run.len() - 1].0;
        self.follow(state, &pieces, first_line, end)
    }

    /// The arm at joints `q` at the end of a move of line `line`: checks the configuration and
    /// takes it as the controller's.
    fn arrive(&self, state: &mut State, q: [f64; 6], line: usize) -> Result<(), ReadError> {
        self.check_configuration(state, &q, line)?;
        state.joints = Some(q);
        state.pose = state.tcp.map(|tcp| ur5e_flange(&q).then(&tcp));
        Ok(())
    }

    /// Runs the pending run of `movej`, if any: from the arm's joints along the path of
    /// [`movej_path`], every configuration checked, to its last target.
    fn end_joint_run(&self, state: &mut State) -> Result<(), ReadError> {
        let run = std::mem::take(&mut state.joint_run);
        let Some(&(end, _, last_line)) = run.last() else {
            return Ok(());
        };
        if let Some(from) = state.joints {
            let Some(tcp) = state.tcp else {
                return fail(run[0].2, "a movej before set_tcp");
            };
            let tcp_of = |q: &[f64; 6]| ur5e_flange(q).then(&tcp).position;
            for (piece, line) in movej_path(&from, &run, &tcp_of)? {
                let count = (piece.extent() / JOINT_STEP_RAD).ceil().max(1.0) as usize;
                for k in 1..=count {
                    let q = piece.at(k as f64 / count as f64);
                    self.check_configuration(state, &q, line)?;
                }
            }
        }
        self.arrive(state, end, last_line)
    }

    /// Checks a configuration the arm passes ([`PlanChecks::configuration`]).
    fn check_configuration(
        &self,
        state: &mut State,
        q: &[f64; 6],
        line: usize,
    ) -> Result<(), ReadError> {
        self.plan
            .configuration(&mut state.drawing, q)
            .or_else(|problem| fail(line, problem))
    }

    /// The controller following Cartesian `pieces` (each with its line) to the target `end`,
    /// the move starting at line `line`: each sample's joints by the closed form nearest the previous ones, on the
    /// branch the move starts on, no joint jumping, every configuration checked; while the
    /// tool is on, each TCP on its task within the tolerance and the cone.
    fn follow(
        &self,
        state: &mut State,
        pieces: &[(Piece, usize)],
        line: usize,
        end: Pose,
    ) -> Result<(), ReadError> {
        let (Some(tcp), Some(mut joints)) = (state.tcp, state.joints) else {
            return fail(line, "a Cartesian move before the arm's joints are known");
        };
        let flange_of = |pose: &Pose| pose.then(&tcp.inverse());
        let start = self.current_pose(state, line)?;
        let branch = ur5e_follow(&flange_of(&start), &joints)
            .ok_or_else(|| ReadError {
                program: None,
                line,
                problem: "the move's start has no inverse kinematics solution".to_string(),
            })?
            .branch;
        for (piece, piece_line) in pieces {
            for pose in piece.samples() {
                let Some(solution) = ur5e_follow(&flange_of(&pose), &joints) else {
                    return fail(*piece_line, format!("{:?} is out of reach", pose.to_ur()));
                };
                if solution.branch != branch {
                    return fail(
                        *piece_line,
                        format!(
                            "the controller leaves the branch {branch:?} for {:?} at {:?}",
                            solution.branch,
                            pose.to_ur()
                        ),
                    );
                }
                let step = largest_change(&solution.q, &joints);
                state.report.worst_joint_step_rad = state.report.worst_joint_step_rad.max(step);
                if step > MAX_JOINT_JUMP_RAD {
                    return fail(
                        *piece_line,
                        format!(
                            "a joint jumps by {step:.4} rad within {PATH_STEP_M} m of the path \
                             at {:?}",
                            pose.to_ur()
                        ),
                    );
                }
                joints = solution.q;
                self.check_configuration(state, &joints, *piece_line)?;
                if state.drawing.tool_on {
                    self.check_on_task(state, &pose, *piece_line)?;
                }
            }
        }
        state.joints = Some(joints);
        state.pose = Some(end);
        state.report.cartesian_moves += 1;
        Ok(())
    }

    /// Checks a TCP pose while the tool is on ([`PlanChecks::on_task`]).
    fn check_on_task(&self, state: &mut State, pose: &Pose, line: usize) -> Result<(), ReadError> {
        let axis = pose.rotation.column(2);
        self.plan
            .on_task(&mut state.drawing, &pose.position, &axis)
            .or_else(|problem| fail(line, problem))
    }

    /// The tool switched on at line `line` ([`PlanChecks::switch_on`]).
    fn switch_on(&self, state: &mut State, line: usize) -> Result<(), ReadError> {
        let Some(pose) = state.pose else {
            return fail(line, "the tool switches on before the first move");
        };
        let axis = pose.rotation.column(2);
        self.plan
            .switch_on(&mut state.drawing, &pose.position, &axis)
            .or_else(|problem| fail(line, problem))
    }

    /// The tool switched off at line `line` ([`PlanChecks::switch_off`]).
    fn switch_off(&self, state: &mut State, line: usize) -> Result<(), ReadError> {
        let pose = self.current_pose(state, line)?;
        self.plan
            .switch_off(&mut state.drawing, &pose.position)
            .or_else(|problem| fail(line, problem))
    }
}
