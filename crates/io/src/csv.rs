//! The CSV table of a rollout: `time_s`, `q1..q7`, `qd1..qd7`, TCP, tool angle, `ρ`, controller.
//! The layout is documented in `docs/trajectory-format.md`.

use emg_control::StepRecord;
use emg_kinematics::{DOF, JointVector};
use emg_verify::{JointSamples, point_velocities};

use crate::error::FormatError;

/// The CSV header written by [`trajectory_csv`]; [`read_csv`] needs its first 15 columns.
pub const CSV_HEADER: &str = "time_s,q1,q2,q3,q4,q5,q6,q7,qd1,qd2,qd3,qd4,qd5,qd6,qd7,\
                              tcp_x,tcp_y,tcp_z,tool_angle_deg,rho,controller";

/// Columns [`read_csv`] reads: the time, the positions and the declared velocities.
const CSV_READ_COLUMNS: usize = 1 + 2 * DOF;

/// Times and positions of recorded steps (exact times, no declared velocities).
pub fn samples_from_steps(steps: &[StepRecord]) -> JointSamples {
    JointSamples {
        time_s: steps.iter().map(|s| s.time_s).collect(),
        q: steps.iter().map(|s| s.q).collect(),
        qd: None,
        qdd: None,
    }
}

/// The CSV table of a rollout's steps: [`CSV_HEADER`], then one row per step: time (s),
/// positions (rad), velocities by [`point_velocities`] (rad/s), TCP (m), tool angle (degrees),
/// `ρ`, and the acting controller (`classical`, `learned` or empty). Numbers are Rust's
/// shortest round-trip form, so [`read_csv`] gives back the very same values.
pub fn trajectory_csv(steps: &[StepRecord]) -> String {
    let samples = samples_from_steps(steps);
    let velocities = point_velocities(&samples.time_s, &samples.q);
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for (step, qd) in steps.iter().zip(&velocities) {
        let mut row = vec![step.time_s];
        row.extend(step.q.iter());
        row.extend(qd.iter());
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

/// Reads a CSV table: the header must start with `time_s,q1..q7,qd1..qd7` (the columns after
/// those are not read); every row must have as many cells as the header, and the cells read
/// must be finite numbers. The error names the line, the column and what is wrong.
pub fn read_csv(text: &str) -> Result<JointSamples, FormatError> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or_else(|| FormatError::CsvHeader("the file is empty".into()))?
        .split(',')
        .map(str::trim)
        .collect();
    let expected: Vec<&str> = CSV_HEADER.split(',').take(CSV_READ_COLUMNS).collect();
    for (column, want) in expected.iter().enumerate() {
        match header.get(column) {
            Some(name) if name == want => {}
            Some(name) => {
                return Err(FormatError::CsvHeader(format!(
                    "column {} is '{name}', expected '{want}' (the header must start with \
                     time_s,q1..q7,qd1..qd7)",
                    column + 1
                )));
            }
            None => {
                return Err(FormatError::CsvHeader(format!(
                    "has {} columns; column {} must be '{want}' (the header must start with \
                     time_s,q1..q7,qd1..qd7)",
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
        let mut values = [0.0; CSV_READ_COLUMNS];
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
        q.push(JointVector::from_column_slice(&values[1..=DOF]));
        qd.push(JointVector::from_column_slice(&values[DOF + 1..]));
    }
    Ok(JointSamples {
        time_s,
        q,
        qd: Some(qd),
        qdd: None,
    })
}
