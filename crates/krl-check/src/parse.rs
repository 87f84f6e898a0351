//! A parser of the subset of KRL a job's program holds, line by line as KRL is written: the
//! `.src` file's `DEF name( )` ... `END` with its statements (assignments `target=value`,
//! `PTP point`, `LIN point` with an optional `C_DIS`, `WAIT SEC time`), and the `.dat` file's
//! `DEFDAT name` ... `ENDDAT` with its declarations `DECL TYPE NAME={KEY value,...}`. Comments
//! run from `;` to the end of the line, `&` lines (the editor's attributes) come first; keywords
//! and names are read without regard to case, as KRL reads them. Anything else is refused
//! naming its line.

use std::collections::BTreeMap;

use emg_program_check::{ReadError, fail};

/// A motion instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// `PTP`: every axis linear in time, together.
    Ptp,
    /// `LIN`: the TCP on a straight line.
    Lin,
}

/// What a statement of the `.src` file does.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// `target=value`: the target in capitals, the value as written.
    Assign {
        /// The variable assigned (`$VEL.CP`, `TOOL_DATA[1]`, ...).
        target: String,
        /// Its new value, as written.
        value: String,
    },
    /// A motion to a point of the `.dat` file.
    Move {
        /// `PTP` or `LIN`.
        motion: Motion,
        /// The point's name, in capitals.
        point: String,
        /// The approximation named after it (`C_DIS`), in capitals.
        approximation: Option<String>,
    },
    /// `WAIT SEC time`.
    WaitSec(f64),
}

/// A statement and its line (1-based).
#[derive(Clone, Debug, PartialEq)]
pub struct Statement {
    /// Its line.
    pub line: usize,
    /// What it does.
    pub action: Action,
}

/// A `.src` file: its program's name and statements.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// The name after `DEF`, in capitals.
    pub name: String,
    /// The statements between `DEF` and `END`.
    pub statements: Vec<Statement>,
}

/// A declaration of the `.dat` file: `DECL TYPE NAME={KEY value,...}`.
#[derive(Clone, Debug, PartialEq)]
pub struct Declaration {
    /// Its line in the `.dat` file.
    pub line: usize,
    /// Its type (`E6POS`, `E6AXIS`, `FRAME`), in capitals.
    pub data_type: String,
    /// Its fields, keys in capitals, in the order written.
    pub fields: Vec<(String, f64)>,
}

impl Declaration {
    /// The values of exactly the fields `keys` (in that order, each once, no others), else why
    /// not (naming `name`).
    pub fn values(&self, name: &str, keys: &[&str]) -> Result<Vec<f64>, String> {
        if let Some((key, _)) = self
            .fields
            .iter()
            .find(|(key, _)| !keys.contains(&key.as_str()))
        {
            return Err(format!(
                "{name} (.dat line {}) has a field {key}",
                self.line
            ));
        }
        keys.iter()
            .map(|key| {
                let found: Vec<f64> = self
                    .fields
                    .iter()
                    .filter(|(k, _)| k == key)
                    .map(|(_, v)| *v)
                    .collect();
                match found.as_slice() {
                    [value] => Ok(*value),
                    _ => Err(format!(
                        "{name} (.dat line {}) has {} fields {key}, not one",
                        self.line,
                        found.len()
                    )),
                }
            })
            .collect()
    }
}

/// A `.dat` file: its name and declarations by name (in capitals).
#[derive(Clone, Debug, PartialEq)]
pub struct DataList {
    /// The name after `DEFDAT`, in capitals.
    pub name: String,
    /// The declarations.
    pub declarations: BTreeMap<String, Declaration>,
}

/// The lines of `text` that hold code: each line's number and its code, the comment cut off
/// and the ends trimmed; the leading `&` lines left out.
fn code_lines(text: &str) -> Vec<(usize, &str)> {
    let mut lines = Vec::new();
    let mut header = true;
    for (index, raw) in text.lines().enumerate() {
        let code = raw.split(';').next().unwrap_or_default().trim();
        if code.is_empty() {
            continue;
        }
        if header && code.starts_with('&') {
            continue;
        }
        header = false;
        lines.push((index + 1, code));
    }
    lines
}

/// `code`'s first word in capitals and the rest, trimmed.
fn first_word(code: &str) -> (String, &str) {
    let mut parts = code.splitn(2, char::is_whitespace);
    let word = parts.next().unwrap_or_default().to_ascii_uppercase();
    (word, parts.next().unwrap_or_default().trim())
}

/// Whether `name` is a KRL name (a letter, `_` or `$` first, then letters, digits, `_` or `$`,
/// at most 24).
fn is_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_' || c == '$')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$')
        && name.len() <= 24
}

/// A number as KRL writes it.
fn number(text: &str, what: &str, line: usize) -> Result<f64, ReadError> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| ReadError::at(line, format!("{what} is `{text}`, not a number")))
}

/// Parses a `.src` file.
pub fn parse_src(text: &str) -> Result<Program, ReadError> {
    let lines = code_lines(text);
    let Some(&(first, def)) = lines.first() else {
        return fail(0, "the .src file holds no program");
    };
    let (keyword, rest) = first_word(def);
    let name = rest
        .strip_suffix(')')
        .and_then(|r| r.split_once('('))
        .filter(|(name, arguments)| is_name(name.trim()) && arguments.trim().is_empty())
        .map(|(name, _)| name.trim().to_ascii_uppercase());
    let (true, Some(name)) = (keyword == "DEF", name) else {
        return fail(first, "the .src file does not start with DEF name( )");
    };
    let Some(&(last, end)) = lines.last() else {
        return fail(first, "the .src file ends early");
    };
    if lines.len() < 2 || !end.eq_ignore_ascii_case("END") {
        return fail(last, "the .src file does not end with END");
    }
    let statements = lines[1..lines.len() - 1]
        .iter()
        .map(|&(line, code)| statement(line, code))
        .collect::<Result<_, _>>()?;
    Ok(Program { name, statements })
}

/// One statement of a `.src` file.
fn statement(line: usize, code: &str) -> Result<Statement, ReadError> {
    let (word, rest) = first_word(code);
    let action = match word.as_str() {
        "PTP" | "LIN" => {
            let words: Vec<&str> = rest.split_whitespace().collect();
            let (point, approximation) = match words.as_slice() {
                [point] => (point, None),
                [point, approximation] => (point, Some(approximation.to_ascii_uppercase())),
                _ => return fail(line, format!("{word} takes a point and an approximation")),
            };
            if !is_name(point) {
                return fail(line, format!("{word} to `{point}`: not a point's name"));
            }
            Action::Move {
                motion: if word == "PTP" {
                    Motion::Ptp
                } else {
                    Motion::Lin
                },
                point: point.to_ascii_uppercase(),
                approximation,
            }
        }
        "WAIT" => {
            let (unit, time) = first_word(rest);
            if unit != "SEC" {
                return fail(
                    line,
                    "WAIT without SEC: a job's program waits only for time",
                );
            }
            Action::WaitSec(number(time, "WAIT SEC's time", line)?)
        }
        _ => {
            let Some((target, value)) = code.split_once('=') else {
                return fail(
                    line,
                    format!("`{code}` is not a statement a job's program holds"),
                );
            };
            Action::Assign {
                target: target.trim().to_ascii_uppercase(),
                value: value.trim().to_string(),
            }
        }
    };
    Ok(Statement { line, action })
}

/// Parses a `.dat` file.
pub fn parse_dat(text: &str) -> Result<DataList, ReadError> {
    let lines = code_lines(text);
    let Some(&(first, defdat)) = lines.first() else {
        return fail(0, "the .dat file holds no data list");
    };
    let (keyword, name) = first_word(defdat);
    if keyword != "DEFDAT" || !is_name(name) {
        return fail(first, "the .dat file does not start with DEFDAT name");
    }
    let Some(&(last, end)) = lines.last() else {
        return fail(first, "the .dat file ends early");
    };
    if lines.len() < 2 || !end.eq_ignore_ascii_case("ENDDAT") {
        return fail(last, "the .dat file does not end with ENDDAT");
    }
    let mut declarations = BTreeMap::new();
    for &(line, code) in &lines[1..lines.len() - 1] {
        let at = |problem: String| ReadError::at(0, format!(".dat line {line}: {problem}"));
        let (decl, rest) = first_word(code);
        let (data_type, rest) = first_word(rest);
        let Some((name, value)) = rest.split_once('=') else {
            return Err(at(format!(
                "`{code}` is not a declaration DECL TYPE NAME=value"
            )));
        };
        let name = name.trim();
        if decl != "DECL" || !is_name(name) {
            return Err(at(format!(
                "`{code}` is not a declaration DECL TYPE NAME=value"
            )));
        }
        let Some(inner) = value
            .trim()
            .strip_prefix('{')
            .and_then(|v| v.strip_suffix('}'))
        else {
            return Err(at(format!("{name}'s value is not an aggregate {{...}}")));
        };
        let fields = inner
            .split(',')
            .map(|field| {
                let (key, value) = first_word(field.trim());
                number(value, &format!("{name}'s {key}"), 0)
                    .map(|v| (key, v))
                    .map_err(|e| at(e.problem))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let name = name.to_ascii_uppercase();
        if declarations.contains_key(&name) {
            return Err(at(format!("{name} is declared twice")));
        }
        declarations.insert(
            name,
            Declaration {
                line,
                data_type,
                fields,
            },
        );
    }
    Ok(DataList {
        name: name.to_ascii_uppercase(),
        declarations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_program_and_its_data_list_parse() {
        let src = "&ACCESS RVP\n&REL 1\nDEF job( )\n; a comment\n  $VEL.CP=0.2 ; speed\n  \
                   PTP home\n  lin P1 c_dis\n  WAIT SEC 0.5\nEND\n";
        let program = parse_src(src).unwrap();
        assert_eq!(program.name, "JOB");
        assert_eq!(
            program.statements,
            vec![
                Statement {
                    line: 5,
                    action: Action::Assign {
                        target: "$VEL.CP".to_string(),
                        value: "0.2".to_string()
                    }
                },
                Statement {
                    line: 6,
                    action: Action::Move {
                        motion: Motion::Ptp,
                        point: "HOME".to_string(),
                        approximation: None
                    }
                },
                Statement {
                    line: 7,
                    action: Action::Move {
                        motion: Motion::Lin,
                        point: "P1".to_string(),
                        approximation: Some("C_DIS".to_string())
                    }
                },
                Statement {
                    line: 8,
                    action: Action::WaitSec(0.5)
                },
            ]
        );
        let dat = "&ACCESS RVP\nDEFDAT job\nDECL FRAME T={X 1.5,Y 0.0,Z -2,A 0,B 0,C 0}\nENDDAT\n";
        let list = parse_dat(dat).unwrap();
        let tool = &list.declarations["T"];
        assert_eq!((tool.line, tool.data_type.as_str()), (3, "FRAME"));
        assert_eq!(
            tool.values("T", &["X", "Y", "Z", "A", "B", "C"]).unwrap(),
            vec![1.5, 0.0, -2.0, 0.0, 0.0, 0.0]
        );
        assert!(tool.values("T", &["X", "Y", "Z"]).is_err());
    }

    #[test]
    fn what_is_not_krl_a_job_holds_is_refused_at_its_line() {
        let error = parse_src("DEF job( )\n  LIN P1 C_DIS extra\nEND\n").unwrap_err();
        assert_eq!(error.line, 2);
        let error = parse_src("DEF job( )\n  IF X THEN\nEND\n").unwrap_err();
        assert_eq!(error.line, 2);
        let error = parse_src("DEF job( )\n  WAIT FOR $IN[1]\nEND\n").unwrap_err();
        assert_eq!(error.line, 2);
        assert_eq!(parse_src("DEF job( )\n  PTP P1\n").unwrap_err().line, 2);
        let error = parse_dat("DEFDAT job\nDECL E6POS P1={X one}\nENDDAT\n").unwrap_err();
        assert!(error.problem.contains(".dat line 2"), "{error}");
    }
}
