//! A parser of the subset of URScript the programs written for the UR5e hold: one `def`, its
//! statements (tool outputs, the TCP, the home check block, `movej`, `movel`, `movep`, `sleep`
//! in a native program; the home check or `movej`, `servoj` and `stopj` in a joint stream), its
//! `end`, and comments. Anything else is refused at its line.

use crate::error::{ReadError, fail};
use crate::geometry::Pose;

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
    /// `movej([...], a=, v=)` or `movej([...], a=, v=, r=)`.
    MoveJ {
        /// The target joints (rad).
        q: [f64; 6],
        /// The blend radius at the target (m, at the TCP; 0 without `r=`).
        radius_m: f64,
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
    /// `servoj(q, a, v, t, lookahead_time, gain)`: `q` tracked for `time_s`.
    ServoJ {
        /// The target joints (rad).
        q: [f64; 6],
        /// How long the target is tracked (s).
        time_s: f64,
    },
    /// `stopj(a)`: the joints decelerate to rest.
    StopJ,
}

/// The two forms of program written for the UR5e.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Form {
    /// `def emg_job():`, a job's native program: the TCP, the tool output, the home check,
    /// `movej`, `movel`, blended `movep` and `sleep`.
    Native,
    /// `def emg_motion():`, a joint stream: the home check or a `movej` to its start, then a
    /// `servoj` target per controller cycle, and `stopj`.
    Servoj,
}

impl Form {
    /// The name of the program's `def`.
    pub fn def_name(self) -> &'static str {
        match self {
            Self::Native => "emg_job",
            Self::Servoj => "emg_motion",
        }
    }

    /// The calls a program of this form may hold.
    fn calls(self) -> &'static [&'static str] {
        match self {
            Self::Native => &[
                "set_tcp",
                "set_standard_digital_out",
                "set_tool_digital_out",
                "movej",
                "movel",
                "movep",
                "sleep",
            ],
            Self::Servoj => &["movej", "servoj", "stopj"],
        }
    }
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
fn parse_statement(code: &str, form: Form) -> Result<Statement, String> {
    let Some((name, args)) = parse_call(code)? else {
        return Err(format!(
            "'{code}' is not a statement of the program's grammar"
        ));
    };
    if !form.calls().contains(&name) {
        return Err(format!("'{name}' is not a call of the program's grammar"));
    }
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
            let names: &[&str] = if args.len() == 4 {
                &["a", "v", "r"]
            } else {
                &["a", "v"]
            };
            let parameters = move_parameters(&args[1..], names)?;
            Ok(Statement::MoveJ {
                q,
                radius_m: parameters.get(2).copied().unwrap_or(0.0),
            })
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
        "servoj" => match args.as_slice() {
            [
                Arg::List(q),
                Arg::Number(a),
                Arg::Number(v),
                Arg::Number(t),
                Arg::Number(lookahead),
                Arg::Number(gain),
            ] if *a >= 0.0
                && *v >= 0.0
                && *t > 0.0
                && (0.03..=0.2).contains(lookahead)
                && (100.0..=2000.0).contains(gain) =>
            {
                Ok(Statement::ServoJ {
                    q: six(q, "the joint list")?,
                    time_s: *t,
                })
            }
            _ => Err(
                "servoj takes joints, a, v, t > 0, a lookahead_time in [0.03, 0.2] s and a gain \
                 in [100, 2000]"
                    .to_string(),
            ),
        },
        "stopj" => match args.as_slice() {
            [Arg::Number(a)] if *a > 0.0 => Ok(Statement::StopJ),
            _ => Err("stopj takes a positive deceleration".to_string()),
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

/// Parses a program of `form`: comments, then `def emg_job():` (or `def emg_motion():`), its
/// statements and `end`, then only comments.
pub fn parse_program(text: &str, form: Form) -> Result<Program, ReadError> {
    let def = format!("def {}():", form.def_name());
    // Code lines: (line number, code without comment, trimmed).
    let code: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, line)| (i + 1, strip_comment(line).trim()))
        .filter(|(_, code)| !code.is_empty())
        .collect();
    let mut lines = code.iter().copied();
    match lines.next() {
        Some((_, first)) if first == def => {}
        Some((line, other)) => {
            return fail(line, format!("expected '{def}', found '{other}'"));
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
        let statement = parse_statement(code, form).or_else(|problem| fail(line, problem))?;
        statements.push((line, statement));
    }
    if !closed {
        return fail(0, format!("'{def}' is never closed by 'end'"));
    }
    if let Some((line, code)) = lines.next() {
        return fail(line, format!("'{code}' follows the program's 'end'"));
    }
    Ok(Program {
        statements,
        code_lines: code.len(),
    })
}
