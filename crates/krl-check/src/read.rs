//! A KRL program read back: its statements run as the controller runs them, what the arm does
//! checked against the job's plan with the independent checker.

use std::collections::BTreeMap;

use emg_job::JobFile;
use emg_program_check::{
    CartesianTarget, Controller, Drawing, Drawn, JointTarget, PlanChecks, PlanConfigurations, Pose,
    ReadError, TARGET_MATCH_RAD, fail,
};
use emg_verify::ReferenceModel;

use crate::arm::{Kr16, StatusTurn, kuka_pose, ros_frame};
use crate::parse::{Action, DataList, Declaration, Motion, Statement, parse_dat, parse_src};

/// The closest two consecutive Cartesian targets may lie (m).
pub const MIN_TARGET_SPACING_M: f64 = 1e-4;

/// The fields of a `FRAME`.
const FRAME_FIELDS: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
/// The fields of an `E6POS`.
const E6POS_FIELDS: [&str; 14] = [
    "X", "Y", "Z", "A", "B", "C", "S", "T", "E1", "E2", "E3", "E4", "E5", "E6",
];
/// The fields of an `E6AXIS`.
const E6AXIS_FIELDS: [&str; 12] = [
    "A1", "A2", "A3", "A4", "A5", "A6", "E1", "E2", "E3", "E4", "E5", "E6",
];

/// What the reader found.
#[derive(Clone, Debug, PartialEq)]
pub struct KrlReport {
    /// `PTP` instructions.
    pub ptp: usize,
    /// `LIN` instructions.
    pub lin: usize,
    /// Largest distance (rad, any joint) of a target's solution from the plan's configuration.
    pub worst_target_rad: f64,
    /// Smallest distance (m) between consecutive Cartesian targets.
    pub least_spacing_m: f64,
    /// What the arm drew.
    pub drawn: Drawn,
}

/// A value as the controller holds it: KRL's `REAL` is single precision.
fn real(value: f64) -> f64 {
    value as f32 as f64
}

/// What the program declares and the plan holds.
struct Reading<'a> {
    /// The arm with the program's tool (set before its first move), run against the plan.
    controller: Controller<'a, Kr16>,
    model: &'a ReferenceModel,
    data: DataList,
    /// The plan's configurations: its samples and its moves' vertices.
    configurations: PlanConfigurations,
    /// The tool's `$OUT` number and the level that switches it on.
    output: (u32, bool),
}

/// The controller's state as the program runs.
struct State {
    joints: Option<[f64; 6]>,
    /// `TOOL_DATA[n]` and `BASE_DATA[n]` set by the program (KUKA's frames).
    tool_data: BTreeMap<String, Pose>,
    base_data: BTreeMap<String, Pose>,
    /// `$TOOL` and `$BASE` (KUKA's frames), until the first move.
    tool: Option<Pose>,
    base: Option<Pose>,
    /// Whether the program has moved (its tool and base fixed from then on).
    moved: bool,
    interpolates_in_base: bool,
    orientation_varies: bool,
    advance: i64,
    /// `$APO.CDIS` (m).
    approximation_m: Option<f64>,
    drawing: Drawing,
    /// The pending approximated `LIN` run, each target holding its Status.
    run: Vec<CartesianTarget<u8>>,
    /// The Status the arm stands in where the pending run starts.
    run_status: Option<u8>,
    last_target: Option<Pose>,
    /// `PTP` and `LIN` instructions met.
    moves: [usize; 2],
    worst_target_rad: f64,
    least_spacing_m: f64,
}

/// Reads the KRL program `src` and its data list `dat` against the job's plan `file` with the
/// checker `model` of the KR 16-2 (base `base_link`, tip `pen_tip`). A refusal names the line of
/// the `.src` file (and the `.dat` line of the point it moves to).
pub fn read_krl(
    src: &str,
    dat: &str,
    file: &JobFile,
    model: &ReferenceModel,
) -> Result<KrlReport, ReadError> {
    let program = parse_src(src)?;
    let data = parse_dat(dat)?;
    if data.name != program.name {
        return fail(
            0,
            format!(
                "the .dat file is {}'s data list, not {}'s",
                data.name, program.name
            ),
        );
    }
    let plan = PlanChecks::new(file, model).or_else(|problem| fail(0, problem))?;
    let tool_output = file.settings.tool_output;
    let mut reading = Reading {
        controller: Controller {
            arm: Kr16::default(),
            plan,
            tool: Pose::identity(),
        },
        model,
        data,
        configurations: PlanConfigurations::of(file),
        output: (tool_output.number + 1, tool_output.on_high),
    };
    let mut state = State {
        joints: None,
        tool_data: BTreeMap::new(),
        base_data: BTreeMap::new(),
        tool: None,
        base: None,
        moved: false,
        interpolates_in_base: false,
        orientation_varies: false,
        advance: 1,
        approximation_m: None,
        drawing: reading.controller.plan.start(file.strokes.len()),
        run: Vec::new(),
        run_status: None,
        last_target: None,
        moves: [0, 0],
        worst_target_rad: 0.0,
        least_spacing_m: f64::INFINITY,
    };
    for statement in &program.statements {
        reading.execute(&mut state, statement)?;
    }
    let last_line = src.lines().count();
    if !state.run.is_empty() {
        return fail(
            last_line,
            "the program ends on an approximated point: its last move is no exact stop",
        );
    }
    let drawn = reading.controller.finish(&state.drawing, file, last_line)?;
    Ok(KrlReport {
        ptp: state.moves[0],
        lin: state.moves[1],
        worst_target_rad: state.worst_target_rad,
        least_spacing_m: state.least_spacing_m,
        drawn,
    })
}

impl Reading<'_> {
    /// The declaration of the point `name` of type `data_type`, else why not.
    fn point(&self, name: &str, data_type: &str, line: usize) -> Result<&Declaration, ReadError> {
        let declaration = self.data.declarations.get(name).ok_or_else(|| {
            ReadError::at(line, format!("{name} is not declared in the .dat file"))
        })?;
        if declaration.data_type != data_type {
            return fail(
                line,
                format!(
                    "{name} (.dat line {}) is {}, not {data_type}",
                    declaration.line, declaration.data_type
                ),
            );
        }
        Ok(declaration)
    }

    /// The frame `name` declared as a `FRAME` (KUKA's, mm and degrees, as the controller holds
    /// them).
    fn frame(&self, name: &str, line: usize) -> Result<Pose, ReadError> {
        let declaration = self.point(name, "FRAME", line)?;
        let values = declaration
            .values(name, &FRAME_FIELDS)
            .or_else(|problem| fail(line, problem))?;
        Ok(kuka_pose(std::array::from_fn(|i| real(values[i]))))
    }

    /// The frame an assignment's value names: `TOOL_DATA[n]`/`BASE_DATA[n]` as set, or a
    /// declared `FRAME`.
    fn named_frame(
        &self,
        value: &str,
        set: &BTreeMap<String, Pose>,
        line: usize,
    ) -> Result<Pose, ReadError> {
        let name = value.to_ascii_uppercase();
        match set.get(&name) {
            Some(frame) => Ok(*frame),
            None if name.contains('[') => {
                fail(line, format!("{name} is not set before it is used"))
            }
            None => self.frame(&name, line),
        }
    }

    /// Whether the arm has a pending approximated run, which a statement that stops the advance
    /// run (`$OUT`, `WAIT SEC`, a `PTP`) would cut short.
    fn refuse_after_approximation(
        &self,
        state: &State,
        what: &str,
        line: usize,
    ) -> Result<(), ReadError> {
        if state.run.is_empty() {
            Ok(())
        } else {
            fail(
                line,
                format!(
                    "{what} after an approximated point: the advance-run stop makes the arm stop \
                     there rather than pass it"
                ),
            )
        }
    }

    fn execute(&mut self, state: &mut State, statement: &Statement) -> Result<(), ReadError> {
        let line = statement.line;
        match &statement.action {
            Action::WaitSec(time) => {
                if *time < 0.0 {
                    return fail(line, "WAIT SEC with a negative time");
                }
                self.refuse_after_approximation(state, "WAIT SEC", line)
            }
            Action::Assign { target, value } => self.assign(state, target, value, line),
            Action::Move {
                motion: Motion::Ptp,
                point,
                approximation,
            } => {
                state.moves[0] += 1;
                if let Some(approximation) = approximation {
                    return fail(
                        line,
                        format!("PTP {point} {approximation}: a job's PTP stops exactly"),
                    );
                }
                self.refuse_after_approximation(state, "PTP", line)?;
                self.start_moving(state, line)?;
                if state.drawing.tool_on {
                    return fail(line, "PTP with the tool on");
                }
                let declaration = self.point(point, "E6AXIS", line)?;
                let values = declaration
                    .values(point, &E6AXIS_FIELDS)
                    .or_else(|problem| fail(line, problem))?;
                external_axes(&values[6..], point, line)?;
                let q: [f64; 6] = std::array::from_fn(|i| real(values[i]).to_radians());
                let (error, _) = self.configurations.nearest(&q);
                if error > TARGET_MATCH_RAD {
                    return fail(
                        line,
                        format!(
                            "PTP {point} is no configuration of the plan ({error:.3e} rad away)"
                        ),
                    );
                }
                let target = JointTarget {
                    joints: q,
                    zone_m: 0.0,
                    line,
                };
                state.joints =
                    self.controller
                        .joint_run(&mut state.drawing, state.joints, &[target])?;
                state.last_target = None;
                Ok(())
            }
            Action::Move {
                motion: Motion::Lin,
                point,
                approximation,
            } => {
                state.moves[1] += 1;
                self.start_moving(state, line)?;
                self.lin(state, point, approximation.as_deref(), line)
            }
        }
    }

    /// The program's first move fixes its tool and base: both must be set, the tool the
    /// checker's tip.
    fn start_moving(&mut self, state: &mut State, line: usize) -> Result<(), ReadError> {
        if state.moved {
            return Ok(());
        }
        let (Some(tool), Some(_)) = (state.tool, state.base) else {
            return fail(line, "the first move before $TOOL and $BASE are set");
        };
        // KUKA's tool frame (x along the tool) in KUKA's flange frame, as the TCP (z along the
        // tool) in ROS-Industrial's `tool0` frame.
        let flange_in_tool0 = ros_frame(&Pose::identity()).inverse();
        self.controller.tool = flange_in_tool0.then(&ros_frame(&tool));
        if let Some(q) = self.configurations.first() {
            let q = *q;
            self.controller
                .tool_is_tip(self.model, &q)
                .or_else(|problem| fail(line, format!("$TOOL: {problem}")))?;
        }
        state.moved = true;
        Ok(())
    }

    /// A `LIN` to `point`, approximated where `approximation` is `C_DIS`.
    fn lin(
        &mut self,
        state: &mut State,
        point: &str,
        approximation: Option<&str>,
        line: usize,
    ) -> Result<(), ReadError> {
        if !state.interpolates_in_base || !state.orientation_varies {
            return fail(
                line,
                "LIN before $IPO_MODE=#BASE and $ORI_TYPE=#VAR: the path would not be the one \
                 read here",
            );
        }
        let zone_m = match approximation {
            None => 0.0,
            Some("C_DIS") => {
                if state.advance < 1 {
                    return fail(line, "C_DIS with $ADVANCE 0: no approximation is possible");
                }
                state
                    .approximation_m
                    .ok_or_else(|| ReadError::at(line, "C_DIS before $APO.CDIS is set"))?
            }
            Some(other) => {
                return fail(
                    line,
                    format!("LIN {point} {other}: a job's LIN approximates by C_DIS"),
                );
            }
        };
        let declaration = self.point(point, "E6POS", line)?;
        let dat_line = declaration.line;
        let values = declaration
            .values(point, &E6POS_FIELDS)
            .or_else(|problem| fail(line, problem))?;
        external_axes(&values[8..], point, line)?;
        let (status, turn) = (values[6], values[7]);
        if status.fract() != 0.0 || !(0.0..8.0).contains(&status) {
            return fail(line, format!("{point}'s Status S {status} is not 0 to 7"));
        }
        if turn.fract() != 0.0 || !(0.0..64.0).contains(&turn) {
            return fail(line, format!("{point}'s Turn T {turn} is not 0 to 63"));
        }
        let configuration = StatusTurn {
            status: status as u8,
            turn: turn as u8,
        };
        let Some(base) = state.base else {
            return fail(line, "a LIN before $BASE is set");
        };
        let in_base = kuka_pose(std::array::from_fn(|i| real(values[i])));
        let pose = ros_frame(&base.then(&in_base));
        let flange = pose.then(&self.controller.tool.inverse());
        let q = self
            .controller
            .arm
            .solve(&flange, configuration, self.controller.plan.limits())
            .map_err(|count| {
                ReadError::at(
                    line,
                    format!(
                        "{point} (.dat line {dat_line}): its Status and Turn {configuration:?} \
                         select {count} solutions, not one"
                    ),
                )
            })?;
        let (error, _) = self.configurations.nearest(&q);
        state.worst_target_rad = state.worst_target_rad.max(error);
        if error > TARGET_MATCH_RAD {
            return fail(
                line,
                format!(
                    "{point} (.dat line {dat_line}): its solution by Status and Turn \
                     {configuration:?} is no configuration of the plan ({error:.3e} rad away)"
                ),
            );
        }
        let Some(joints) = state.joints else {
            return fail(
                line,
                "a LIN before the arm's joints are known (no PTP before it)",
            );
        };
        // A LIN keeps the Status the arm stands in: KUKA ignores a LIN target's S and T.
        let standing = *state
            .run_status
            .get_or_insert(self.controller.arm.status_turn(&joints).status);
        if !self.controller.arm.holds_status(&q, standing) {
            return fail(
                line,
                format!(
                    "{point} (.dat line {dat_line}) has Status {}, the arm stands in Status \
                     {standing}: a LIN cannot change it",
                    configuration.status
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
                        "{point} lies {:.4} mm from the target before: closer than {} mm",
                        spacing * 1e3,
                        MIN_TARGET_SPACING_M * 1e3
                    ),
                );
            }
        }
        state.last_target = Some(pose);
        state.run.push(CartesianTarget {
            pose,
            joints: q,
            zone_m,
            line,
            held: standing,
        });
        if zone_m == 0.0 {
            let run = std::mem::take(&mut state.run);
            state.run_status = None;
            state.joints = Some(
                self.controller
                    .cartesian_run(&mut state.drawing, joints, &run)?,
            );
        }
        Ok(())
    }

    /// An assignment: the tool, the base, the interpolation's settings, the speeds, the
    /// approximation distance and the tool's output.
    fn assign(
        &mut self,
        state: &mut State,
        target: &str,
        value: &str,
        line: usize,
    ) -> Result<(), ReadError> {
        let number = |what: &str| -> Result<f64, ReadError> {
            value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| ReadError::at(line, format!("{what} is `{value}`, not a number")))
        };
        let fixed_after_moving = |what: &str| -> Result<(), ReadError> {
            if state.moved {
                fail(
                    line,
                    format!("{what} changes after the first move: a job's program keeps one"),
                )
            } else {
                Ok(())
            }
        };
        match target {
            t if t.starts_with("TOOL_DATA[") || t.starts_with("BASE_DATA[") => {
                fixed_after_moving(t)?;
                let frame = self.frame(&value.to_ascii_uppercase(), line)?;
                let set = if t.starts_with("TOOL") {
                    &mut state.tool_data
                } else {
                    &mut state.base_data
                };
                set.insert(t.to_string(), frame);
            }
            "$TOOL" => {
                fixed_after_moving(target)?;
                state.tool = Some(self.named_frame(value, &state.tool_data, line)?);
            }
            "$BASE" => {
                fixed_after_moving(target)?;
                state.base = Some(self.named_frame(value, &state.base_data, line)?);
            }
            "$IPO_MODE" => state.interpolates_in_base = value.eq_ignore_ascii_case("#BASE"),
            "$ORI_TYPE" => state.orientation_varies = value.eq_ignore_ascii_case("#VAR"),
            "$ADVANCE" => {
                let advance = number(target)?;
                if advance.fract() != 0.0 || !(0.0..=5.0).contains(&advance) {
                    return fail(line, format!("$ADVANCE {value} is not 0 to 5"));
                }
                state.advance = advance as i64;
            }
            "$VEL.CP" => {
                if number(target)? <= 0.0 {
                    return fail(line, format!("$VEL.CP {value} m/s: not a speed"));
                }
            }
            "$APO.CDIS" => {
                let mm = number(target)?;
                if mm < 0.0 {
                    return fail(line, format!("$APO.CDIS {value} mm: not a distance"));
                }
                state.approximation_m = Some(real(mm) / 1e3);
            }
            t if t.starts_with("$VEL_AXIS[") || t.starts_with("$ACC_AXIS[") => {
                let percent = number(t)?;
                if percent <= 0.0 || percent > 100.0 {
                    return fail(line, format!("{t} {value} % is not in (0, 100]"));
                }
            }
            t if t.starts_with("$OUT[") => {
                let number = t
                    .strip_prefix("$OUT[")
                    .and_then(|n| n.strip_suffix(']'))
                    .and_then(|n| n.parse::<u32>().ok());
                if number != Some(self.output.0) {
                    return fail(
                        line,
                        format!("{t}: not the tool's output $OUT[{}]", self.output.0),
                    );
                }
                let level = match value.to_ascii_uppercase().as_str() {
                    "TRUE" => true,
                    "FALSE" => false,
                    _ => return fail(line, format!("{t}={value}: neither TRUE nor FALSE")),
                };
                self.refuse_after_approximation(state, t, line)?;
                self.controller.switch(
                    &mut state.drawing,
                    state.joints,
                    level == self.output.1,
                    line,
                )?;
            }
            other => {
                return fail(
                    line,
                    format!("{other} is not a variable a job's program sets"),
                );
            }
        }
        Ok(())
    }
}

/// Refuses external axes other than 0 (the arm has none).
fn external_axes(values: &[f64], point: &str, line: usize) -> Result<(), ReadError> {
    if values.iter().any(|v| *v != 0.0) {
        return fail(line, format!("{point} moves external axes the arm has not"));
    }
    Ok(())
}
