//! What a program claims of its strokes, measured from the motion it holds: the stretch of its
//! stroke each stroke part's samples cover, and per stroke the length drawn and the stretches
//! left undrawn. The plan measures them with the planners' kinematics when it writes the
//! program; [`crate::verify_job`] measures them again with the independent checker's and
//! refuses a program whose claims exceed what its samples draw.

use emg_control::{ARRIVAL_M, Task};
use emg_kinematics::{JointVector, Robot};
use serde::{Deserialize, Serialize};

/// A stretch of a stroke, in arc length along it as drawn (m).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stretch {
    /// Where it starts.
    pub from_s: f64,
    /// Where it ends.
    pub to_s: f64,
}

impl Stretch {
    /// Its length (m).
    pub fn length_m(&self) -> f64 {
        self.to_s - self.from_s
    }
}

/// Gaps between the stretches a stroke's parts cover shorter than this (m) are not stretches
/// left undrawn: a motion counts as at the end of its path within [`ARRIVAL_M`], and so does
/// the next part at its start.
pub const COVERAGE_SLACK_M: f64 = 2.0 * ARRIVAL_M;

/// How a stroke is covered by its parts.
#[derive(Clone, Debug, PartialEq)]
pub struct Coverage {
    /// The arc length covered: the length of the union of the parts' stretches (m).
    pub drawn_m: f64,
    /// The stretches no part covers, each longer than [`COVERAGE_SLACK_M`], in order.
    pub undrawn: Vec<Stretch>,
}

impl Coverage {
    /// How the stretches `covered` cover a stroke `length_m` long.
    pub fn of(length_m: f64, covered: &[Stretch]) -> Self {
        let mut covered: Vec<Stretch> = covered
            .iter()
            .map(|c| Stretch {
                from_s: c.from_s.clamp(0.0, length_m),
                to_s: c.to_s.clamp(0.0, length_m),
            })
            .collect();
        covered.sort_by(|a, b| a.from_s.total_cmp(&b.from_s));
        let mut drawn_m = 0.0;
        let mut undrawn = Vec::new();
        // How far the union reaches so far.
        let mut reach = 0.0_f64;
        for stretch in &covered {
            if stretch.from_s - reach > COVERAGE_SLACK_M {
                undrawn.push(Stretch {
                    from_s: reach,
                    to_s: stretch.from_s,
                });
            }
            drawn_m += (stretch.to_s - stretch.from_s.max(reach)).max(0.0);
            reach = reach.max(stretch.to_s);
        }
        if length_m - reach > COVERAGE_SLACK_M {
            undrawn.push(Stretch {
                from_s: reach,
                to_s: length_m,
            });
        }
        Self { drawn_m, undrawn }
    }

    /// Whether every stretch of the stroke is covered.
    pub fn whole(&self) -> bool {
        self.undrawn.is_empty()
    }
}

/// Where a stroke part's task lies on its stroke: it starts `from_s` along the stroke and runs
/// toward the stroke's end, or back toward its start where `backward` (a part drawn from the
/// stroke's other end).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OnStroke {
    /// Arc length along the stroke where the task starts (m).
    pub from_s: f64,
    /// Whether the task runs back toward the stroke's start.
    pub backward: bool,
}

impl OnStroke {
    /// The arc length along the stroke of the point `s` along the task (m).
    pub fn stroke_s(&self, s: f64) -> f64 {
        if self.backward {
            self.from_s - s
        } else {
            self.from_s + s
        }
    }

    /// The stretch of the stroke between the task's progress `least` and `greatest`.
    pub fn stretch(&self, least: f64, greatest: f64) -> Stretch {
        let (a, b) = (self.stroke_s(least), self.stroke_s(greatest));
        Stretch {
            from_s: a.min(b),
            to_s: a.max(b),
        }
    }
}

/// The stretch of its stroke that the configurations `samples` of a stroke part cover, the
/// part's task lying `on` the stroke: the TCP's progress along the task followed from its start
/// (as the planners follow it, [`Task::along`]), from its least to its greatest, mapped onto
/// the stroke.
pub fn part_coverage<'a>(
    robot: &Robot,
    task: &Task,
    on: OnStroke,
    samples: impl IntoIterator<Item = &'a JointVector>,
) -> Stretch {
    let mut s = 0.0_f64;
    let (mut least, mut greatest) = (f64::INFINITY, f64::NEG_INFINITY);
    for q in samples {
        s = task.along(&robot.forward(q).tcp(), s).s_m;
        least = least.min(s);
        greatest = greatest.max(s);
    }
    on.stretch(least.min(greatest), greatest.max(least))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stretch(from_s: f64, to_s: f64) -> Stretch {
        Stretch { from_s, to_s }
    }

    #[test]
    fn the_union_of_overlapping_parts_counts_once_and_gaps_are_listed() {
        let coverage = Coverage::of(
            1.0,
            &[stretch(0.5, 0.7), stretch(0.0, 0.3), stretch(0.298, 0.4)],
        );
        assert!(
            (coverage.drawn_m - 0.6).abs() < 1e-12,
            "{}",
            coverage.drawn_m
        );
        assert_eq!(coverage.undrawn, vec![stretch(0.4, 0.5), stretch(0.7, 1.0)]);
        assert!(!coverage.whole());
    }

    #[test]
    fn gaps_within_the_slack_are_not_undrawn() {
        let gap = COVERAGE_SLACK_M * 0.5;
        let coverage = Coverage::of(1.0, &[stretch(gap, 0.5), stretch(0.5 + gap, 1.0 - gap)]);
        assert!(coverage.whole(), "{:?}", coverage.undrawn);
        assert!((coverage.drawn_m - (1.0 - 3.0 * gap)).abs() < 1e-12);
        let nothing = Coverage::of(0.2, &[]);
        assert_eq!(
            (nothing.drawn_m, nothing.undrawn),
            (0.0, vec![stretch(0.0, 0.2)])
        );
    }
}
