//! The CSV table of a rollout: `time_s`, `q1..qn`, `qd1..qdn` (`n` = 6 or 7 joints), TCP, tool
//! angle, `ρ`, controller.
//! The layout is documented in `docs/trajectory-format.md`.

use emg_control::StepRecord;
use emg_kinematics::{MAX_DOF, MIN_DOF};
use emg_verify::{JointSamples, point_velocities};

use crate::error::FormatError;
use crate::joint_trajectory::padded;

/// The CSV header [`trajectory_csv`] writes for an arm of `joints` joints; [`read_csv`] needs its
/// first `1 + 2·joints` columns.
pub fn csv_header(joints: usize) -> String {
    let names = |prefix: &'static str| (1..=joints).map(move |i| format!("{prefix}{i}"));
    std::iter::once("time_s".to_string())
        .chain(names("q"))
        .chain(names("qd"))
        .chain(
            [
                "tcp_x",
                "tcp_y",
                "tcp_z",
                "tool_angle_deg",
                "rho",
                "controller",
            ]
            .map(String::from),
        )
        .collect::<Vec<_>>()
        .join(",")
}

/// Times and positions of recorded steps (exact times, no declared velocities).
pub fn samples_from_steps(steps: &[StepRecord]) -> JointSamples {
    JointSamples {
        time_s: steps.iter().map(|s| s.time_s).collect(),
        q: steps.iter().map(|s| s.q).collect(),
        qd: None,
        qdd: None,
    }
}

/// The CSV table of a rollout's steps on an arm of `joints` joints: [`csv_header`], then one row
/// per step: time (s),
/// positions (rad), velocities by [`point_velocities`] (rad/s), TCP (m), tool angle (degrees),
/// `ρ`, and the acting controller (`classical`, `learned` or empty). Numbers are Rust's
/// shortest round-trip form, so [`read_csv`] gives back the very same values.
pub fn trajectory_csv(steps: &[StepRecord], joints: usize) -> String {
    let samples = samples_from_steps(steps);
    let velocities = point_velocities(&samples.time_s, &samples.q);
    let mut out = csv_header(joints);
    out.push('\n');
    for (step, qd) in steps.iter().zip(&velocities) {
        let mut row = vec![step.time_s];
        row.extend(&step.q.as_slice()[..joints]);
        row.extend(&qd.as_slice()[..joints]);
        row.extend(step.tcp.iter());
        row.extend([step.tool_angle_deg, step.rho]);
        for value in row {
            out.push_str(&format!("{value:?},"));
        }
        out.push_str(step.controller.map_or("", |c| c.name()));
        out.push('\n');
    }
    out
}

/// Reads a CSV table: the header must start with `time_s,q1..qn,qd1..qdn` for `n` = 6 or 7 (the
/// columns after those are not read); every row must have as many cells as the header, and the
/// cells read must be finite numbers. The error names the line, the column and what is wrong.
pub fn read_csv(text: &str) -> Result<JointSamples, FormatError> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or_else(|| FormatError::CsvHeader("the file is empty".into()))?
        .split(',')
        .map(str::trim)
        .collect();
    // The arm's joints: the q columns after the time, at least MIN_DOF of them (a shorter run
    // is reported at its first missing column below).
    let joints = (1..=MAX_DOF)
        .take_while(|&i| header.get(i).is_some_and(|name| *name == format!("q{i}")))
        .count()
        .max(MIN_DOF);
    let read_columns = 1 + 2 * joints;
    let full_header = csv_header(joints);
    let expected: Vec<&str> = full_header.split(',').take(read_columns).collect();
    for (column, want) in expected.iter().enumerate() {
        match header.get(column) {
            Some(name) if name == want => {}
            Some(name) => {
                return Err(FormatError::CsvHeader(format!(
                    "column {} is '{name}', expected '{want}' (the header must start with \
                     time_s,q1..qn,qd1..qdn for n = 6 or 7 joints)",
                    column + 1
                )));
            }
            None => {
                return Err(FormatError::CsvHeader(format!(
                    "has {} columns; column {} must be '{want}' (the header must start with \
                     time_s,q1..qn,qd1..qdn for n = 6 or 7 joints)",
                    header.len(),
                    column + 1
                )));
            }
        }
    }
    let (mut time_s, mut q, mut qd) = (Vec::new(), Vec::new(), Vec::new());
    for (index, row) in lines.enumerate() {
        let line = index + 2;
        let cells: Vec<&str> = row.split(',').collect();
        if cells.len() != header.len() {
            return Err(FormatError::CsvCell {
                line,
                column: cells.len().min(header.len()),
                name: header[cells.len().min(header.len()) - 1].to_string(),
                problem: format!(
                    "the row has {} cells, the header {} columns",
                    cells.len(),
                    header.len()
                ),
            });
        }
        let mut values = [0.0; 1 + 2 * MAX_DOF];
        let values = &mut values[..read_columns];
        for (column, value) in values.iter_mut().enumerate() {
            let cell = cells[column].trim();
            *value = match cell.parse::<f64>() {
                Ok(x) if x.is_finite() => x,
                _ => {
                    return Err(FormatError::CsvCell {
                        line,
                        column: column + 1,
                        name: header[column].to_string(),
                        problem: format!("'{cell}' is not a finite number"),
                    });
                }
            };
        }
        time_s.push(values[0]);
        q.push(padded(&values[1..=joints]));
        qd.push(padded(&values[1 + joints..]));
    }
    Ok(JointSamples {
        time_s,
        q,
        qd: Some(qd),
        qdd: None,
    })
}
