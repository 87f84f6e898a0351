//! An independent reader of the native URScript programs `emg job --export urscript` writes for
//! the UR5e: a parser of the subset of URScript such a program holds, an interpreter of its
//! moves as the Universal Robots URScript manual defines them (`movej` linear in joint space,
//! `movel` on a straight line with its orientation slerped, runs of `movep` on straight lines
//! joined by circular blends), the UR5e's closed-form inverse kinematics as the controller
//! follows a Cartesian move, and the checks of what the program makes the arm do against the
//! job's plan, measured with the independent checker (`emg_verify`). It shares no code with the
//! exporter: the plan's data types and the checker are all it reads besides the script.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use emg_control::{ConstraintConfig, task_bounds};
use emg_job::{Coverage, JobFile, SegmentKind, Stretch, with_part};
use emg_kinematics::Vec3;
use emg_verify::{Bounds, Joints, Line, ReferenceModel};

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

/// How far (m) below its plan's drawn length each stroke part's covered length may fall.
pub const COVERAGE_ALLOWANCE_M: f64 = 1e-3;

/// Rounding slack (m) of the distance checks, the checker's own.
const SLACK_M: f64 = 1e-9;

/// Rounding slack (degrees) of the tool-angle check, the checker's own.
const SLACK_DEG: f64 = 1e-6;

// The reader's trigonometry comes from the platform's C library: the test crate does not depend
// on `libm`, and the reader compares everything it computes with a tolerance, never bit for bit.

/// The sine of `x` (rad).
#[allow(clippy::disallowed_methods)]
fn sin(x: f64) -> f64 {
    x.sin()
}

/// The cosine of `x` (rad).
#[allow(clippy::disallowed_methods)]
fn cos(x: f64) -> f64 {
    x.cos()
}

/// The four-quadrant arctangent of `y / x` (rad).
#[allow(clippy::disallowed_methods)]
fn atan2(y: f64, x: f64) -> f64 {
    y.atan2(x)
}

/// The arccosine of `x` (rad), `x` clamped to `[-1, 1]`.
#[allow(clippy::disallowed_methods)]
fn acos(x: f64) -> f64 {
    x.clamp(-1.0, 1.0).acos()
}

/// `angle` (rad) wrapped into `(-π, π]`.
pub fn wrap(angle: f64) -> f64 {
    let wrapped = angle - TAU * ((angle + PI) / TAU).floor();
    if wrapped <= -PI {
        wrapped + TAU
    } else {
        wrapped
    }
}

/// The angle (degrees) between two vectors.
pub fn angle_deg(a: &Vec3, b: &Vec3) -> f64 {
    atan2(a.cross(b).norm(), a.dot(b)).to_degrees()
}

/// A rotation matrix, row by row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotation(pub [[f64; 3]; 3]);

impl Rotation {
    /// No rotation.
    pub const IDENTITY: Self = Self([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);

    /// The rotation whose columns are `x`, `y` and `z`.
    pub fn from_columns(x: &Vec3, y: &Vec3, z: &Vec3) -> Self {
        Self([[x.x, y.x, z.x], [x.y, y.y, z.y], [x.z, y.z, z.z]])
    }

    /// Column `c` (the rotated frame's axis `c` in the outer frame).
    pub fn column(&self, c: usize) -> Vec3 {
        Vec3::new(self.0[0][c], self.0[1][c], self.0[2][c])
    }

    /// The inverse rotation.
    pub fn transpose(&self) -> Self {
        let m = &self.0;
        Self([
            [m[0][0], m[1][0], m[2][0]],
            [m[0][1], m[1][1], m[2][1]],
            [m[0][2], m[1][2], m[2][2]],
        ])
    }

    /// The product `self · other`.
    pub fn then(&self, other: &Self) -> Self {
        let (a, b) = (&self.0, &other.0);
        let mut m = [[0.0; 3]; 3];
        for (r, row) in m.iter_mut().enumerate() {
            for (c, value) in row.iter_mut().enumerate() {
                *value = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
            }
        }
        Self(m)
    }

    /// `self · v`.
    pub fn apply(&self, v: &Vec3) -> Vec3 {
        let m = &self.0;
        Vec3::new(
            m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z,
        )
    }

    /// The rotation by `|v|` (rad) about `v` (Rodrigues' formula): URScript's rotation vector.
    pub fn from_rotation_vector(v: &Vec3) -> Self {
        let angle = v.norm();
        if angle < 1e-300 {
            return Self::IDENTITY;
        }
        let a = v / angle;
        let (s, c) = (sin(angle), cos(angle));
        let t = 1.0 - c;
        Self([
            [
                c + t * a.x * a.x,
                t * a.x * a.y - s * a.z,
                t * a.x * a.z + s * a.y,
            ],
            [
                t * a.x * a.y + s * a.z,
                c + t * a.y * a.y,
                t * a.y * a.z - s * a.x,
            ],
            [
                t * a.x * a.z - s * a.y,
                t * a.y * a.z + s * a.x,
                c + t * a.z * a.z,
            ],
        ])
    }

    /// The rotation vector (axis × angle, angle in `[0, π]`) of this rotation.
    pub fn rotation_vector(&self) -> Vec3 {
        let m = &self.0;
        let cosine = ((m[0][0] + m[1][1] + m[2][2] - 1.0) / 2.0).clamp(-1.0, 1.0);
        // sin(angle) × axis.
        let w = Vec3::new(m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]) * 0.5;
        let sine = w.norm();
        let angle = atan2(sine, cosine);
        if sine > 1e-6 || cosine > 0.0 {
            return if sine > 0.0 {
                w * (angle / sine)
            } else {
                Vec3::zeros()
            };
        }
        // Near a half turn: (R + Rᵀ)/2 = cos(angle) I + (1 − cos(angle)) a aᵀ.
        let diagonal = |i: usize| (m[i][i] - cosine) / (1.0 - cosine);
        let k = (0..3)
            .max_by(|&i, &j| diagonal(i).total_cmp(&diagonal(j)))
            .unwrap_or(0);
        let mut axis = Vec3::zeros();
        for i in 0..3 {
            let identity = if i == k { cosine } else { 0.0 };
            axis[i] = ((m[i][k] + m[k][i]) / 2.0 - identity) / (1.0 - cosine);
        }
        let axis = axis / axis.norm();
        let axis = if axis.dot(&w) < 0.0 { -axis } else { axis };
        axis * angle
    }

    /// The angle (rad) of the rotation from `self` to `other`.
    pub fn angle_to(&self, other: &Self) -> f64 {
        self.transpose().then(other).rotation_vector().norm()
    }

    /// The rotation a fraction `s` of the way from `self` to `other` along the shortest turn:
    /// `self · exp(s · log(selfᵀ · other))`.
    pub fn slerp(&self, other: &Self, s: f64) -> Self {
        let relative = self.transpose().then(other).rotation_vector();
        self.then(&Self::from_rotation_vector(&(relative * s)))
    }

    /// The rotation by `angle` about z.
    fn about_z(angle: f64) -> Self {
        let (s, c) = (sin(angle), cos(angle));
        Self([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    }

    /// The rotation by `angle` about x.
    fn about_x(angle: f64) -> Self {
        let (s, c) = (sin(angle), cos(angle));
        Self([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    }
}

/// A rigid pose: a frame's origin and its axes in an outer frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// The origin (m).
    pub position: Vec3,
    /// The axes.
    pub rotation: Rotation,
}

impl Pose {
    /// URScript's `p[x, y, z, rx, ry, rz]`: position (m) and rotation vector.
    pub fn from_ur(values: &[f64; 6]) -> Self {
        Self {
            position: Vec3::new(values[0], values[1], values[2]),
            rotation: Rotation::from_rotation_vector(&Vec3::new(values[3], values[4], values[5])),
        }
    }

    /// The pose as URScript's `p[x, y, z, rx, ry, rz]`.
    pub fn to_ur(self) -> [f64; 6] {
        let v = self.rotation.rotation_vector();
        [
            self.position.x,
            self.position.y,
            self.position.z,
            v.x,
            v.y,
            v.z,
        ]
    }

    /// `self` followed by `other` (`other` given in `self`'s frame).
    pub fn then(&self, other: &Self) -> Self {
        Self {
            position: self.position + self.rotation.apply(&other.position),
            rotation: self.rotation.then(&other.rotation),
        }
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Self {
        let rotation = self.rotation.transpose();
        Self {
            position: -rotation.apply(&self.position),
            rotation,
        }
    }

    /// The distance (m) between the origins and the angle (rad) between the frames.
    pub fn difference(&self, other: &Self) -> (f64, f64) {
        (
            (self.position - other.position).norm(),
            self.rotation.angle_to(&other.rotation),
        )
    }
}

/// The UR5e's standard DH parameter `d` of each joint (m).
pub const UR5E_D: [f64; 6] = [0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996];

/// The UR5e's standard DH parameter `a` of each joint (m).
pub const UR5E_A: [f64; 6] = [0.0, -0.425, -0.3922, 0.0, 0.0, 0.0];

/// The UR5e's standard DH parameter `alpha` of each joint (rad).
pub const UR5E_ALPHA: [f64; 6] = [FRAC_PI_2, 0.0, 0.0, FRAC_PI_2, -FRAC_PI_2, 0.0];

/// DH frame `i + 1` in frame `i` at joint angle `theta`: `Rz(θ) Tz(d) Tx(a) Rx(α)`.
fn dh(i: usize, theta: f64) -> Pose {
    Pose {
        position: Vec3::new(UR5E_A[i] * cos(theta), UR5E_A[i] * sin(theta), UR5E_D[i]),
        rotation: Rotation::about_z(theta).then(&Rotation::about_x(UR5E_ALPHA[i])),
    }
}

/// The UR5e's flange (DH frame 6) in its Base frame (DH frame 0) at joints `q`.
pub fn ur5e_flange(q: &[f64; 6]) -> Pose {
    (0..6).fold(
        Pose {
            position: Vec3::zeros(),
            rotation: Rotation::IDENTITY,
        },
        |pose, i| pose.then(&dh(i, q[i])),
    )
}

/// The signs of the closed form's three choices: `±acos` of the shoulder (joint 1), of the
/// wrist (joint 5) and of the elbow (joint 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Branch {
    /// The shoulder's sign.
    pub shoulder: i8,
    /// The elbow's sign.
    pub elbow: i8,
    /// The wrist's sign.
    pub wrist: i8,
}

/// One solution of the closed-form inverse kinematics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkSolution {
    /// The joints (rad), each in `(-π, π]`.
    pub q: [f64; 6],
    /// The branch it lies on.
    pub branch: Branch,
}

/// Every solution (up to 8) of the UR5e's closed-form inverse kinematics for its flange at
/// `flange` (in the Base frame), each joint in `(-π, π]`; at a wrist singularity (joint 5 at 0
/// or π) joint 6 is taken as 0.
pub fn ur5e_inverse(flange: &Pose) -> Vec<IkSolution> {
    let (d4, d6) = (UR5E_D[3], UR5E_D[5]);
    let (a2, a3) = (UR5E_A[1], UR5E_A[2]);
    let p06 = flange.position;
    let r06 = &flange.rotation.0;
    // The wrist centre (frame 5's origin) lies d6 back along the flange's z-axis, and d4 from
    // the base's vertical plane through joint 2's axis (frame 1's z-axis).
    let p05 = p06 - flange.rotation.column(2) * d6;
    let radius = (p05.x * p05.x + p05.y * p05.y).sqrt();
    let mut solutions = Vec::new();
    if radius < d4 * (1.0 - 1e-12) {
        return solutions;
    }
    let (psi, phi) = (atan2(p05.y, p05.x), acos(d4 / radius));
    for shoulder in [1_i8, -1] {
        let t1 = psi + f64::from(shoulder) * phi + FRAC_PI_2;
        let (s1, c1) = (sin(t1), cos(t1));
        let c5 = (p06.x * s1 - p06.y * c1 - d4) / d6;
        if c5.abs() > 1.0 + 1e-9 {
            continue;
        }
        for wrist in [1_i8, -1] {
            let t5 = f64::from(wrist) * acos(c5);
            let s5 = sin(t5);
            let t6 = if s5.abs() < 1e-12 {
                0.0
            } else {
                atan2(
                    (-r06[0][1] * s1 + r06[1][1] * c1) / s5,
                    (r06[0][0] * s1 - r06[1][0] * c1) / s5,
                )
            };
            // Frame 4 in frame 1: the planar arm of joints 2, 3 and 4.
            let t14 = dh(0, t1)
                .inverse()
                .then(flange)
                .then(&dh(5, t6).inverse())
                .then(&dh(4, t5).inverse());
            let (px, py) = (t14.position.x, t14.position.y);
            let c3 = (px * px + py * py - a2 * a2 - a3 * a3) / (2.0 * a2 * a3);
            if c3.abs() > 1.0 + 1e-9 {
                continue;
            }
            for elbow in [1_i8, -1] {
                let t3 = f64::from(elbow) * acos(c3);
                let t2 = atan2(py, px) - atan2(a3 * sin(t3), a2 + a3 * cos(t3));
                let t234 = atan2(t14.rotation.0[1][0], t14.rotation.0[0][0]);
                let t4 = t234 - t2 - t3;
                solutions.push(IkSolution {
                    q: [t1, t2, t3, t4, t5, t6].map(wrap),
                    branch: Branch {
                        shoulder,
                        elbow,
                        wrist,
                    },
                });
            }
        }
    }
    solutions
}

/// `solution` with each joint replaced by its 2π-equivalent nearest `previous`.
pub fn nearest_equivalent(solution: &[f64; 6], previous: &[f64; 6]) -> [f64; 6] {
    std::array::from_fn(|i| previous[i] + wrap(solution[i] - previous[i]))
}

/// The solution of [`ur5e_inverse`] for `flange` nearest `previous` (each joint its
/// 2π-equivalent nearest `previous`), as a controller continuing from `previous` takes it.
pub fn ur5e_follow(flange: &Pose, previous: &[f64; 6]) -> Option<IkSolution> {
    ur5e_inverse(flange)
        .into_iter()
        .map(|s| IkSolution {
            q: nearest_equivalent(&s.q, previous),
            branch: s.branch,
        })
        .min_by(|a, b| distance2(&a.q, previous).total_cmp(&distance2(&b.q, previous)))
}

/// Squared Euclidean distance between two configurations.
fn distance2(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Largest change of any joint between two configurations (rad).
fn largest_change(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The checker's joint vector of a UR5e configuration.
pub fn checker_joints(q: &[f64; 6]) -> Joints {
    let mut joints = Joints::zeros();
    for (i, value) in q.iter().enumerate() {
        joints[i] = *value;
    }
    joints
}

/// The TCP pose the checker gives configuration `q`.
pub fn checker_tcp(model: &ReferenceModel, q: &[f64; 6]) -> Pose {
    let (position, rotation) = model.tcp_frame(&checker_joints(q));
    let column = |c: usize| rotation.column(c).into_owned();
    Pose {
        position,
        rotation: Rotation::from_columns(&column(0), &column(1), &column(2)),
    }
}

/// Why the reader refuses a program: the line (1-based; 0 for the program as a whole) and
/// what failed there.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadError {
    /// The line.
    pub line: usize,
    /// What failed.
    pub problem: String,
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line == 0 {
            write!(f, "the program: {}", self.problem)
        } else {
            write!(f, "line {}: {}", self.line, self.problem)
        }
    }
}

impl std::error::Error for ReadError {}

/// A [`ReadError`] at `line`.
fn fail<T>(line: usize, problem: impl Into<String>) -> Result<T, ReadError> {
    Err(ReadError {
        line,
        problem: problem.into(),
    })
}

/// A digital output the program writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Output {
    /// The tool connector's output (`set_tool_digital_out`), else the control box's
    /// (`set_standard_digital_out`).
    pub tool: bool,
    /// Its number.
    pub pin: u32,
}

/// One statement of a program.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Statement {
    /// `set_tcp(p[...])`: the TCP in the flange frame.
    SetTcp(Pose),
    /// `set_standard_digital_out(N, B)` or `set_tool_digital_out(N, B)`.
    DigitalOut {
        /// The output.
        output: Output,
        /// The level written.
        level: bool,
    },
    /// The home check block: the program halts unless every joint is within `tolerance_rad`
    /// of `home`.
    HomeCheck {
        /// The configuration checked (rad).
        home: [f64; 6],
        /// The tolerance (rad).
        tolerance_rad: f64,
    },
    /// `movej([...], a=, v=)`.
    MoveJ {
        /// The target joints (rad).
        q: [f64; 6],
    },
    /// `movel(p[...], a=, v=)`.
    MoveL {
        /// The TCP target.
        pose: Pose,
    },
    /// `movep(p[...], a=, v=, r=)`.
    MoveP {
        /// The TCP target.
        pose: Pose,
        /// The blend radius at the target (m).
        radius_m: f64,
    },
    /// `sleep(T)`.
    Sleep,
}

/// A parsed program: its statements with their lines (1-based), and how many lines hold code.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// The statements in order, each with its line.
    pub statements: Vec<(usize, Statement)>,
    /// Lines holding code (neither blank nor only a comment).
    pub code_lines: usize,
}

/// One argument of a call.
#[derive(Clone, Debug, PartialEq)]
enum Arg {
    Number(f64),
    Bool(bool),
    List(Vec<f64>),
    Pose(Vec<f64>),
    Text,
    Named(String, Box<Arg>),
}

/// `line` without its comment (`#` outside a string to the end).
fn strip_comment(line: &str) -> &str {
    let mut in_string = false;
    for (i, c) in line.char_indices() {
        match c {
            '"' => in_string = !in_string,
            '#' if !in_string => return &line[..i],
            _ => {}
        }
    }
    line
}

/// `text` split at its commas outside brackets, parentheses and strings.
fn split_top(text: &str) -> Result<Vec<&str>, String> {
    let (mut depth, mut in_string, mut start) = (0_i32, false, 0);
    let mut parts = Vec::new();
    for (i, c) in text.char_indices() {
        match c {
            '"' => in_string = !in_string,
            '[' | '(' if !in_string => depth += 1,
            ']' | ')' if !in_string => {
                depth -= 1;
                if depth < 0 {
                    return Err(format!("unbalanced '{c}'"));
                }
            }
            ',' if !in_string && depth == 0 => {
                parts.push(text[start..i].trim());
                start = i + 1;
            }
            _ => {}
        }
    }
    if depth != 0 || in_string {
        return Err("unbalanced brackets or quotes".to_string());
    }
    let last = text[start..].trim();
    if !(parts.is_empty() && last.is_empty()) {
        parts.push(last);
    }
    Ok(parts)
}

/// A finite number.
fn number(text: &str) -> Result<f64, String> {
    let text = text.trim();
    let plain = text
        .chars()
        .all(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E'));
    match text.parse::<f64>() {
        Ok(value) if plain && value.is_finite() => Ok(value),
        _ => Err(format!("'{text}' is not a number")),
    }
}

/// The numbers of a bracketed list's inside.
fn numbers(inside: &str) -> Result<Vec<f64>, String> {
    split_top(inside)?.into_iter().map(number).collect()
}

/// One argument.
fn parse_arg(text: &str) -> Result<Arg, String> {
    let text = text.trim();
    if let Some(inside) = text.strip_prefix("p[").and_then(|t| t.strip_suffix(']')) {
        return Ok(Arg::Pose(numbers(inside)?));
    }
    if let Some(inside) = text.strip_prefix('[').and_then(|t| t.strip_suffix(']')) {
        return Ok(Arg::List(numbers(inside)?));
    }
    if text.len() >= 2 && text.starts_with('"') && text.ends_with('"') {
        return Ok(Arg::Text);
    }
    match text {
        "True" => return Ok(Arg::Bool(true)),
        "False" => return Ok(Arg::Bool(false)),
        _ => {}
    }
    if let Some((name, value)) = text.split_once('=')
        && !name.trim().is_empty()
        && name
            .trim()
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_')
    {
        return Ok(Arg::Named(
            name.trim().to_string(),
            Box::new(parse_arg(value)?),
        ));
    }
    number(text).map(Arg::Number)
}

/// A whole-line call `name(args)`: its name and arguments; `None` when the line is no call.
fn parse_call(code: &str) -> Result<Option<(&str, Vec<Arg>)>, String> {
    let Some(open) = code.find('(') else {
        return Ok(None);
    };
    let name = code[..open].trim();
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Ok(None);
    }
    let Some(inside) = code[open + 1..].strip_suffix(')') else {
        return Err(format!("'{code}' does not end its call with ')'"));
    };
    let args = split_top(inside)?
        .into_iter()
        .map(parse_arg)
        .collect::<Result<_, _>>()?;
    Ok(Some((name, args)))
}

/// Six numbers of a list or pose.
fn six(values: &[f64], what: &str) -> Result<[f64; 6], String> {
    values
        .try_into()
        .map_err(|_| format!("{what} holds {} numbers, not 6", values.len()))
}

/// The named positive numbers `names` (in this order) that follow a move's target.
fn move_parameters(args: &[Arg], names: &[&str]) -> Result<Vec<f64>, String> {
    if args.len() != names.len() {
        return Err(format!(
            "expected the target and {} named parameters ({}), found {} arguments",
            names.len(),
            names.join(", "),
            args.len() + 1
        ));
    }
    args.iter()
        .zip(names)
        .map(|(arg, name)| match arg {
            Arg::Named(given, value) if given == name => match **value {
                Arg::Number(v) if v >= 0.0 && (v > 0.0 || *name == "r") => Ok(v),
                _ => Err(format!("{name} must be a positive number")),
            },
            _ => Err(format!("expected {name}=..., found {arg:?}")),
        })
        .collect()
}

/// One statement's code (a line without its comment, trimmed).
fn parse_statement(code: &str) -> Result<Statement, String> {
    let Some((name, args)) = parse_call(code)? else {
        return Err(format!(
            "'{code}' is not a statement of the program's grammar"
        ));
    };
    let target = |what: &str| -> Result<[f64; 6], String> {
        match args.first() {
            Some(Arg::Pose(values)) if what == "pose" => six(values, "the pose"),
            Some(Arg::List(values)) if what == "joints" => six(values, "the joint list"),
            _ => Err(format!("{name} needs a {what} first")),
        }
    };
    match name {
        "set_tcp" => {
            if args.len() != 1 {
                return Err("set_tcp takes one pose".to_string());
            }
            Ok(Statement::SetTcp(Pose::from_ur(&target("pose")?)))
        }
        "set_standard_digital_out" | "set_tool_digital_out" => match args.as_slice() {
            [Arg::Number(pin), Arg::Bool(level)]
                if *pin >= 0.0 && pin.fract() == 0.0 && *pin < 64.0 =>
            {
                Ok(Statement::DigitalOut {
                    output: Output {
                        tool: name == "set_tool_digital_out",
                        pin: *pin as u32,
                    },
                    level: *level,
                })
            }
            _ => Err(format!("{name} takes an output number and True or False")),
        },
        "movej" => {
            let q = target("joints")?;
            move_parameters(&args[1..], &["a", "v"])?;
            Ok(Statement::MoveJ { q })
        }
        "movel" => {
            let pose = Pose::from_ur(&target("pose")?);
            move_parameters(&args[1..], &["a", "v"])?;
            Ok(Statement::MoveL { pose })
        }
        "movep" => {
            let pose = Pose::from_ur(&target("pose")?);
            let parameters = move_parameters(&args[1..], &["a", "v", "r"])?;
            Ok(Statement::MoveP {
                pose,
                radius_m: parameters[2],
            })
        }
        "sleep" => match args.as_slice() {
            [Arg::Number(t)] if *t >= 0.0 => Ok(Statement::Sleep),
            _ => Err("sleep takes a time of at least 0 s".to_string()),
        },
        _ => Err(format!("'{name}' is not a call of the program's grammar")),
    }
}

/// The code of the home check's lines after `home = [...]`, whitespace removed; the fourth
/// line's tolerance and the fifth line's popup are matched apart.
const HOME_CHECK: [&str; 9] = [
    "actual=get_actual_joint_positions()",
    "joint=0",
    "whilejoint<6:",
    "ifnorm(actual[joint]-home[joint])>",
    "popup(",
    "halt",
    "end",
    "joint=joint+1",
    "end",
];

/// Parses a program: comments, then `def emg_job():`, its statements and `end`, then only
/// comments.
pub fn parse_program(text: &str) -> Result<Program, ReadError> {
    // Code lines: (line number, code without comment, trimmed).
    let code: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, line)| (i + 1, strip_comment(line).trim()))
        .filter(|(_, code)| !code.is_empty())
        .collect();
    let mut lines = code.iter().copied();
    match lines.next() {
        Some((_, "def emg_job():")) => {}
        Some((line, other)) => {
            return fail(line, format!("expected 'def emg_job():', found '{other}'"));
        }
        None => return fail(0, "holds no code"),
    }
    let mut statements = Vec::new();
    let mut closed = false;
    while let Some((line, code)) = lines.next() {
        if code == "end" {
            closed = true;
            break;
        }
        let squeezed: String = code.split_whitespace().collect();
        if let Some(list) = squeezed.strip_prefix("home=") {
            let home = list
                .strip_prefix('[')
                .and_then(|l| l.strip_suffix(']'))
                .ok_or_else(|| "the home is not a list".to_string())
                .and_then(numbers)
                .and_then(|values| six(&values, "the home"))
                .or_else(|problem| fail(line, problem))?;
            let mut tolerance_rad = f64::NAN;
            for (k, expected) in HOME_CHECK.iter().enumerate() {
                let Some((check_line, check_code)) = lines.next() else {
                    return fail(line, "the home check block ends early");
                };
                let squeezed: String = check_code.split_whitespace().collect();
                let matches = match k {
                    3 => squeezed
                        .strip_prefix(expected)
                        .and_then(|rest| rest.strip_suffix(':'))
                        .and_then(|value| number(value).ok())
                        .map(|value| tolerance_rad = value)
                        .is_some(),
                    4 => matches!(parse_call(check_code), Ok(Some(("popup", _)))),
                    _ => squeezed == *expected,
                };
                if !matches || (k == 3 && tolerance_rad <= 0.0) {
                    return fail(
                        check_line,
                        format!("'{check_code}' is not the home check's line '{expected}...'"),
                    );
                }
            }
            statements.push((
                line,
                Statement::HomeCheck {
                    home,
                    tolerance_rad,
                },
            ));
            continue;
        }
        let statement = parse_statement(code).or_else(|problem| fail(line, problem))?;
        statements.push((line, statement));
    }
    if !closed {
        return fail(0, "'def emg_job():' is never closed by 'end'");
    }
    if let Some((line, code)) = lines.next() {
        return fail(line, format!("'{code}' follows the program's 'end'"));
    }
    Ok(Program {
        statements,
        code_lines: code.len(),
    })
}

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
    if last_radius > 0.0 {
        return fail(
            last_line,
            format!("a blend radius of {last_radius} m at a run's last target"),
        );
    }
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
            let turn = atan2(cross.norm(), u1.dot(&u2));
            let blend = if !(1e-9..=PI - 1e-9).contains(&turn) {
                Piece::Line {
                    a: entry,
                    b: exit,
                    from: 0.0,
                    to: 1.0,
                }
            } else {
                let axis = cross / cross.norm();
                let bend = radius * (1.0 + cos(turn)) / sin(turn);
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

/// A stroke part of the plan as the reader checks it.
struct StrokePart {
    /// Its segment's index.
    segment: usize,
    /// Its stroke's place in the file's `strokes`.
    place: usize,
    /// Arc length along the stroke where its task starts (m).
    from_s: f64,
    /// Its task as the checker reads it.
    line: Line,
    /// The bounds its samples keep (the part in the scene).
    bounds: Bounds,
    /// The TCP at its first and last sample.
    start: Vec3,
    /// See `start`.
    end: Vec3,
}

/// What the reader found.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadReport {
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
    limits: Vec<(f64, f64)>,
    collision_margin_m: f64,
    /// The line and bounds of the moves between strokes (the part in the scene), if the plan
    /// has a part.
    free: Option<(Line, Bounds)>,
    parts: Vec<StrokePart>,
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
    /// The tool output and whether the tool is on.
    output: Option<Output>,
    tool_on: bool,
    /// Stroke parts switched on so far.
    parts_on: usize,
    /// The TCP samples of the stroke part being drawn.
    drawn: Vec<Vec3>,
    /// Per stroke (its place), the stretches covered.
    covered: Vec<Vec<Stretch>>,
    /// The pending `movep` run: each target, its radius and its line.
    run: Vec<(Pose, f64, usize)>,
    report: ReadReport,
}

/// Reads the program `text` against the job's plan `file` with the checker `model` of the
/// UR5e (base `base_link`, tip `pen_tip`); `on_level` is the tool output's level that switches
/// the tool on.
pub fn read_program(
    text: &str,
    file: &JobFile,
    model: &ReferenceModel,
    on_level: bool,
) -> Result<ReadReport, ReadError> {
    let program = parse_program(text)?;
    let reading = Reading::new(file, model, on_level)?;
    let mut state = State {
        tcp: None,
        joints: None,
        pose: None,
        output: None,
        tool_on: false,
        parts_on: 0,
        drawn: Vec::new(),
        covered: vec![Vec::new(); file.strokes.len()],
        run: Vec::new(),
        report: ReadReport {
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
    let last_line = text.lines().count();
    if state.tool_on {
        return fail(last_line, "the program ends with the tool on");
    }
    if state.parts_on != reading.parts.len() {
        return fail(
            last_line,
            format!(
                "the tool switches on {} times; the plan draws {} stroke parts",
                state.parts_on,
                reading.parts.len()
            ),
        );
    }
    let mut report = state.report;
    for (report_of_stroke, covered) in file.strokes.iter().zip(&state.covered) {
        let coverage = Coverage::of(report_of_stroke.length_m, covered);
        report
            .per_stroke
            .push((coverage.drawn_m, report_of_stroke.drawn_m));
        report.covered_m += coverage.drawn_m;
        report.drawn_m += report_of_stroke.drawn_m;
    }
    let allowance = COVERAGE_ALLOWANCE_M * reading.parts.len() as f64;
    if report.covered_m < report.drawn_m - allowance {
        return fail(
            0,
            format!(
                "the tool covers {:.6} m of the strokes; the plan draws {:.6} m",
                report.covered_m, report.drawn_m
            ),
        );
    }
    Ok(report)
}

impl<'a> Reading<'a> {
    /// What the reading needs of `file` and `model`.
    fn new(file: &JobFile, model: &'a ReferenceModel, on_level: bool) -> Result<Self, ReadError> {
        if file.joint_names.len() != 6 || model.limits().len() != 6 {
            return fail(0, "the plan is not a six-joint arm's");
        }
        let points = file.points();
        let configurations: Vec<[f64; 6]> = points
            .iter()
            .map(|p| std::array::from_fn(|i| p.positions[i]))
            .collect();
        let times: Vec<f64> = points.iter().map(|p| p.time_from_start.seconds()).collect();
        let on_part = with_part(&file.constraints, &file.surfaces);
        let free_config = ConstraintConfig {
            line_tolerance_m: f64::INFINITY,
            theta_max_deg: 180.0,
            ..on_part.clone()
        };
        let free = file
            .surfaces
            .first()
            .map(|task| (task.into(), task_bounds(task, &free_config)));
        let mut parts = Vec::new();
        for (segment, s) in file.segments.iter().enumerate() {
            let SegmentKind::Stroke { stroke, from_s, .. } = s.kind else {
                continue;
            };
            let Some(task) = &s.task else {
                return fail(
                    0,
                    format!("the plan's segment {segment} is a stroke without its task"),
                );
            };
            let place = file
                .strokes
                .iter()
                .position(|r| r.stroke == stroke)
                .ok_or_else(|| ReadError {
                    line: 0,
                    problem: format!("the plan's stroke {stroke} has no report"),
                })?;
            let first = times.partition_point(|t| *t < s.start_s - 1e-9);
            let last = times.partition_point(|t| *t <= s.end_s + 1e-9);
            if first >= last {
                return fail(0, format!("the plan's segment {segment} holds no sample"));
            }
            let tcp = |k: usize| checker_tcp(model, &configurations[k]).position;
            parts.push(StrokePart {
                segment,
                place,
                from_s,
                line: task.into(),
                bounds: task_bounds(task, &on_part),
                start: tcp(first),
                end: tcp(last - 1),
            });
        }
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
            limits: model.limits(),
            collision_margin_m: file.constraints.collision_margin_m,
            free,
            parts,
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
                if on && !state.tool_on {
                    self.switch_on(state, line)?;
                } else if !on && state.tool_on {
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
            Statement::MoveJ { q } => {
                state.report.movej += 1;
                self.move_joints(state, line, q)?;
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
        }
        Ok(())
    }

    /// The commanded TCP pose, which a Cartesian move starts from.
    fn current_pose(&self, state: &State, line: usize) -> Result<Pose, ReadError> {
        if state.tcp.is_none() {
            return fail(line, "a Cartesian move before set_tcp");
        }
        state.pose.ok_or_else(|| ReadError {
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

    /// A `movej` of line `line` to `q`.
    fn move_joints(&self, state: &mut State, line: usize, q: [f64; 6]) -> Result<(), ReadError> {
        if state.tool_on {
            return fail(line, "movej with the tool on");
        }
        if !self.joints_index.holds(&q) {
            return fail(
                line,
                format!("movej target {q:?} is no configuration of the plan"),
            );
        }
        if let Some(from) = state.joints {
            let steps = (largest_change(&from, &q) / JOINT_STEP_RAD).ceil().max(1.0) as usize;
            for k in 1..steps {
                let f = k as f64 / steps as f64;
                let between: [f64; 6] = std::array::from_fn(|i| from[i] + (q[i] - from[i]) * f);
                self.check_configuration(state, &between, line)?;
            }
        }
        self.arrive(state, q, line)
    }

    /// Checks a configuration the arm passes: the joint limits and the checker's clearances
    /// (its own links; the part and the scene by the bounds of the stroke part being drawn, or
    /// of the moves between strokes).
    fn check_configuration(
        &self,
        state: &mut State,
        q: &[f64; 6],
        line: usize,
    ) -> Result<(), ReadError> {
        state.report.samples += 1;
        for (i, (value, (low, high))) in q.iter().zip(&self.limits).enumerate() {
            if !(value >= low && value <= high) {
                return fail(
                    line,
                    format!(
                        "joint {} = {value} leaves its limits [{low}, {high}]",
                        i + 1
                    ),
                );
            }
        }
        let joints = checker_joints(q);
        let (clearance, a, b) = self.model.min_clearance(&joints);
        state.report.least_clearance_m = state.report.least_clearance_m.min(clearance);
        if clearance < self.collision_margin_m - SLACK_M {
            return fail(
                line,
                format!("{a} and {b} come within {:.2} mm at {q:?}", clearance * 1e3),
            );
        }
        let scene = if state.tool_on {
            let part = &self.parts[state.parts_on - 1];
            Some((&part.line, &part.bounds))
        } else {
            self.free.as_ref().map(|(line, bounds)| (line, bounds))
        };
        if let Some((task, bounds)) = scene
            && let Some((margin, link, obstacle)) = self.model.scene_margin(&joints, task, bounds)
            && margin < -SLACK_M
        {
            return fail(
                line,
                format!(
                    "{link} comes {:.2} mm into {obstacle} at {q:?}",
                    -margin * 1e3
                ),
            );
        }
        Ok(())
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
                if state.tool_on {
                    self.check_on_task(state, &pose, *piece_line)?;
                }
            }
        }
        state.joints = Some(joints);
        state.pose = Some(end);
        Ok(())
    }

    /// Checks a TCP pose while the tool is on: within the tolerance of the stroke part's task
    /// and the tool axis within the cone round its normal, as the checker measures them.
    fn check_on_task(&self, state: &mut State, pose: &Pose, line: usize) -> Result<(), ReadError> {
        let part = &self.parts[state.parts_on - 1];
        let deviation = part.line.distance(&pose.position);
        let angle = angle_deg(&pose.rotation.column(2), &part.line.n);
        let report = &mut state.report;
        report.worst_deviation_m = report.worst_deviation_m.max(deviation);
        report.worst_tool_angle_deg = report.worst_tool_angle_deg.max(angle);
        if deviation > part.bounds.line_tolerance_m + SLACK_M {
            return fail(
                line,
                format!(
                    "the TCP {:?} lies {:.4} mm from stroke part {} (segment {}); the tolerance \
                     is {:.4} mm",
                    pose.position.as_slice(),
                    deviation * 1e3,
                    state.parts_on - 1,
                    part.segment,
                    part.bounds.line_tolerance_m * 1e3
                ),
            );
        }
        if angle > part.bounds.theta_max_deg + SLACK_DEG {
            return fail(
                line,
                format!(
                    "the tool axis leans {angle:.3}° from the normal of stroke part {}; the cone \
                     is {}°",
                    state.parts_on - 1,
                    part.bounds.theta_max_deg
                ),
            );
        }
        state.drawn.push(pose.position);
        Ok(())
    }

    /// The tool switched on at line `line`: the next stroke part of the plan starts, the TCP
    /// at its start.
    fn switch_on(&self, state: &mut State, line: usize) -> Result<(), ReadError> {
        let Some(part) = self.parts.get(state.parts_on) else {
            return fail(
                line,
                format!(
                    "the tool switches on a {}th time; the plan draws {} stroke parts",
                    state.parts_on + 1,
                    self.parts.len()
                ),
            );
        };
        let Some(pose) = state.pose else {
            return fail(line, "the tool switches on before the first move");
        };
        let off = (pose.position - part.start).norm();
        if off > part.bounds.line_tolerance_m + SLACK_M {
            return fail(
                line,
                format!(
                    "the tool switches on {:.4} mm from the start of stroke part {} (segment {})",
                    off * 1e3,
                    state.parts_on,
                    part.segment
                ),
            );
        }
        state.tool_on = true;
        state.parts_on += 1;
        state.report.stroke_parts += 1;
        state.drawn.clear();
        self.check_on_task(state, &pose, line)
    }

    /// The tool switched off at line `line`: the stroke part ends, the TCP at its end; what it
    /// covered is measured.
    fn switch_off(&self, state: &mut State, line: usize) -> Result<(), ReadError> {
        let part = &self.parts[state.parts_on - 1];
        let pose = self.current_pose(state, line)?;
        let off = (pose.position - part.end).norm();
        if off > part.bounds.line_tolerance_m + SLACK_M {
            return fail(
                line,
                format!(
                    "the tool switches off {:.4} mm from the end of stroke part {} (segment {})",
                    off * 1e3,
                    state.parts_on - 1,
                    part.segment
                ),
            );
        }
        state.tool_on = false;
        if let Some((least, greatest)) = part.line.covered(state.drawn.drain(..)) {
            state.covered[part.place].push(Stretch {
                from_s: part.from_s + least,
                to_s: part.from_s + greatest,
            });
        }
        Ok(())
    }
}
