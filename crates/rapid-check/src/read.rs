//! A module read back: its instructions run as the controller runs them, what the arm does
//! checked against the job's plan with the independent checker.

use std::collections::BTreeMap;

use emg_job::JobFile;
use emg_program_check::{
    CartesianTarget, Controller, Drawing, Drawn, JointTarget, PlanChecks, PlanConfigurations, Pose,
    ReadError, TARGET_MATCH_RAD, fail,
};
use emg_verify::ReferenceModel;

use crate::arm::{Configuration, Irb120, rapid_pose};
use crate::parse::{Instruction, Module, Value, parse_module};

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
    /// Largest distance (rad, any joint) of a target's solution from the plan's configuration.
    pub worst_target_rad: f64,
    /// Smallest distance (m) between consecutive Cartesian targets.
    pub least_spacing_m: f64,
    /// What the arm drew.
    pub drawn: Drawn,
}

/// What the module declares and the plan holds.
struct Reading<'a> {
    /// The arm with the module's tool, run against the plan.
    controller: Controller<'a, Irb120>,
    /// The plan's configurations: its samples and its moves' vertices.
    configurations: PlanConfigurations,
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
    /// The pending fly-by `MoveL` run, each target holding its `cfx`.
    run: Vec<CartesianTarget<i32>>,
    /// The pending fly-by `MoveAbsJ` run.
    joint_run: Vec<JointTarget>,
    last_target: Option<Pose>,
    /// `MoveAbsJ` and `MoveL` instructions met.
    moves: [usize; 2],
    worst_target_rad: f64,
    least_spacing_m: f64,
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
        drawing: reading.controller.plan.start(file.strokes.len()),
        run: Vec::new(),
        joint_run: Vec::new(),
        last_target: None,
        moves: [0, 0],
        worst_target_rad: 0.0,
        least_spacing_m: f64::INFINITY,
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
    let drawn = reading.controller.finish(&state.drawing, file, last_line)?;
    Ok(RapidReport {
        move_abs_j: state.moves[0],
        move_l: state.moves[1],
        declared_zones: module
            .declarations
            .iter()
            .filter(|d| d.data_type == "zonedata")
            .count(),
        worst_target_rad: state.worst_target_rad,
        least_spacing_m: state.least_spacing_m,
        drawn,
    })
}

/// A frame `[[x, y, z], [q1, q2, q3, q4]]` (mm, ABB's quaternion order).
fn frame(value: &Value, what: &str, line: usize) -> Result<Pose, ReadError> {
    let parts = value.items(what, 2, line)?;
    let position = parts[0].numbers::<3>(what, line)?;
    let quaternion = parts[1].numbers::<4>(what, line)?;
    rapid_pose(position, quaternion)
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
        let configurations = PlanConfigurations::of(file);
        let controller = Controller {
            arm: Irb120::default(),
            plan,
            tool,
        };
        if let Some(q) = configurations.first() {
            controller
                .tool_is_tip(model, q)
                .or_else(|problem| fail(tooldata.line, problem))?;
        }
        let tool_output = file.settings.tool_output;
        Ok(Self {
            controller,
            configurations,
            work_object,
            zones,
            signal: format!("doEmgTool{}", tool_output.number),
            on_level: tool_output.on_high,
        })
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
                self.controller
                    .switch(&mut state.drawing, state.joints, on, line)?;
            }
            "MoveAbsJ" => {
                state.moves[0] += 1;
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
                let (error, _) = self.configurations.nearest(&q);
                if error > TARGET_MATCH_RAD {
                    return fail(
                        line,
                        format!(
                            "MoveAbsJ target is no configuration of the plan ({error:.3e} rad away)"
                        ),
                    );
                }
                let radius = self.zone(zone, line)?;
                state.joint_run.push(JointTarget {
                    joints: q,
                    zone_m: radius,
                    line,
                });
                state.at_rest = radius == 0.0;
                if radius == 0.0 {
                    let run = std::mem::take(&mut state.joint_run);
                    state.joints =
                        self.controller
                            .joint_run(&mut state.drawing, state.joints, &run)?;
                }
                state.last_target = None;
            }
            "MoveL" => {
                state.moves[1] += 1;
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
                let pose = rapid_pose(position, quaternion)
                    .map(|p| self.work_object.then(&p))
                    .ok_or_else(|| {
                        ReadError::at(line, "the robtarget's quaternion is not a rotation")
                    })?;
                let configuration: Configuration = conf.map(|c| c as i32);
                let flange = pose.then(&self.controller.tool.inverse());
                let q = self
                    .controller
                    .arm
                    .solve(&flange, configuration, self.controller.plan.limits())
                    .map_err(|count| {
                        ReadError::at(
                            line,
                            format!(
                                "the configuration data {configuration:?} select {count} \
                                 solutions of the target, not one"
                            ),
                        )
                    })?;
                let (error, _) = self.configurations.nearest(&q);
                state.worst_target_rad = state.worst_target_rad.max(error);
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
                    state.least_spacing_m = state.least_spacing_m.min(spacing);
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
                state.run.push(CartesianTarget {
                    pose,
                    joints: q,
                    zone_m: radius,
                    line,
                    held: configuration[3],
                });
                state.at_rest = radius == 0.0;
                if radius == 0.0 {
                    let run = std::mem::take(&mut state.run);
                    let Some(joints) = state.joints else {
                        return fail(
                            run[0].line,
                            "a MoveL before the arm's joints are known (no MoveAbsJ before it)",
                        );
                    };
                    state.joints = Some(self.controller.cartesian_run(
                        &mut state.drawing,
                        joints,
                        &run,
                    )?);
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
}
