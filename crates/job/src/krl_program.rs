//! A job's program as a KRL program for a KUKA controller (KR C4 / KR C5, KSS 8): a `.src` file
//! with the moves and a `.dat` file with their points, as KUKA's own inline forms keep them. The
//! controller moves the tool itself, with its own kinematics and approximation, through targets
//! taken from the plan ([`crate::controller_targets`], chosen as for every controller, each
//! approximated corner's path taken as a parabola inside the triangle of its ends and its
//! target).
//!
//! * `TOOL_DATA[1]` is set to `EMG_TOOL`, the TCP (the pen's tip) in KUKA's flange frame
//!   (`$FLANGE`: x out of the flange along A6), the tool's x axis along the tool (KUKA's tool
//!   direction); `BASE_DATA[1]` to `EMG_PART`, the part's frame in the robot root frame (where
//!   the job has one work surface: its origin the surface's point, z out of the part, x along
//!   the surface's direction; else the root frame). `$TOOL` and `$BASE` are set from them, and
//!   every Cartesian target is an `E6POS` in that base, in millimetres, its orientation KUKA's
//!   `A, B, C` (about z, then the new y, then the new x, degrees), with the Status and Turn
//!   ([`KukaConfiguration`]) of the plan's joints there.
//! * The moves between strokes: `PTP` through the plan's joint vertices as `E6AXIS` (degrees,
//!   KUKA's axis directions, which ROS-Industrial's descriptions keep), each an exact stop (the
//!   controller's PTP approximation, a share of its machine data, is not used); the lift off a
//!   stroke and the set-down onto the next as `LIN` to an exact stop.
//! * A stroke part: at rest on its start, the tool switched on (`$OUT`, then `WAIT SEC` its
//!   lead), a run of `LIN` through its targets at the plan's tool speed (`$VEL.CP`), each inner
//!   corner approximated with `C_DIS` by the corner radius the targets allow (`$APO.CDIS`, mm),
//!   an exact stop at the end, then `WAIT SEC` its lag and the tool off. The switching happens
//!   at rest, where the plan switches: the plan's lead and lag are dwells, not shifts along a
//!   moving path (which `TRIGGER WHEN DISTANCE` would make).
//! * No two consecutive targets of a stroke lie closer than [`crate::MIN_TARGET_SPACING_M`]; no
//!   approximation reaches past [`crate::controller_targets::BLEND_LENGTH_SHARE`] of either
//!   neighbouring line (the controller itself bounds it by half of each).

use std::path::Path;

use emg_control::Task;
use emg_kinematics::{JointVector, Robot, Vec3};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

use crate::controller_targets::{
    Corner, Pose, StepWriter, TargetRules, segment_configurations, write_steps,
};
use crate::free_space::FreeSpace;
use crate::industrial::{fixed, part_frame, spaced};
use crate::kuka_configuration::KukaConfiguration;
use crate::program::JobFile;
use crate::reach::WristReach;
use crate::tool_output::ToolOutput;

/// The longest name KRL gives a program (its file's name).
const MAX_NAME_CHARS: usize = 24;

/// The smallest approximation distance written (mm): below it the corner is an exact stop.
const MIN_CDIS_MM: f64 = 0.01;

/// A KRL program and what it holds.
#[derive(Clone, Debug)]
pub struct KrlProgram {
    /// The `.src` file's text.
    pub src: String,
    /// The `.dat` file's text.
    pub dat: String,
    /// Stroke parts drawn (each with the tool switched on once).
    pub stroke_parts: usize,
    /// `PTP` instructions.
    pub ptp: usize,
    /// `LIN` instructions.
    pub lin: usize,
    /// The largest distance (m) from its stroke of the straight lines between a stroke's targets.
    pub worst_chord_m: f64,
}

/// Why a job's program cannot be written as a KRL program.
#[derive(Debug, thiserror::Error)]
pub enum KrlProgramError {
    /// Not a six-joint arm.
    #[error("a KRL program needs a six-joint KUKA arm; this one has {0} joints")]
    Joints(usize),
    /// The program's file name is not a KRL name.
    #[error(
        "a KRL program is named by its file: `{0}` is not a KRL name (a letter or _ first, then \
         letters, digits or _, at most 24): name the output file so"
    )]
    Name(String),
    /// The flange's chain is not the arm's.
    #[error(
        "the chain to the flange (tool0) has {flange} joints, the arm's {arm}: not the same arm"
    )]
    Flange {
        /// The flange chain's joints.
        flange: usize,
        /// The arm's joints.
        arm: usize,
    },
    /// A stroke segment without its task.
    #[error("segments[{0}] is a stroke part without its task: plan the job again")]
    NoTask(usize),
}

/// The TCP of `robot` in the frame of the flange `flange` (the same arm's chain to
/// ROS-Industrial's `tool0`, z out of the flange), at the arm's zeros.
pub fn tool_in_flange(robot: &Robot, flange: &Robot) -> Result<Isometry3<f64>, KrlProgramError> {
    if flange.dof() != robot.dof() {
        return Err(KrlProgramError::Flange {
            flange: flange.dof(),
            arm: robot.dof(),
        });
    }
    let frame = |arm: &Robot| {
        let kinematics = arm.forward(&arm.joint_vector(&vec![0.0; arm.dof()]));
        let pose = Pose::from_matrix(kinematics.tcp(), kinematics.tcp_rotation());
        Isometry3::from_parts(Translation3::from(pose.position), pose.rotation)
    };
    Ok(frame(flange).inverse() * frame(robot))
}

/// The name of the KRL program written to `out`: its file's stem, if a KRL name.
fn program_name(out: &Path) -> Result<String, KrlProgramError> {
    let stem = out
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or_default()
        .to_string();
    let mut chars = stem.chars();
    let valid = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && stem.len() <= MAX_NAME_CHARS;
    if valid {
        Ok(stem)
    } else {
        Err(KrlProgramError::Name(stem))
    }
}

/// The `.src` file a KRL program written beside the job's program `program` goes to: KRL names
/// a program by its file, so its name is the part of `program`'s name before its first dot
/// (`house.job.json` → `house.src`), each character KRL does not allow in a name made `_`, an
/// `_` put first where it would start with a digit, at most 24 characters.
pub fn krl_path_beside(program: &Path) -> std::path::PathBuf {
    let file_name = program
        .file_name()
        .and_then(|s| s.to_str())
        .unwrap_or_default();
    let stem = file_name.split('.').next().unwrap_or_default();
    let mut name: String = stem
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if !name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
        name.insert(0, '_');
    }
    name.truncate(MAX_NAME_CHARS);
    program.with_file_name(format!("{name}.src"))
}

/// `file`'s program exported as a KRL program to `out` (the `.src`) and the `.dat` beside it,
/// in memory ([`emg_io::Export::write`] writes them), recorded in their headers as written for
/// `reference`; `tool_in_flange` is the TCP in ROS-Industrial's `tool0` frame
/// ([`tool_in_flange`]).
pub fn krl_program_export(
    file: &JobFile,
    robot: &Robot,
    tool_in_flange: &Isometry3<f64>,
    reference: &str,
    out: &Path,
) -> Result<emg_io::Export, KrlProgramError> {
    let name = program_name(out)?;
    let tool = file.settings.tool_output;
    let header = vec![
        format!("written by emg from a job's program for robot {reference}"),
        format!(
            "for a KUKA controller (KR C4, KR C5): copy {name}.src and {name}.dat to KRC:\\R1\\Program \
             and run {name} (docs/robot-export.md)"
        ),
        "targets in mm in BASE_DATA[1] = EMG_PART, orientations as A, B, C (degrees, about z, \
         y, x), Status and Turn of the planned joints; axes in degrees"
            .to_string(),
        format!(
            "the tool: {tool}, switched by $OUT[{}]; the program sets TOOL_DATA[1] and \
             BASE_DATA[1]: change the numbers where the cell keeps others there",
            output_number(&tool)
        ),
        match &file.home {
            Some(_) => "the program starts with PTP to the arm's home, from wherever the arm \
                        stands: clear that way"
                .to_string(),
            None => "the first PTP starts from wherever the arm stands: clear that way".to_string(),
        },
    ];
    let program = krl_program(file, robot, tool_in_flange, &name, &header)?;
    let summary = format!(
        "KRL for a KUKA controller: {name}.src with {} moves ({} PTP, {} LIN) for {} stroke \
         parts, each a LIN run within {:.3} mm of its stroke between targets, the tool on \
         $OUT[{}], and {name}.dat with their points",
        program.ptp + program.lin,
        program.ptp,
        program.lin,
        program.stroke_parts,
        program.worst_chord_m * 1e3,
        output_number(&tool),
    );
    Ok(emg_io::Export {
        format: emg_io::ExportFormat::Krl,
        files: vec![
            (out.to_path_buf(), program.src.into_bytes()),
            (out.with_extension("dat"), program.dat.into_bytes()),
        ],
        thinning: None,
        servoj_targets: 0,
        summary,
    })
}

/// The `$OUT` number of the tool's output: KUKA numbers its outputs from 1, the job's settings
/// from 0.
fn output_number(tool: &ToolOutput) -> u32 {
    tool.number + 1
}

/// A frame in KUKA's terms (x along the tool or out of the flange) from ROS-Industrial's (z
/// along it): turned by −90° about its own y axis.
fn kuka_frame(rotation: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
    rotation * about_y(-std::f64::consts::FRAC_PI_2)
}

/// The turn by `angle` (rad) about the y axis.
fn about_y(angle: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&emg_kinematics::rotation_about(&Vec3::y(), angle))
}

/// Below this `cos B` a frame is taken as turned by exactly ±90° about its y axis (`C` = 0):
/// closer to that lock, `A` and `C` read from the frame's matrix lose more than the frame
/// itself turns.
const GIMBAL_LOCK_COS: f64 = 1e-8;

/// KUKA's `A, B, C` (rad) of `rotation`: the angles about z, then the new y, then the new x
/// that turn the frame there (`Rz(A) Ry(B) Rx(C)`), read from its matrix so that they compose
/// back to it within about 1e-8 rad wherever `B` stands, ±90° included.
fn abc(rotation: &UnitQuaternion<f64>) -> [f64; 3] {
    let r = rotation.to_rotation_matrix().into_inner();
    let cos_b = libm::hypot(r[(0, 0)], r[(1, 0)]);
    let b = libm::atan2(-r[(2, 0)], cos_b);
    if cos_b > GIMBAL_LOCK_COS {
        [
            libm::atan2(r[(1, 0)], r[(0, 0)]),
            b,
            libm::atan2(r[(2, 1)], r[(2, 2)]),
        ]
    } else {
        // Rz(A) Ry(±90°): its second column is (−sin A, cos A, 0).
        [libm::atan2(-r[(0, 1)], r[(1, 1)]), b, 0.0]
    }
}

/// `X x,Y y,Z z,A a,B b,C c` of `pose` (mm to 0.1 µm, degrees to 1e-6: KUKA's REAL holds no
/// more).
fn frame_text(pose: &Isometry3<f64>) -> String {
    let p = pose.translation.vector * 1e3;
    let [a, b, c] = abc(&pose.rotation);
    format!(
        "X {},Y {},Z {},A {},B {},C {}",
        fixed(p.x, 4),
        fixed(p.y, 4),
        fixed(p.z, 4),
        fixed(a.to_degrees(), 6),
        fixed(b.to_degrees(), 6),
        fixed(c.to_degrees(), 6)
    )
}

/// The external axes of an `E6POS` or `E6AXIS`: none.
const NO_EXTERNAL_AXES: &str = "E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0";

/// `q`'s axes in degrees as an `E6AXIS`, no external axes.
fn axis_text(robot: &Robot, q: &JointVector) -> String {
    let axes: Vec<String> = robot
        .joints_of(q)
        .iter()
        .enumerate()
        .map(|(i, v)| format!("A{} {}", i + 1, fixed(v.to_degrees(), 6)))
        .collect();
    format!("{{{},{NO_EXTERNAL_AXES}}}", axes.join(","))
}

/// The approximation distance (mm, rounded down to a micrometre) of a corner radius `radius_m`
/// (m); `None` (an exact stop) below [`MIN_CDIS_MM`].
fn cdis_mm(radius_m: f64) -> Option<f64> {
    let mm = (radius_m * 1e6).floor() / 1e3;
    (mm >= MIN_CDIS_MM).then_some(mm)
}

/// `job`'s program as a KRL program named `name` for `robot` (six joints, ROS-Industrial's KUKA
/// frames; its TCP `tool_in_flange` in `tool0`'s frame), with `header` as comment lines.
pub fn krl_program(
    file: &JobFile,
    robot: &Robot,
    tool_in_flange: &Isometry3<f64>,
    name: &str,
    header: &[String],
) -> Result<KrlProgram, KrlProgramError> {
    if robot.dof() != 6 {
        return Err(KrlProgramError::Joints(robot.dof()));
    }
    let free = FreeSpace::new(robot, file.surfaces.clone(), &file.constraints);
    let mut writer = Writer {
        rules: TargetRules::for_job(
            file,
            (robot, &free),
            Corner::Parabola,
            WristReach::of(robot),
        ),
        part: part_frame(file),
        output: output_number(&file.settings.tool_output),
        tool: file.settings.tool_output,
        body: String::new(),
        points: String::new(),
        velocity: None,
        approximation: None,
        joint_points: 0,
        program: KrlProgram {
            src: String::new(),
            dat: String::new(),
            stroke_parts: 0,
            ptp: 0,
            lin: 0,
            worst_chord_m: 0.0,
        },
    };
    let samples = segment_configurations(file);
    writer.switch(false);
    match file.home.as_ref() {
        Some(home) => {
            writer.line("; the program's start, from wherever the arm stands: clear that way");
            writer.ptp(&robot.joint_vector(home), Some("EMG_HOME"));
        }
        None => {
            if let Some(first) = samples.first().and_then(|s| s.first()) {
                writer.line("; the program's start, from wherever the arm stands: clear that way");
                writer.ptp(first, None);
            }
        }
    }
    write_steps(file, robot, &samples, &mut writer).map_err(KrlProgramError::NoTask)?;
    writer.finish(name, tool_in_flange, header);
    Ok(writer.program)
}

/// The program being written, and what it is written from.
struct Writer<'a> {
    rules: TargetRules<'a>,
    /// `EMG_PART` in the robot root frame.
    part: Isometry3<f64>,
    tool: ToolOutput,
    /// The tool's `$OUT` number.
    output: u32,
    /// The `.src` file's statements.
    body: String,
    /// The `.dat` file's point declarations.
    points: String,
    /// The `$VEL.CP` set last (m/s).
    velocity: Option<f64>,
    /// The `$APO.CDIS` set last (mm).
    approximation: Option<f64>,
    /// The `J<n>` points declared.
    joint_points: usize,
    program: KrlProgram,
}

impl StepWriter for Writer<'_> {
    fn rules(&self) -> &TargetRules<'_> {
        &self.rules
    }

    fn comment(&mut self, text: &str) {
        self.line(&format!("; {text}"));
    }

    fn stroke(&mut self, qs: &[JointVector], task: &Task) {
        self.stroke_part(qs, task);
    }

    fn straight_move(&mut self, q: &JointVector, speed: f64) {
        self.lin(q, speed, 0.0);
    }

    fn joint_move(&mut self, q: &JointVector, _radius: f64) {
        self.ptp(q, None);
    }
}

impl Writer<'_> {
    fn line(&mut self, line: &str) {
        self.body.push_str("  ");
        self.body.push_str(line);
        self.body.push('\n');
    }

    /// The tool's output set to switch it on or off.
    fn switch(&mut self, on: bool) {
        let level = if self.tool.level(on) { "TRUE" } else { "FALSE" };
        self.line(&format!("$OUT[{}]={level}", self.output));
    }

    /// `PTP` to the axes `q`, an exact stop, its point named `name` (else the next `J<n>`).
    fn ptp(&mut self, q: &JointVector, name: Option<&str>) {
        self.program.ptp += 1;
        let name = name.map_or_else(
            || {
                self.joint_points += 1;
                format!("J{}", self.joint_points)
            },
            str::to_string,
        );
        let axes = axis_text(self.rules.robot, q);
        self.points
            .push_str(&format!("DECL E6AXIS {name}={axes}\n"));
        self.line(&format!("PTP {name}"));
    }

    /// `LIN` to the TCP pose of `q` at `speed` (m/s), approximated by the corner radius
    /// `radius` (m) there.
    fn lin(&mut self, q: &JointVector, speed: f64, radius: f64) {
        let robot = self.rules.robot;
        let speed = ((speed * 1e4).floor() / 1e4).max(1e-4);
        if self.velocity != Some(speed) {
            self.line(&format!("$VEL.CP={}", fixed(speed, 4)));
            self.velocity = Some(speed);
        }
        let approximation = cdis_mm(radius);
        if let Some(mm) = approximation
            && self.approximation != Some(mm)
        {
            self.line(&format!("$APO.CDIS={}", fixed(mm, 3)));
            self.approximation = Some(mm);
        }
        let tcp = Pose::of(robot, q);
        let in_part = self.part.inverse()
            * Isometry3::from_parts(Translation3::from(tcp.position), kuka_frame(&tcp.rotation));
        let configuration = KukaConfiguration::of(robot, q).text();
        self.program.lin += 1;
        let name = format!("P{}", self.program.lin);
        self.points.push_str(&format!(
            "DECL E6POS {name}={{{},{configuration},{NO_EXTERNAL_AXES}}}\n",
            frame_text(&in_part)
        ));
        let approximate = if approximation.is_some() {
            " C_DIS"
        } else {
            ""
        };
        self.line(&format!("LIN {name}{approximate}"));
    }

    /// A stroke part whose samples are `qs`, along `task`, the tool at rest on its start: the
    /// tool on, a `LIN` run through its targets held [`crate::MIN_TARGET_SPACING_M`] apart
    /// ([`spaced`]), the tool off.
    fn stroke_part(&mut self, qs: &[JointVector], task: &Task) {
        let run = self.rules.stroke(qs, task);
        self.program.worst_chord_m = self.program.worst_chord_m.max(run.worst_chord_m);
        self.program.stroke_parts += 1;
        self.switch(true);
        if self.tool.lead_s > 0.0 {
            self.line(&format!("WAIT SEC {}", self.tool.lead_s));
        }
        for n in spaced(&run.poses, &run.kept) {
            self.lin(&qs[run.kept[n]], run.speeds[n], run.radii[n]);
        }
        if self.tool.lag_s > 0.0 {
            self.line(&format!("WAIT SEC {}", self.tool.lag_s));
        }
        self.switch(false);
    }

    /// The two files' text: `header` as comments; the `.src` setting the tool, the base and the
    /// axes' speeds, then the moves; the `.dat` with the tool, the part and the points.
    fn finish(&mut self, name: &str, tool_in_flange: &Isometry3<f64>, header: &[String]) {
        let comments: String = header.iter().map(|line| format!("; {line}\n")).collect();
        // The TCP in KUKA's flange frame, its x along the tool: both frames turned as
        // [`kuka_frame`] turns them.
        let turn = about_y(std::f64::consts::FRAC_PI_2);
        let tool = Isometry3::from_parts(
            Translation3::from(turn * tool_in_flange.translation.vector),
            turn * kuka_frame(&tool_in_flange.rotation),
        );
        let mut src = format!("&ACCESS RVP\n&REL 1\nDEF {name}( )\n{comments}");
        src.push_str("  TOOL_DATA[1]=EMG_TOOL\n  BASE_DATA[1]=EMG_PART\n");
        src.push_str("  $TOOL=TOOL_DATA[1]\n  $BASE=BASE_DATA[1]\n  $IPO_MODE=#BASE\n");
        src.push_str("  $ORI_TYPE=#VAR\n  $ADVANCE=3\n");
        for axis in 1..=6 {
            src.push_str(&format!(
                "  $VEL_AXIS[{axis}]=100\n  $ACC_AXIS[{axis}]=100\n"
            ));
        }
        src.push_str(&self.body);
        src.push_str("END\n");
        let mut dat = format!("&ACCESS RVP\n&REL 1\nDEFDAT {name}\n{comments}");
        dat.push_str(&format!("DECL FRAME EMG_TOOL={{{}}}\n", frame_text(&tool)));
        dat.push_str(&format!(
            "DECL FRAME EMG_PART={{{}}}\n",
            frame_text(&self.part)
        ));
        dat.push_str(&self.points);
        dat.push_str("ENDDAT\n");
        self.program.src = src;
        self.program.dat = dat;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_program_is_named_by_its_file_if_krl_allows_the_name() {
        assert_eq!(program_name(Path::new("out/house.src")).unwrap(), "house");
        assert_eq!(program_name(Path::new("_a1.src")).unwrap(), "_a1");
        for bad in [
            "my-job.src",
            "1job.src",
            "a_name_longer_than_24_chars.src",
            ".src",
        ] {
            assert!(
                matches!(program_name(Path::new(bad)), Err(KrlProgramError::Name(_))),
                "{bad}"
            );
        }
    }

    #[test]
    fn the_program_beside_a_job_is_named_as_krl_allows() {
        for (program, expected) in [
            ("out/house.job.json", "out/house.src"),
            ("pen-drag-house.job.json", "pen_drag_house.src"),
            ("2024 drawing.json", "_2024_drawing.src"),
            (
                "a_very_long_name_of_a_drawing_file.job.json",
                "a_very_long_name_of_a_dr.src",
            ),
        ] {
            let beside = krl_path_beside(Path::new(program));
            assert_eq!(beside, Path::new(expected));
            assert!(program_name(&beside).is_ok(), "{program}");
        }
    }

    #[test]
    fn an_approximation_distance_is_the_radius_rounded_down_to_a_micrometre() {
        assert_eq!(cdis_mm(0.0), None);
        assert_eq!(cdis_mm(0.99e-5), None);
        assert_eq!(cdis_mm(1e-5), Some(0.01));
        assert_eq!(cdis_mm(0.000_812_9), Some(0.812));
        assert_eq!(cdis_mm(f64::NAN), None);
    }

    #[test]
    fn kukas_tool_direction_is_the_ros_frames_z() {
        let ros = UnitQuaternion::from_rotation_matrix(&emg_kinematics::rotation_from_rpy(
            0.3, -0.2, 1.1,
        ));
        let kuka = kuka_frame(&ros);
        assert!((kuka * Vec3::x() - ros * Vec3::z()).norm() < 1e-12);
    }

    /// `Rz(a) Ry(b) Rx(c)`.
    fn named([a, b, c]: [f64; 3]) -> UnitQuaternion<f64> {
        let about = |axis: Vec3, angle: f64| {
            UnitQuaternion::from_rotation_matrix(&emg_kinematics::rotation_about(&axis, angle))
        };
        about(Vec3::z(), a) * about(Vec3::y(), b) * about(Vec3::x(), c)
    }

    #[test]
    fn a_b_c_compose_back_to_the_frame_at_and_near_the_gimbal_lock() {
        let half_pi = std::f64::consts::FRAC_PI_2;
        for b in [0.3, -1.2, 2.9] {
            let frame = named([0.86, b, -0.63]);
            let read = abc(&frame);
            assert!(named(read).angle_to(&frame) < 1e-12, "{b}");
        }
        // A pen held square to a level part: B at ±90°, give or take what a plan's rounding
        // leaves (a quaternion's own decomposition is off by up to 0.08 rad there).
        for off in [0.0, 1e-12, 1e-9, 9e-9, 1e-8, 2e-8, 1e-7, 1e-5] {
            for sign in [1.0, -1.0] {
                let frame = named([0.86, sign * (half_pi - off), -0.63]);
                let read = abc(&frame);
                let error = named(read).angle_to(&frame);
                assert!(error < 2e-8, "{sign} (90° − {off} rad): {error} rad");
            }
        }
    }
}
