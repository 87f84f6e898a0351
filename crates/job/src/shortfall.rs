//! Why a stretch of a stroke is not drawn, and where that happened (docs/jobs.md, "Why a
//! stroke stops short"): each search along a stroke leaves a [`Stop`] where it ended short of
//! the stroke's end, each part left out its stretch and why, and each stretch the program does
//! not draw is given the cause found at its start.

use emg_control::{Termination, Violation, WORK_SURFACE};
use serde::{Deserialize, Serialize};

use crate::claims::{COVERAGE_SLACK_M, Stretch};

/// Why a stretch of a stroke is not drawn.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "cause", rename_all = "snake_case")]
pub enum Shortfall {
    /// The arm stopped there: its next step would have broken `violation` (a joint limit, the
    /// tool cone, the line tolerance, a collision of the arm with itself, the part or the
    /// scene).
    Reach {
        /// The constraint the next step broke.
        violation: Violation,
    },
    /// No motion starts there: the search found no configuration at the stretch's start that
    /// keeps every constraint (`why`).
    NoStart {
        /// What the search found.
        why: String,
    },
    /// A part was planned there but left out of the program: no safe move reaches it, or the
    /// tool cannot lift off it (`why`).
    LeftOut {
        /// Why the part was left out.
        why: String,
    },
    /// A part was planned there but its motion cannot be timed within the joint limits (`why`):
    /// it is left out of the program.
    Untimed {
        /// What the timing found.
        why: String,
    },
    /// The stroke's searches (`settings.max_parts`) were spent before it: it was not searched.
    NotSearched,
    /// The parts planned over it were timed shorter than planned: their samples stop before
    /// it.
    TimedShort,
}

impl Shortfall {
    /// Short machine-readable name of the cause: where the arm stopped, what its next step
    /// broke (`self_collision`: the arm itself; `part`: the part drawn on, its work surface;
    /// `scene`: another obstacle; `reach`: a joint limit, the tool cone or the line tolerance);
    /// else `no_start`, `left_out`, `untimed`, `not_searched` (the search budget) or
    /// `timed_short`.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Reach { violation } => match violation {
                Violation::SelfCollision { .. } => "self_collision",
                Violation::SceneContact { obstacle, .. } if obstacle == WORK_SURFACE => "part",
                Violation::SceneContact { .. } => "scene",
                Violation::JointLimit { .. }
                | Violation::ToolCone { .. }
                | Violation::LineTolerance { .. } => "reach",
            },
            Self::NoStart { .. } => "no_start",
            Self::LeftOut { .. } => "left_out",
            Self::Untimed { .. } => "untimed",
            Self::NotSearched => "not_searched",
            Self::TimedShort => "timed_short",
        }
    }
}

impl std::fmt::Display for Shortfall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Reach { violation } => write!(f, "out of reach: {violation}"),
            Self::NoStart { why } => write!(f, "no motion starts there: {why}"),
            Self::LeftOut { why } => write!(f, "planned but left out: {why}"),
            Self::Untimed { why } => write!(f, "planned but cannot be timed: {why}"),
            Self::NotSearched => write!(
                f,
                "not searched: the stroke's searches (settings.max_parts) were spent"
            ),
            Self::TimedShort => write!(f, "the timed motion stops before it"),
        }
    }
}

/// Where a search along a stroke ended short of the stroke's end, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Stop {
    /// Arc length along the stroke as drawn where the search ended (m): where its motion
    /// stopped, or where it could not start.
    pub at_s: f64,
    /// Why it ended there.
    pub why: Shortfall,
}

impl Stop {
    /// The stop of a motion ended by `termination` at `at_s`; `None` for a motion that ended
    /// at its path's end or at the rollout's step cap (the arm still able to go on).
    pub fn of_motion(at_s: f64, termination: &Termination) -> Option<Self> {
        let why = match termination {
            Termination::Violation { violation, .. } => Shortfall::Reach {
                violation: violation.clone(),
            },
            Termination::InvalidStart { violation } => Shortfall::NoStart {
                why: format!("its start breaks a constraint: {violation}"),
            },
            Termination::StepCap | Termination::Completed => return None,
        };
        Some(Self { at_s, why })
    }
}

/// A part planned over `planned` but left out of the program, for `why`.
#[derive(Clone, Debug, PartialEq)]
pub struct LeftOut {
    /// The stretch of the stroke the part was planned over.
    pub planned: Stretch,
    /// Why it was left out: [`Shortfall::LeftOut`] or [`Shortfall::Untimed`].
    pub why: Shortfall,
}

/// Why `undrawn`, a stretch of a stroke its program does not draw, is not drawn: a part left
/// out over it; else the stop nearest its start (within [`COVERAGE_SLACK_M`] of it or inside
/// it: a motion stopped at its start, or no motion started there); else, where the stroke's
/// searches were spent by its start (`unsearched_from_s`), not searched; else its parts were
/// timed short of it.
pub fn cause(
    undrawn: Stretch,
    stops: &[Stop],
    left_out: &[LeftOut],
    unsearched_from_s: Option<f64>,
) -> Shortfall {
    let overlap = |a: Stretch| a.to_s.min(undrawn.to_s) - a.from_s.max(undrawn.from_s);
    if let Some(part) = left_out
        .iter()
        .find(|part| overlap(part.planned) > COVERAGE_SLACK_M)
    {
        return part.why.clone();
    }
    let near = |stop: &&Stop| {
        (undrawn.from_s - COVERAGE_SLACK_M..=undrawn.to_s + COVERAGE_SLACK_M).contains(&stop.at_s)
    };
    let from_start = |stop: &Stop| (stop.at_s - undrawn.from_s).abs();
    if let Some(stop) = stops
        .iter()
        .filter(near)
        .min_by(|a, b| from_start(a).total_cmp(&from_start(b)))
    {
        return stop.why.clone();
    }
    if unsearched_from_s.is_some_and(|s| s <= undrawn.from_s + COVERAGE_SLACK_M) {
        return Shortfall::NotSearched;
    }
    Shortfall::TimedShort
}

/// The stretches `undrawn` of a stroke its program does not draw, each split where the stroke's
/// searches were spent (`unsearched_from_s`: what lies past it is [`Shortfall::NotSearched`]),
/// each with its [`cause`].
pub fn undrawn_causes(
    undrawn: &[Stretch],
    stops: &[Stop],
    left_out: &[LeftOut],
    unsearched_from_s: Option<f64>,
) -> Vec<(Stretch, Shortfall)> {
    let mut causes = Vec::with_capacity(undrawn.len());
    for &stretch in undrawn {
        let split = unsearched_from_s.filter(|&s| {
            s > stretch.from_s + COVERAGE_SLACK_M && s < stretch.to_s - COVERAGE_SLACK_M
        });
        let Some(split) = split else {
            causes.push((stretch, cause(stretch, stops, left_out, unsearched_from_s)));
            continue;
        };
        let searched = Stretch {
            from_s: stretch.from_s,
            to_s: split,
        };
        causes.push((
            searched,
            cause(searched, stops, left_out, unsearched_from_s),
        ));
        let rest = Stretch {
            from_s: split,
            to_s: stretch.to_s,
        };
        causes.push((rest, Shortfall::NotSearched));
    }
    causes
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stretch(from_s: f64, to_s: f64) -> Stretch {
        Stretch { from_s, to_s }
    }

    fn reach(joint: usize) -> Shortfall {
        Shortfall::Reach {
            violation: Violation::JointLimit {
                joint,
                value_rad: 2.9,
                limit_rad: 2.8,
            },
        }
    }

    #[test]
    fn an_undrawn_stretch_is_given_the_stop_at_its_start() {
        let stops = [
            Stop {
                at_s: 0.1,
                why: reach(1),
            },
            Stop {
                at_s: 0.4,
                why: reach(4),
            },
            Stop {
                at_s: 0.405,
                why: Shortfall::NoStart {
                    why: "no seed".into(),
                },
            },
        ];
        assert_eq!(cause(stretch(0.4, 0.5), &stops, &[], None), reach(4));
        assert_eq!(cause(stretch(0.1, 0.2), &stops, &[], Some(0.1)), reach(1));
        // Where no stop lies at or inside it, the searches spent before it or the timing.
        assert_eq!(
            cause(stretch(0.6, 0.7), &stops, &[], Some(0.6)),
            Shortfall::NotSearched
        );
        assert_eq!(
            cause(stretch(0.6, 0.7), &stops, &[], None),
            Shortfall::TimedShort
        );
    }

    #[test]
    fn a_stretch_is_split_where_the_searches_were_spent() {
        let stops = [Stop {
            at_s: 0.03,
            why: reach(6),
        }];
        let causes = undrawn_causes(&[stretch(0.03, 0.63)], &stops, &[], Some(0.05));
        assert_eq!(
            causes,
            [
                (stretch(0.03, 0.05), reach(6)),
                (stretch(0.05, 0.63), Shortfall::NotSearched)
            ]
        );
    }

    #[test]
    fn a_part_left_out_over_a_stretch_is_its_cause_whatever_stopped_near() {
        let untimed = Shortfall::Untimed {
            why: "a joint still breaks its acceleration limit".into(),
        };
        let left_out = [LeftOut {
            planned: stretch(0.0, 0.3),
            why: untimed.clone(),
        }];
        let stops = [Stop {
            at_s: 0.3,
            why: reach(2),
        }];
        assert_eq!(cause(stretch(0.0, 0.35), &stops, &left_out, None), untimed);
        assert_eq!(untimed.label(), "untimed");
        // A part left out elsewhere is not this stretch's cause.
        assert_eq!(cause(stretch(0.3, 0.4), &stops, &left_out, None), reach(2));
    }

    #[test]
    fn a_stop_is_labelled_by_what_the_next_step_broke() {
        let contact = |obstacle: &str| Shortfall::Reach {
            violation: Violation::SceneContact {
                link: "fr3_link7".into(),
                obstacle: obstacle.into(),
                clearance_m: -1e-3,
            },
        };
        let itself = Shortfall::Reach {
            violation: Violation::SelfCollision {
                first_link: "fr3_link2".into(),
                second_link: "fr3_link6".into(),
                clearance_m: 0.0,
            },
        };
        let cone = Shortfall::Reach {
            violation: Violation::ToolCone { angle_deg: 31.0 },
        };
        assert_eq!(reach(6).label(), "reach");
        assert_eq!(cone.label(), "reach");
        assert_eq!(itself.label(), "self_collision");
        assert_eq!(contact(WORK_SURFACE).label(), "part");
        assert_eq!(contact("fixture").label(), "scene");
        assert_eq!(Shortfall::NotSearched.label(), "not_searched");
    }

    #[test]
    fn motions_that_finished_or_met_the_step_cap_leave_no_stop() {
        assert_eq!(Stop::of_motion(0.2, &Termination::Completed), None);
        assert_eq!(Stop::of_motion(0.2, &Termination::StepCap), None);
        let stop = Stop::of_motion(
            0.2,
            &Termination::InvalidStart {
                violation: Violation::ToolCone { angle_deg: 31.0 },
            },
        )
        .unwrap();
        assert_eq!(stop.why.label(), "no_start");
        assert!(stop.why.to_string().contains("cone"), "{}", stop.why);
    }
}
