//! A URScript program for a Universal Robots e-Series controller: `movej` to the start, then one
//! `servoj` target per 2 ms controller cycle, resampled from the timed motion (the quintic
//! through the two samples around each target's time, exact where the samples fall on the 2 ms
//! grid), held at the end and stopped.

use crate::joint_trajectory::JointTrajectoryPoint;

/// The e-Series controller's cycle, the time each `servoj` target is tracked for (s).
pub const SERVO_PERIOD_S: f64 = 0.002;
/// `servoj`'s `lookahead_time` (s, URScript's range 0.03–0.2): how far ahead the controller
/// smooths the targets; 0.1 s, the value of Universal Robots' and ur_rtde's examples.
pub const LOOKAHEAD_TIME_S: f64 = 0.1;
/// `servoj`'s `gain` (URScript's range 100–2000): the proportional gain tracking the targets;
/// 300, the value of the same examples.
pub const GAIN: u32 = 300;
/// `movej`'s joint speed on the way to the start (rad/s): URScript's default.
pub const MOVEJ_SPEED_RAD_S: f64 = 1.05;
/// `movej`'s joint acceleration on the way to the start (rad/s²): URScript's default.
pub const MOVEJ_ACCELERATION_RAD_S2: f64 = 1.4;
/// How far (rad) each joint may stand from the start of a motion that starts at the arm's home
/// when the program begins.
pub const START_TOLERANCE_RAD: f64 = 0.01;
/// How long the last target is held after the motion (s): the lookahead's lag settles.
pub const HOLD_S: f64 = 0.2;
/// Most `servoj` lines one program holds by default: 2,500 (5 s of motion). Universal Robots
/// publishes no limit; users report UR controllers that do not run streamed programs of more
/// than about 2,500 targets (visose/Robots issue 55, a UR5; ros-industrial/universal_robot
/// issue 411 reports 1,000 on a UR10), so a longer motion is split where it rests, or refused.
pub const DEFAULT_MAX_SERVOJ_LINES: usize = 2500;

/// One `servoj` target.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    /// Time since the motion's start (s).
    pub time_s: f64,
    /// Joint positions (rad), the pendant's order.
    pub q: Vec<f64>,
    /// Whether the motion is at rest here (every velocity zero).
    pub at_rest: bool,
}

/// The motion resampled every [`SERVO_PERIOD_S`] from its start to its end (the last target at
/// the last point, at rest).
pub fn resample(points: &[JointTrajectoryPoint]) -> Vec<Target> {
    let Some(last) = points.last() else {
        return Vec::new();
    };
    let ns = |k: usize| {
        i64::from(points[k].time_from_start.sec) * 1_000_000_000
            + i64::from(points[k].time_from_start.nanosec)
    };
    let end_ns = ns(points.len() - 1);
    let period_ns = 2_000_000_i64;
    let count = (end_ns + period_ns - 1) / period_ns;
    let mut targets = Vec::with_capacity(count as usize + 1);
    let mut k = 0;
    for i in 0..=count {
        let t_ns = (i * period_ns).min(end_ns);
        while k + 1 < points.len() && ns(k + 1) <= t_ns {
            k += 1;
        }
        let (q, at_rest) = if ns(k) == t_ns || k + 1 == points.len() {
            let p = &points[k];
            (p.positions.clone(), p.velocities.iter().all(|v| *v == 0.0))
        } else {
            let kept = [k, k + 1];
            let h = (t_ns - ns(k)) as f64 * 1e-9;
            (super::thinning::positions_between(points, kept, h), false)
        };
        targets.push(Target {
            time_s: t_ns as f64 * 1e-9,
            q,
            at_rest,
        });
    }
    debug_assert_eq!(targets.last().map(|t| &t.q), Some(&last.positions));
    targets
}

/// The targets split into programs of at most `max_lines` targets each, cut where the motion
/// rests (each program but the first starts where the one before it stopped, at rest): the
/// index ranges; `Err` with the first stretch between rests that is longer.
pub fn split(targets: &[Target], max_lines: usize) -> Result<Vec<(usize, usize)>, (f64, f64)> {
    let rests: Vec<usize> = (0..targets.len())
        .filter(|&i| targets[i].at_rest || i + 1 == targets.len())
        .collect();
    let mut parts = Vec::new();
    let mut start = 0;
    while start + 1 < targets.len() {
        let end = rests
            .iter()
            .copied()
            .rfind(|&r| r > start && r - start <= max_lines);
        match end {
            Some(end) => {
                parts.push((start, end));
                start = end;
            }
            None => {
                let next = rests.iter().copied().find(|&r| r > start).unwrap_or(start);
                return Err((targets[start].time_s, targets[next].time_s));
            }
        }
    }
    if parts.is_empty() {
        parts.push((0, targets.len().saturating_sub(1)));
    }
    Ok(parts)
}

/// A joint vector as URScript writes it, every number in its shortest round-trip form and in
/// plain decimals (never an exponent).
pub fn joint_list(q: &[f64]) -> String {
    let values: Vec<String> = q.iter().map(|v| format!("{v}")).collect();
    format!("[{}]", values.join(", "))
}

/// The lines of a program's body (indented by two spaces) that halt it, with a message on the
/// pendant, unless the arm stands at `home`: every joint within [`START_TOLERANCE_RAD`] of it.
pub fn home_check(home: &[f64]) -> String {
    let mut text = String::new();
    text.push_str("  # the arm's home, where the motion starts: the arm must stand there\n");
    text.push_str(&format!("  home = {}\n", joint_list(home)));
    text.push_str("  actual = get_actual_joint_positions()\n");
    text.push_str("  joint = 0\n");
    text.push_str(&format!("  while joint < {}:\n", home.len()));
    text.push_str(&format!(
        "    if norm(actual[joint] - home[joint]) > {START_TOLERANCE_RAD}:\n"
    ));
    text.push_str(
        "      popup(\"The arm is not at the program's home: move it there first.\", \
         title=\"emg\", error=True, blocking=True)\n",
    );
    text.push_str("      halt\n");
    text.push_str("    end\n");
    text.push_str("    joint = joint + 1\n");
    text.push_str("  end\n");
    text
}

/// How a program comes to its first target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// `movej` there from wherever the arm stands.
    Move,
    /// The arm must stand there (the arm's home): every joint within [`START_TOLERANCE_RAD`]
    /// of it, else a popup and `halt`.
    Check,
}

/// The program running `targets[range.0..=range.1]`, with `header` lines as comments, coming
/// to its first target as `start` says.
pub fn program(
    targets: &[Target],
    range: (usize, usize),
    name: &str,
    header: &[String],
    start: Start,
) -> String {
    let mut text = String::new();
    for line in header {
        text.push_str(&format!("# {line}\n"));
    }
    let (first, last) = (&targets[range.0], &targets[range.1]);
    text.push_str(&format!("def {name}():\n"));
    match start {
        Start::Move => {
            text.push_str(&format!(
                "  # the way to the start, at rest (t = {:.3} s of the motion)\n",
                first.time_s
            ));
            text.push_str(&format!(
                "  movej({}, a={MOVEJ_ACCELERATION_RAD_S2}, v={MOVEJ_SPEED_RAD_S})\n",
                joint_list(&first.q)
            ));
        }
        Start::Check => text.push_str(&home_check(&first.q)),
    }
    text.push_str(&format!(
        "  # servoj(q, a, v, t, lookahead_time, gain): one target every {SERVO_PERIOD_S} s\n"
    ));
    for target in &targets[range.0 + 1..=range.1] {
        text.push_str(&format!(
            "  servoj({}, 0, 0, {SERVO_PERIOD_S}, {LOOKAHEAD_TIME_S}, {GAIN})\n",
            joint_list(&target.q)
        ));
    }
    text.push_str(&format!(
        "  # at rest at t = {:.3} s: hold the last target while the lookahead settles, then stop\n",
        last.time_s
    ));
    text.push_str(&format!(
        "  servoj({}, 0, 0, {HOLD_S}, {LOOKAHEAD_TIME_S}, {GAIN})\n",
        joint_list(&last.q)
    ));
    text.push_str(&format!("  stopj({MOVEJ_ACCELERATION_RAD_S2})\n"));
    text.push_str("end\n");
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn targets(rest_at: &[usize], count: usize) -> Vec<Target> {
        (0..count)
            .map(|i| Target {
                time_s: i as f64 * SERVO_PERIOD_S,
                q: vec![0.0; 6],
                at_rest: i == 0 || rest_at.contains(&i),
            })
            .collect()
    }

    #[test]
    fn long_motions_split_where_they_rest_or_are_refused() {
        assert_eq!(split(&targets(&[], 11), 10), Ok(vec![(0, 10)]));
        assert_eq!(split(&targets(&[4, 9], 15), 10), Ok(vec![(0, 9), (9, 14)]));
        assert_eq!(
            split(&targets(&[4], 20), 10),
            Err((4.0 * SERVO_PERIOD_S, 19.0 * SERVO_PERIOD_S))
        );
    }
}
