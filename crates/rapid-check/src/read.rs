//! A module read back: its instructions run as the controller runs them, what the arm does
//! checked against the job's plan with the independent checker.

use std::collections::BTreeMap;

use emg_job::JobFile;
use emg_kinematics::Vec3;
use emg_program_check::{Drawing, PlanChecks};
use emg_verify::ReferenceModel;

use crate::arm::{Configuration, Irb120, Pose};
use crate::error::{ReadError, fail};
use crate::parse::{Instruction, Module, Value, parse_module};

/// Largest spacing (m) of the TCP samples along an interpolated Cartesian path.
pub const PATH_STEP_M: f64 = 1e-4;
/// Largest step (rad, the joint moving most) between the configurations checked along a joint
/// move.
pub const JOINT_STEP_RAD: f64 = 0.01;
/// Largest change (rad) of any joint between consecutive samples of a Cartesian path: more is
/// a jump through a singularity.
pub const MAX_JOINT_JUMP_RAD: f64 = 0.05;
/// How near (rad, every joint) a target's solution must be to a configuration of the plan.
pub const TARGET_MATCH_RAD: f64 = 1e-6;
/// How near (m and rad) the tool's TCP must be to the checker's tip.
pub const TOOL_MATCH: f64 = 1e-6;
/// The closest two consecutive Cartesian targets may lie (m).
pub const MIN_TARGET_SPACING_M: f64 = 1e-4;

/// ABB's predefined zones: name and TCP zone (mm).
const PREDEFINED_ZONES: [(&str, f64); 14] = [
    ("z0", 0.3),
    ("z1", 1.0),
    ("z5", 5.0),
    ("z10", 10.0),
    ("z15", 15.0),
    ("z20", 20.0),
    ("z30", 30.0),
    ("z40", 40.0),
    ("z50", 50.0),
    ("z60", 60.0),
    ("z80", 80.0),
    ("z100", 100.0),
    ("z150", 150.0),
    ("z200", 200.0),
];

/// What the reader found.
#[derive(Clone, Debug, PartialEq)]
pub struct RapidReport {
    /// `MoveAbsJ` instructions.
    pub move_abs_j: usize,
    /// `MoveL` instructions.
    pub move_l: usize,
    /// Zones declared by the module.
    pub declared_zones: usize,
    /// Stroke parts drawn (tool switched on).
    pub stroke_parts: usize,
    /// Largest distance (rad, any joint) of a target's solution from the plan's configuration.
    pub worst_target_rad: f64,
    /// Smallest distance (m) between consecutive Cartesian targets.
    pub least_spacing_m: f64,
    /// Configurations checked along the moves.
    pub samples: usize,
    /// Largest distance (m) of the interpolated TCP from its task while the tool is on.
    pub worst_deviation_m: f64,
    /// Largest angle (degrees) of the tool axis from its task's normal while the tool is on.
    pub worst_tool_angle_deg: f64,
    /// Smallest self-clearance (m) along the moves.
    pub least_clearance_m: f64,
    /// Total covered while the tool is on (m).
    pub covered_m: f64,
    /// Total the plan draws (m).
    pub drawn_m: f64,
}

/// What the module declares and the plan holds.
struct Reading<'a> {
    arm: Irb120,
    /// The plan's side: its stroke parts and the checks against them.
    plan: PlanChecks<'a>,
    /// The plan's configurations: its samples and its moves' vertices.
    configurations: Vec<[f64; 6]>,
    /// The TCP in the flange frame (`tooldata`).
    tool: Pose,
    /// The work object's frame in the base frame (`wobjdata`).
    work_object: Pose,
    /// Zones by name: TCP zone (m).
    zones: BTreeMap<String, f64>,
    signal: String,
    on_level: bool,
}

/// The controller's state as the module runs.
struct State {
    joints: Option<[f64; 6]>,
    /// Whether the arm is at rest (the last move ended `fine`).
    at_rest: bool,
    conf_linear: bool,
    /// What the arm has drawn so far.
    drawing: Drawing,
    /// The pending fly-by run: each target's pose, joints, zone radius (m), line and
    /// configuration data.
    run: Vec<(Pose, [f64; 6], f64, usize, Configuration)>,
    /// The pending fly-by joint moves: each target, zone radius (m) and line.
    joint_run: Vec<([f64; 6], f64, usize)>,
    last_target: Option<Pose>,
    report: RapidReport,
}

/// Reads the module `text` against the job's plan `file` with the checker `model` of the IRB
/// 120 (base `base_link`, tip `pen_tip`).
pub fn read_rapid(
    text: &str,
    file: &JobFile,
    model: &ReferenceModel,
) -> Result<RapidReport, ReadError> {
    let module = parse_module(text)?;
    let reading = Reading::new(&module, file, model)?;
    let mut state = State {
        joints: None,
        at_rest: true,
        conf_linear: false,
        drawing: reading.plan.start(file.strokes.len()),
        run: Vec::new(),
        joint_run: Vec::new(),
        last_target: None,
        report: RapidReport {
            move_abs_j: 0,
            move_l: 0,
            declared_zones: module
                .declarations
                .iter()
                .filter(|d| d.data_type == "zonedata")
                .count(),
            stroke_parts: 0,
            worst_target_rad: 0.0,
            least_spacing_m: f64::INFINITY,
            samples: 0,
            worst_deviation_m: 0.0,
            worst_tool_angle_deg: 0.0,
            least_clearance_m: f64::INFINITY,
            covered_m: 0.0,
            drawn_m: 0.0,
        },
    };
    for instruction in &module.main {
        reading.execute(&mut state, instruction)?;
    }
    let last_line = text.lines().count();
    if !state.run.is_empty() || !state.joint_run.is_empty() {
        return fail(
            last_line,
            "the module ends on a fly-by point: its last move is not fine",
        );
    }
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
    report.covered_m = covered.covered_m;
    report.drawn_m = covered.drawn_m;
    Ok(report)
}

/// The largest change of any joint from `a` to `b` (rad).
fn largest_change(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// A frame `[[x, y, z], [q1, q2, q3, q4]]` (mm, ABB's quaternion order).
fn frame(value: &Value, what: &str, line: usize) -> Result<Pose, ReadError> {
    let parts = value.items(what, 2, line)?;
    let position = parts[0].numbers::<3>(what, line)?;
    let quaternion = parts[1].numbers::<4>(what, line)?;
    Pose::from_rapid(position, quaternion)
        .ok_or_else(|| ReadError::at(line, format!("{what}'s quaternion is not a rotation")))
}

impl<'a> Reading<'a> {
    fn new(module: &Module, file: &JobFile, model: &'a ReferenceModel) -> Result<Self, ReadError> {
        let declared = |data_type: &str| {
            let found: Vec<_> = module
                .declarations
                .iter()
                .filter(|d| d.data_type == data_type)
                .collect();
            match found.as_slice() {
                [only] => Ok(*only),
                _ => fail(
                    0,
                    format!("the module declares {} {data_type}, not one", found.len()),
                ),
            }
        };
        let tooldata = declared("tooldata")?;
        let tool_items = tooldata.value.items("tooldata", 3, tooldata.line)?;
        let tool = frame(&tool_items[1], "tooldata's tframe", tooldata.line)?;
        let wobjdata = declared("wobjdata")?;
        let wobj_items = wobjdata.value.items("wobjdata", 5, wobjdata.line)?;
        if wobj_items[0] != Value::Bool(false) || wobj_items[1] != Value::Bool(true) {
            return fail(
                wobjdata.line,
                "the work object is not a fixed one held by no robot ([FALSE, TRUE, ...])",
            );
        }
        let work_object = frame(&wobj_items[3], "wobjdata's uframe", wobjdata.line)?.then(&frame(
            &wobj_items[4],
            "wobjdata's oframe",
            wobjdata.line,
        )?);
        let mut zones: BTreeMap<String, f64> = PREDEFINED_ZONES
            .iter()
            .map(|(name, mm)| (name.to_string(), mm / 1e3))
            .collect();
        for zone in module
            .declarations
            .iter()
            .filter(|d| d.data_type == "zonedata")
        {
            let items = zone.value.items("zonedata", 7, zone.line)?;
            if items[0] != Value::Bool(false) {
                return fail(zone.line, format!("zone {} is a stop point", zone.name));
            }
            let tcp_mm = items[1].number("pzone_tcp", zone.line)?;
            let orientation_mm = items[2].number("pzone_ori", zone.line)?;
            if tcp_mm.is_nan() || tcp_mm <= 0.0 || orientation_mm > tcp_mm {
                return fail(
                    zone.line,
                    format!(
                        "zone {} reorients the tool over {orientation_mm} mm, beyond its TCP \
                         zone of {tcp_mm} mm",
                        zone.name
                    ),
                );
            }
            zones.insert(zone.name.clone(), tcp_mm / 1e3);
        }
        let plan = PlanChecks::new(file, model).or_else(|problem| fail(0, problem))?;
        let mut configurations: Vec<[f64; 6]> = file
            .points()
            .iter()
            .map(|p| std::array::from_fn(|i| p.positions[i]))
            .collect();
        for segment in &file.segments {
            for vertex in &segment.vertices {
                if vertex.len() >= 6 {
                    configurations.push(std::array::from_fn(|i| vertex[i]));
                }
            }
        }
        let arm = Irb120::default();
        // The tool the module names is the checker's tip on the arm's flange.
        if let Some(q) = configurations.first() {
            let (position, rotation) = model.tcp_frame(&emg_program_check::checker_joints(q));
            let tip = arm.flange(q).then(&tool);
            let axis = tip.rotation * Vec3::z();
            let (distance, angle) = (
                (tip.position - position).norm(),
                libm::acos(axis.dot(&rotation.column(2).into_owned()).clamp(-1.0, 1.0)),
            );
            if distance > TOOL_MATCH || angle > TOOL_MATCH {
                return fail(
                    tooldata.line,
                    format!(
                        "the tool's TCP is not the tool's tip ({distance:.3e} m, {angle:.3e} rad \
                         away)"
                    ),
                );
            }
        }
        let tool_output = file.settings.tool_output;
        Ok(Self {
            arm,
            plan,
            configurations,
            tool,
            work_object,
            zones,
            signal: format!("doEmgTool{}", tool_output.number),
            on_level: tool_output.on_high,
        })
    }

    /// The plan's configuration nearest `q` (largest joint difference), with that difference.
    fn nearest_configuration(&self, q: &[f64; 6]) -> (f64, [f64; 6]) {
        self.configurations
            .iter()
            .map(|c| (largest_change(c, q), *c))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap_or((f64::INFINITY, *q))
    }

    /// The zone (m, 0 for `fine`) an instruction's zone argument names.
    fn zone(&self, value: &Value, line: usize) -> Result<f64, ReadError> {
        match value {
            Value::Name(name) if name == "fine" => Ok(0.0),
            Value::Name(name) => self
                .zones
                .get(name)
                .copied()
                .ok_or_else(|| ReadError::at(line, format!("zone {name} is not defined"))),
            other => fail(line, format!("the zone is {other:?}, not a zone's name")),
        }
    }

    /// Checks the tool and work object arguments of a move.
    fn check_frames(&self, instruction: &Instruction, tool: &Value) -> Result<(), ReadError> {
        let line = instruction.line;
        if *tool != Value::Name("tEmgTool".to_string()) {
            return fail(line, format!("the move's tool is {tool:?}, not tEmgTool"));
        }
        match instruction.switch("WObj") {
            Some(Some(Value::Name(name))) if name == "wEmgPart" => Ok(()),
            _ => fail(line, "the move is not given in the work object wEmgPart"),
        }
    }

    fn execute(&self, state: &mut State, instruction: &Instruction) -> Result<(), ReadError> {
        let line = instruction.line;
        let values = instruction.values();
        match instruction.name.as_str() {
            "ConfJ" => {}
            "ConfL" => state.conf_linear = instruction.switch("On").is_some(),
            "WaitTime" => {
                if values.len() != 1 || values[0].number("WaitTime", line)? < 0.0 {
                    return fail(line, "WaitTime without its time");
                }
            }
            "SetDO" => {
                let [Value::Name(signal), level] = values.as_slice() else {
                    return fail(line, "SetDO without its signal and value");
                };
                if *signal != self.signal {
                    return fail(
                        line,
                        format!("SetDO {signal}: not the tool's {}", self.signal),
                    );
                }
                if !state.at_rest {
                    return fail(
                        line,
                        "SetDO after a fly-by point: it runs before the arm arrives",
                    );
                }
                let on = (level.number("SetDO's value", line)? != 0.0) == self.on_level;
                if on && !state.drawing.tool_on {
                    self.switch_on(state, line)?;
                } else if !on && state.drawing.tool_on {
                    self.switch_off(state, line)?;
                }
            }
            "MoveAbsJ" => {
                state.report.move_abs_j += 1;
                let [target, _speed, zone, tool] = values.as_slice() else {
                    return fail(line, "MoveAbsJ without its target, speed, zone and tool");
                };
                self.check_frames(instruction, tool)?;
                if state.drawing.tool_on {
                    return fail(line, "MoveAbsJ with the tool on");
                }
                if !state.run.is_empty() {
                    return fail(line, "MoveAbsJ after a MoveL fly-by point");
                }
                let axes =
                    target.items("the jointtarget", 2, line)?[0].numbers::<6>("axes", line)?;
                let q = axes.map(f64::to_radians);
                let (error, _) = self.nearest_configuration(&q);
                if error > TARGET_MATCH_RAD {
                    return fail(
                        line,
                        format!(
                            "MoveAbsJ target is no configuration of the plan ({error:.3e} rad away)"
                        ),
                    );
                }
                let radius = self.zone(zone, line)?;
                state.joint_run.push((q, radius, line));
                state.at_rest = radius == 0.0;
                if radius == 0.0 {
                    self.end_joint_run(state)?;
                }
                state.last_target = None;
            }
            "MoveL" => {
                state.report.move_l += 1;
                let [target, _speed, zone, tool] = values.as_slice() else {
                    return fail(line, "MoveL without its target, speed, zone and tool");
                };
                self.check_frames(instruction, tool)?;
                if !state.conf_linear {
                    return fail(
                        line,
                        "MoveL before ConfL \\On: the configuration data would not hold",
                    );
                }
                if !state.joint_run.is_empty() {
                    return fail(line, "MoveL after a MoveAbsJ fly-by point");
                }
                let items = target.items("the robtarget", 4, line)?;
                let position = items[0].numbers::<3>("the robtarget's position", line)?;
                let quaternion = items[1].numbers::<4>("the robtarget's orientation", line)?;
                let conf = items[2].numbers::<4>("the robtarget's confdata", line)?;
                let pose = Pose::from_rapid(position, quaternion)
                    .map(|p| self.work_object.then(&p))
                    .ok_or_else(|| {
                        ReadError::at(line, "the robtarget's quaternion is not a rotation")
                    })?;
                let configuration: Configuration = conf.map(|c| c as i32);
                let flange = pose.then(&self.tool.inverse());
                let q = self
                    .arm
                    .solve(&flange, configuration, self.plan.limits())
                    .map_err(|count| {
                        ReadError::at(
                            line,
                            format!(
                                "the configuration data {configuration:?} select {count} \
                                 solutions of the target, not one"
                            ),
                        )
                    })?;
                let (error, _) = self.nearest_configuration(&q);
                state.report.worst_target_rad = state.report.worst_target_rad.max(error);
                if error > TARGET_MATCH_RAD {
                    return fail(
                        line,
                        format!(
                            "the target's solution by its configuration data {configuration:?} \
                             is no configuration of the plan ({error:.3e} rad away)"
                        ),
                    );
                }
                if let Some(previous) = state.last_target {
                    let spacing = (pose.position - previous.position).norm();
                    state.report.least_spacing_m = state.report.least_spacing_m.min(spacing);
                    if spacing < MIN_TARGET_SPACING_M {
                        return fail(
                            line,
                            format!(
                                "the target lies {:.4} mm from the one before: closer than {} mm",
                                spacing * 1e3,
                                MIN_TARGET_SPACING_M * 1e3
                            ),
                        );
                    }
                }
                state.last_target = Some(pose);
                let radius = self.zone(zone, line)?;
                state.run.push((pose, q, radius, line, configuration));
                state.at_rest = radius == 0.0;
                if radius == 0.0 {
                    self.end_run(state)?;
                }
            }
            other => {
                return fail(
                    line,
                    format!("{other} is not an instruction a job's module holds"),
                );
            }
        }
        Ok(())
    }

    /// Runs the pending `MoveL` run: from where the arm stands along straight lines, each
    /// fly-by corner on the parabola through its zone (the zone at most half of each
    /// neighbouring line), the tool followed by the nearest solution sample by sample.
    fn end_run(&self, state: &mut State) -> Result<(), ReadError> {
        let run = std::mem::take(&mut state.run);
        let Some(joints) = state.joints else {
            return fail(
                run[0].3,
                "a MoveL before the arm's joints are known (no MoveAbsJ before it)",
            );
        };
        let start = self.arm.flange(&joints).then(&self.tool);
        let mut corners: Vec<Pose> = vec![start];
        corners.extend(run.iter().map(|r| r.0));
        // Each inner corner's zone, bounded by half of either line.
        let radius = |k: usize| -> f64 {
            if k == 0 || k + 1 >= corners.len() {
                return 0.0;
            }
            let before = (corners[k].position - corners[k - 1].position).norm();
            let after = (corners[k + 1].position - corners[k].position).norm();
            run[k - 1].2.min(before / 2.0).min(after / 2.0)
        };
        let mut joints = joints;
        let mut from = start;
        for k in 1..corners.len() {
            let (line, held) = (run[k - 1].3, run[k - 1].4);
            let (a, b) = (corners[k - 1], corners[k]);
            let length = (b.position - a.position).norm().max(1e-12);
            let entry = b.toward(&a, radius(k) / length);
            // The straight line up to where the next zone begins.
            joints = self.follow_segment(state, [&from, &entry], joints, (line, held))?;
            if radius(k) > 0.0 {
                let c = corners[k + 1];
                let out_length = (c.position - b.position).norm().max(1e-12);
                let exit = b.toward(&c, radius(k) / out_length);
                joints = self.follow_corner(state, [&entry, &b, &exit], joints, (line, held))?;
                from = exit;
            } else {
                from = b;
                let planned = run[k - 1].1;
                if largest_change(&joints, &planned) > TARGET_MATCH_RAD * 10.0 {
                    return fail(
                        line,
                        format!(
                            "the controller arrives at {joints:?}, not at the plan's {planned:?}"
                        ),
                    );
                }
                joints = planned;
            }
        }
        state.joints = Some(joints);
        Ok(())
    }

    /// Follows the straight line from `a` to `b`, sampled every [`PATH_STEP_M`].
    fn follow_segment(
        &self,
        state: &mut State,
        [a, b]: [&Pose; 2],
        joints: [f64; 6],
        at: (usize, Configuration),
    ) -> Result<[f64; 6], ReadError> {
        let (distance, angle) = a.difference(b);
        let count = ((distance / PATH_STEP_M).max(angle / 1e-3)).ceil().max(1.0) as usize;
        let mut joints = joints;
        for k in 1..=count {
            let pose = a.toward(b, k as f64 / count as f64);
            joints = self.sample(state, &pose, joints, at)?;
        }
        Ok(joints)
    }

    /// Follows the corner's parabola from `entry` past `target` to `exit`.
    fn follow_corner(
        &self,
        state: &mut State,
        [entry, target, exit]: [&Pose; 3],
        joints: [f64; 6],
        at: (usize, Configuration),
    ) -> Result<[f64; 6], ReadError> {
        let length =
            (target.position - entry.position).norm() + (exit.position - target.position).norm();
        let count = (length / PATH_STEP_M).ceil().max(2.0) as usize;
        let mut joints = joints;
        for k in 1..=count {
            let t = k as f64 / count as f64;
            let position = entry.position * ((1.0 - t) * (1.0 - t))
                + target.position * (2.0 * t * (1.0 - t))
                + exit.position * (t * t);
            let pose = Pose {
                position,
                rotation: entry.toward(exit, t).rotation,
            };
            joints = self.sample(state, &pose, joints, at)?;
        }
        Ok(joints)
    }

    /// One sample of a Cartesian path toward the target of line `line` whose configuration
    /// data are `held`: its joints by the solution nearest the last among those holding the
    /// data's `cfx` (`ConfL \On`: the controller keeps the configuration; past a singularity,
    /// where two solutions meet, it leaves on the one the data name), no joint jumping, the
    /// configuration checked, and while the tool is on, the TCP on its task.
    fn sample(
        &self,
        state: &mut State,
        pose: &Pose,
        joints: [f64; 6],
        (line, held): (usize, Configuration),
    ) -> Result<[f64; 6], ReadError> {
        let flange = pose.then(&self.tool.inverse());
        let Some((q, change)) = self
            .arm
            .follow(&flange, &joints, self.plan.limits(), held[3])
        else {
            let (wrist, reach) = self.arm.wrist_reach(&flange);
            return fail(
                line,
                format!(
                    "{:?} is out of reach: its wrist centre lies {wrist:.6} m from axis 2, which \
                     the arm reaches {reach:.6} m from (or a joint limit stands in the way)",
                    pose.position.as_slice()
                ),
            );
        };
        if change > MAX_JOINT_JUMP_RAD {
            return fail(
                line,
                format!("a joint jumps by {change:.4} rad within {PATH_STEP_M} m of the path"),
            );
        }
        self.check_configuration(state, &q, line)?;
        if state.drawing.tool_on {
            self.check_on_task(state, pose, line)?;
        }
        Ok(q)
    }

    /// Runs the pending `MoveAbsJ` run: linear in joint space from where the arm stands, each
    /// fly-by corner on the joint-space parabola between the points where the TCP enters and
    /// leaves its zone, every configuration checked.
    fn end_joint_run(&self, state: &mut State) -> Result<(), ReadError> {
        let run = std::mem::take(&mut state.joint_run);
        let Some(&(end, _, _)) = run.last() else {
            return Ok(());
        };
        if let Some(start) = state.joints {
            let mut vertices = vec![start];
            vertices.extend(run.iter().map(|r| r.0));
            let tcp = |q: &[f64; 6]| self.arm.flange(q).then(&self.tool).position;
            // Where the TCP comes within `radius` of `w` on the edge from `from` to `w`.
            let entering = |from: &[f64; 6], w: &[f64; 6], radius: f64| -> f64 {
                let steps = (largest_change(from, w) / JOINT_STEP_RAD).ceil().max(1.0) as usize;
                let corner = tcp(w);
                (0..=steps)
                    .map(|k| k as f64 / steps as f64)
                    .find(|&t| (tcp(&lerp(from, w, t)) - corner).norm() <= radius)
                    .unwrap_or(1.0)
            };
            let mut from = start;
            for k in 1..vertices.len() {
                let (line, radius) = (run[k - 1].2, run[k - 1].1);
                let w = vertices[k];
                let (entry, exit) = match vertices.get(k + 1) {
                    Some(next) if radius > 0.0 => (
                        lerp(&vertices[k - 1], &w, entering(&vertices[k - 1], &w, radius)),
                        lerp(next, &w, entering(next, &w, radius)),
                    ),
                    _ => (w, w),
                };
                self.check_joint_edge(state, &from, &entry, line)?;
                if entry != w {
                    let steps = (largest_change(&entry, &exit).max(largest_change(&entry, &w))
                        / JOINT_STEP_RAD)
                        .ceil()
                        .max(2.0) as usize;
                    for s in 1..=steps {
                        let t = s as f64 / steps as f64;
                        let q: [f64; 6] = std::array::from_fn(|j| {
                            entry[j] * (1.0 - t) * (1.0 - t)
                                + w[j] * 2.0 * t * (1.0 - t)
                                + exit[j] * t * t
                        });
                        self.check_configuration(state, &q, line)?;
                    }
                }
                from = exit;
            }
        }
        state.joints = Some(end);
        Ok(())
    }

    /// Checks the configurations along the joint-space edge from `a` to `b`.
    fn check_joint_edge(
        &self,
        state: &mut State,
        a: &[f64; 6],
        b: &[f64; 6],
        line: usize,
    ) -> Result<(), ReadError> {
        let steps = (largest_change(a, b) / JOINT_STEP_RAD).ceil().max(1.0) as usize;
        for k in 1..=steps {
            self.check_configuration(state, &lerp(a, b, k as f64 / steps as f64), line)?;
        }
        Ok(())
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

    /// Checks a TCP pose while the tool is on ([`PlanChecks::on_task`]).
    fn check_on_task(&self, state: &mut State, pose: &Pose, line: usize) -> Result<(), ReadError> {
        let axis = pose.rotation * Vec3::z();
        self.plan
            .on_task(&mut state.drawing, &pose.position, &axis)
            .or_else(|problem| fail(line, problem))
    }

    /// The TCP where the arm stands.
    fn tcp(&self, state: &State, line: usize) -> Result<Pose, ReadError> {
        let joints = state
            .joints
            .ok_or_else(|| ReadError::at(line, "the tool switches before the first move"))?;
        Ok(self.arm.flange(&joints).then(&self.tool))
    }

    /// The tool switched on ([`PlanChecks::switch_on`]).
    fn switch_on(&self, state: &mut State, line: usize) -> Result<(), ReadError> {
        let pose = self.tcp(state, line)?;
        self.plan
            .switch_on(
                &mut state.drawing,
                &pose.position,
                &(pose.rotation * Vec3::z()),
            )
            .or_else(|problem| fail(line, problem))
    }

    /// The tool switched off ([`PlanChecks::switch_off`]).
    fn switch_off(&self, state: &mut State, line: usize) -> Result<(), ReadError> {
        let pose = self.tcp(state, line)?;
        self.plan
            .switch_off(&mut state.drawing, &pose.position)
            .or_else(|problem| fail(line, problem))
    }
}

/// The configuration `t` of the way from `a` to `b`, linear in joint space.
fn lerp(a: &[f64; 6], b: &[f64; 6], t: f64) -> [f64; 6] {
    std::array::from_fn(|j| a[j] + (b[j] - a[j]) * t)
}
