//! From planned waypoints to a rest-to-rest motion sampled at a fixed rate: the smooth path
//! ([`SmoothPath`]), TOPP-RA under the joint velocity and acceleration limits and the tool-speed
//! cap ([`topp_ra`]), the jerk-limiting moving average ([`SmoothedProfile`]), and local slow-downs
//! wherever the samples still break a limit ([`breaches`]).

use emg_control::{ConstraintConfig, Task};
use emg_kinematics::{JointVector, Robot};

use crate::dynamics::{LimitBreach, TimedSample, breaches};
use crate::limits::DynamicLimits;
use crate::motion::{MAX_SAMPLES, MotionDefinition, ProfileGrid, SplineStretch};
use crate::path::SmoothPath;
use crate::profile::{PathState, SmoothedProfile};
use crate::sampling::{at_rest, sample};
use crate::topp::{GridPoint, profile_duration, topp_ra};

/// Longest grid step of TOPP-RA along the path (m of TCP travel).
pub const GRID_STEP_M: f64 = 2e-3;

/// Fewest grid intervals of TOPP-RA on a moving path.
pub const MIN_GRID_INTERVALS: usize = 50;

/// Factor on the local speed bound (and acceleration limits) around a sample that breaks a
/// limit, per slow-down round.
pub const SLOWDOWN: f64 = 0.8;

/// Share of the acceleration limits TOPP-RA plans for: the rest absorbs the grid's
/// discretization and the moving average's mixing of neighbouring path points.
pub const ACCELERATION_MARGIN: f64 = 0.97;

/// Slow-down rounds at most before giving up.
pub const MAX_SLOWDOWNS: usize = 60;

/// Largest distance (m of arc length) between an unblended corner of a path and the waypoint
/// the motion rests at for it.
pub const REST_SNAP_M: f64 = 1e-3;

/// Share of the requested tool speed above which the tool counts as moving at it.
pub const AT_TOOL_SPEED: f64 = 0.99;

/// What the timing is asked for.
#[derive(Clone, Debug, PartialEq)]
pub struct TimingRequest {
    /// Joint limits, already scaled (and capped by the robot file's velocity limits).
    pub limits: DynamicLimits,
    /// Largest tool (TCP) speed (m/s): the tool moves at it wherever the joints allow.
    pub tool_speed_m_per_s: f64,
    /// Samples per second of the output.
    pub rate_hz: f64,
}

/// What the timing did and how the motion turned out.
#[derive(Clone, Debug, PartialEq)]
pub struct TimingReport {
    /// Time from rest to rest of the output (s).
    pub duration_s: f64,
    /// Time of the fastest motion along the same path under the velocity, acceleration and
    /// tool-speed limits alone (TOPP-RA without jerk limits or slow-downs) (s).
    pub time_optimal_s: f64,
    /// Share of the motion's duration during which the tool moves at ≥ [`AT_TOOL_SPEED`] × the
    /// requested speed.
    pub tool_speed_share: f64,
    /// TCP travel along the path (m).
    pub path_travel_m: f64,
    /// Knots the smooth path gained to hold the task constraints.
    pub refined_knots: usize,
    /// When the smooth path had to end before the last waypoint: the waypoint it ends at and
    /// the constraint the spline broke beyond it.
    pub cut: Option<(usize, String)>,
    /// TOPP-RA grid points.
    pub grid_points: usize,
    /// Rounds of local slow-down the limits needed.
    pub slowdowns: usize,
    /// Times (s) at which the motion rests inside its path: at the corners a path task does not
    /// blend ([`rest_waypoints`]), and where a limit forced a rest ([`time_motion`]); empty on a
    /// line timed without one.
    pub rests_s: Vec<f64>,
}

/// How far (rad, largest joint difference) the motion may move past the sample nearest a
/// waypoint before [`TimedMotion::passing_times_s`] stops looking for a nearer one: more than a
/// planned step moves (a few hundredths), less than a path takes to come back.
pub const PASSING_WINDOW_RAD: f64 = 0.2;

/// A rest-to-rest motion at a fixed rate, with its path and report.
#[derive(Clone, Debug)]
pub struct TimedMotion {
    /// Samples at `k / rate` (rounded to whole nanoseconds), from rest to rest.
    pub samples: Vec<TimedSample>,
    /// The smooth paths the samples follow, one per stretch between rests (one unless a path
    /// task's motion rests at its corners).
    pub paths: Vec<SmoothPath>,
    /// Path parameters of the TOPP-RA grid (over the stretches one after another, each
    /// stretch's parameters after the last one's end).
    pub grid_s: Vec<f64>,
    /// What the timing did.
    pub report: TimingReport,
    /// What the samples are computed from ([`MotionDefinition::samples`] gives them again).
    pub definition: MotionDefinition,
}

/// Why a motion could not be timed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TimingError {
    /// A request field is unusable.
    #[error("{field} must be {allowed}, got {value}")]
    Request {
        /// The field.
        field: &'static str,
        /// What it must be.
        allowed: &'static str,
        /// The value given.
        value: f64,
    },
    /// The motion would need more than [`MAX_SAMPLES`] samples.
    #[error(
        "the motion takes {duration_s:.1} s: {samples:.0} samples at {rate_hz} Hz, more than \
         {MAX_SAMPLES:.0}; lower the rate or raise the tool speed"
    )]
    TooManySamples {
        /// Duration of the motion (s).
        duration_s: f64,
        /// Samples it would take.
        samples: f64,
        /// The rate asked for.
        rate_hz: f64,
    },
    /// The samples still broke a limit after [`MAX_SLOWDOWNS`] rounds, with
    /// [`MAX_FORCED_RESTS`] rests added or at a stretch between two consecutive waypoints.
    #[error(
        "the motion still breaks a limit after {MAX_SLOWDOWNS} slow-downs, resting at its \
         waypoints: {0}"
    )]
    LimitsNotMet(LimitBreach),
}

impl TimingRequest {
    /// Checks the tool speed, the rate and every limit are positive and finite.
    pub fn validate(&self) -> Result<(), TimingError> {
        let positive = |field, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(TimingError::Request {
                    field,
                    allowed: "a positive finite number",
                    value,
                })
            }
        };
        positive("tool_speed_m_per_s", self.tool_speed_m_per_s)?;
        positive("rate_hz", self.rate_hz)?;
        for (field, values) in [
            ("max_velocity", &self.limits.velocity),
            ("max_acceleration", &self.limits.acceleration),
            ("max_jerk", &self.limits.jerk),
        ] {
            for v in values.iter() {
                positive(field, *v)?;
            }
        }
        Ok(())
    }
}

/// Rests at most that the timing adds inside a motion where a stretch between rests still
/// breaks a limit after [`MAX_SLOWDOWNS`] slow-downs ([`time_motion`]).
pub const MAX_FORCED_RESTS: usize = 32;

/// The rest-to-rest motion through `waypoints` (each holding `constraints` for `task`, the
/// first the start). On a path task the motion also comes to rest at every corner the path
/// does not blend ([`rest_waypoints`]): each stretch between rests is timed on its own and the
/// stretches follow one another on the sample grid. Where a stretch still breaks a limit after
/// [`MAX_SLOWDOWNS`] slow-downs (a cusp the spline turns through too fast, say), the motion
/// also rests at the stretch's inner waypoint nearest (in joint space) the first sample that
/// breaks it, and the stretches are timed again: a motion is slowed to rest where a limit forces
/// it rather than given up, up to [`MAX_FORCED_RESTS`] such rests.
///
/// On a path, every sample is then measured as the checker measures it: its TCP followed
/// along the path sample by sample ([`Task::along`]) within the line tolerance of the point it
/// reached. Where one is not, the motion is timed again through the waypoints before it only,
/// and its report says where and why it was cut.
///
/// On a path the waypoints' postures are evened out first (every TCP kept, [`SmoothPath::fit`]),
/// which lets the tool keep its speed through curves; where that motion is cut before the
/// motion through the postures as planned, or cannot be timed, the latter is taken.
pub fn time_motion(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    waypoints: &[JointVector],
    request: &TimingRequest,
) -> Result<TimedMotion, TimingError> {
    let problem = |even_postures| TimingProblem {
        robot,
        task,
        constraints,
        request,
        even_postures,
    };
    if task.path.is_none() {
        return time_within_tolerance(&problem(false), waypoints);
    }
    let evened = match time_within_tolerance(&problem(true), waypoints) {
        Ok(motion) => motion,
        Err(_) => return time_within_tolerance(&problem(false), waypoints),
    };
    let Some((evened_end, _)) = evened.report.cut.clone() else {
        return Ok(evened);
    };
    let planned = time_within_tolerance(&problem(false), waypoints)?;
    Ok(match &planned.report.cut {
        Some((planned_end, _)) if *planned_end <= evened_end => evened,
        _ => planned,
    })
}

/// The motion of [`time_motion`] for `problem`, cut before the first sample that leaves the
/// line tolerance of a path.
fn time_within_tolerance(
    problem: &TimingProblem,
    waypoints: &[JointVector],
) -> Result<TimedMotion, TimingError> {
    let mut end = waypoints.len();
    let mut cut = None;
    loop {
        let mut motion = time_rested(problem, &waypoints[..end])?;
        let Some((time_s, distance_m)) = first_sample_off(problem, &motion) else {
            if motion.report.cut.is_none() {
                motion.report.cut = cut;
            }
            return Ok(motion);
        };
        let passing = motion.passing_times_s(&waypoints[..end]);
        let before = passing
            .iter()
            .rposition(|t| *t < time_s)
            .unwrap_or(0)
            .min(end.saturating_sub(2));
        end = before + 1;
        cut = Some((
            before,
            format!(
                "a timed sample left the line tolerance ({:.2} mm off the path where it \
                 reached)",
                distance_m * 1e3
            ),
        ));
    }
}

/// What every stretch of a [`time_motion`] call is timed for: the arm, its task and the
/// constraints its waypoints hold, and the request.
#[derive(Clone, Copy)]
struct TimingProblem<'a> {
    robot: &'a Robot,
    task: &'a Task,
    constraints: &'a ConstraintConfig,
    request: &'a TimingRequest,
    /// Whether the waypoints' postures are evened out before the spline is fitted.
    even_postures: bool,
}

/// The time (s) of the first sample of `motion` whose TCP, followed along a path task sample by
/// sample, lies farther than the line tolerance from the path point it reached, and that
/// distance (m); `None` on a line, or where every sample lies within it.
fn first_sample_off(problem: &TimingProblem, motion: &TimedMotion) -> Option<(f64, f64)> {
    let TimingProblem {
        robot,
        task,
        constraints,
        ..
    } = *problem;
    task.path.as_ref()?;
    let mut s = 0.0;
    motion.samples.iter().find_map(|sample| {
        let along = task.along(&robot.forward(&sample.q).tcp(), s);
        s = along.s_m;
        let distance_m = along.lateral.norm();
        (distance_m > constraints.line_tolerance_m).then(|| (sample.time_s(), distance_m))
    })
}

/// [`time_motion`] before its samples are measured: the stretches between rests timed, with
/// the rests a limit forces.
fn time_rested(
    problem: &TimingProblem,
    waypoints: &[JointVector],
) -> Result<TimedMotion, TimingError> {
    let TimingProblem {
        robot,
        task,
        request,
        ..
    } = *problem;
    request.validate()?;
    let progress = waypoint_progress(robot, task, waypoints);
    let mut rests = rest_waypoints(task, &progress);
    for forced in 0..=MAX_FORCED_RESTS {
        let unmet = match time_through(problem, waypoints, &progress, &rests) {
            Ok(motion) => return Ok(motion),
            Err(StretchError::Timing(error)) => return Err(error),
            Err(StretchError::Unmet(unmet)) => unmet,
        };
        let (from, to) = unmet.between;
        let nearest = (from + 1..to).min_by(|&a, &b| {
            (waypoints[a] - unmet.at)
                .amax()
                .total_cmp(&(waypoints[b] - unmet.at).amax())
        });
        match nearest {
            Some(k) if forced < MAX_FORCED_RESTS => {
                rests.insert(rests.partition_point(|&r| r < k), k);
            }
            _ => return Err(TimingError::LimitsNotMet(unmet.breach)),
        }
    }
    unreachable!("the loop returns by its last round")
}

/// Why a stretch between rests could not be timed.
enum StretchError {
    /// The request or the motion's length.
    Timing(TimingError),
    /// A limit still broken after [`MAX_SLOWDOWNS`] slow-downs.
    Unmet(Unmet),
}

/// A stretch whose samples still break a limit after [`MAX_SLOWDOWNS`] slow-downs.
struct Unmet {
    /// The first breach.
    breach: LimitBreach,
    /// The configuration of the sample that breaks it.
    at: JointVector,
    /// The stretch's first and last waypoints (indices into the whole motion's).
    between: (usize, usize),
}

/// The motion through `waypoints` (standing `progress` along the task) at rest at each of
/// `rests` (increasing inner waypoints): each stretch between rests timed on its own, the
/// stretches one after another on the sample grid, up to the first one the smooth path cuts.
fn time_through(
    problem: &TimingProblem,
    waypoints: &[JointVector],
    progress: &[f64],
    rests: &[usize],
) -> Result<TimedMotion, StretchError> {
    let bounds: Vec<usize> = std::iter::once(0)
        .chain(rests.iter().copied())
        .chain(std::iter::once(waypoints.len() - 1))
        .collect();
    let mut joined: Option<TimedMotion> = None;
    for pair in bounds.windows(2) {
        let stretch = time_stretch(problem, &waypoints[pair[0]..=pair[1]], progress[pair[0]])
            .map_err(|error| match error {
                StretchError::Unmet(unmet) => StretchError::Unmet(Unmet {
                    between: (pair[0], pair[1]),
                    ..unmet
                }),
                timing => timing,
            })?;
        let cut = stretch.report.cut.is_some();
        joined = Some(match joined {
            None => stretch,
            Some(before) => before.followed_by(stretch, pair[0], problem.request.rate_hz),
        });
        if cut {
            break;
        }
    }
    Ok(joined.expect("a motion has a stretch"))
}

/// Each waypoint's progress along the task, followed from the start ([`Task::along`]).
pub fn waypoint_progress(robot: &Robot, task: &Task, waypoints: &[JointVector]) -> Vec<f64> {
    let mut s = 0.0;
    waypoints
        .iter()
        .map(|q| {
            s = task.along(&robot.forward(q).tcp(), s).s_m;
            s
        })
        .collect()
}

/// The interior waypoints at which a path task's motion comes to rest, the waypoints standing
/// `progress` along it ([`waypoint_progress`]): for each corner the path does not blend, in
/// order along the path, the waypoint nearest it along the path among those after the last
/// rest, when that lies within [`REST_SNAP_M`] of it (a rollout's step lands on a corner, to
/// the step's linearisation). Strictly increasing, so that the stretches between rests follow
/// one another; none on a line.
pub fn rest_waypoints(task: &Task, progress: &[f64]) -> Vec<usize> {
    let Some(path) = &task.path else {
        return Vec::new();
    };
    let mut rests: Vec<usize> = Vec::new();
    for corner in path.corners_m() {
        let after = rests.last().map_or(1, |last| last + 1);
        let nearest = (after..progress.len().saturating_sub(1))
            .map(|k| (k, (progress[k] - corner).abs()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .filter(|&(_, gap)| gap <= REST_SNAP_M);
        rests.extend(nearest.map(|(k, _)| k));
    }
    rests
}

impl TimedMotion {
    /// When the motion passes each of `waypoints` (the planned configurations it was timed
    /// through, in order): the time (s) of the sample nearest each in joint space (largest
    /// joint difference), searched forward from the previous waypoint's sample, and only until
    /// the motion has moved [`PASSING_WINDOW_RAD`] past the nearest one so far (a path that
    /// comes back near itself is not taken for its return). A motion cut short gives its last
    /// sample's time to the waypoints beyond its end.
    pub fn passing_times_s(&self, waypoints: &[JointVector]) -> Vec<f64> {
        let mut from = 0;
        waypoints
            .iter()
            .map(|waypoint| {
                let distance = |k: usize| (self.samples[k].q - waypoint).amax();
                let mut best = from;
                for k in from..self.samples.len() {
                    let d = distance(k);
                    if d < distance(best) {
                        best = k;
                    } else if d > distance(best) + PASSING_WINDOW_RAD {
                        break;
                    }
                }
                from = best;
                self.samples.get(best).map_or(0.0, TimedSample::time_s)
            })
            .collect()
    }

    /// This motion, then `next` (which starts at rest where this one ends, at waypoint
    /// `first_waypoint` of the whole motion): its samples after its first follow on the grid
    /// of `rate_hz`, its grid after this one's path parameters, its report added to this one's.
    fn followed_by(mut self, next: TimedMotion, first_waypoint: usize, rate_hz: f64) -> Self {
        let rest_s = self.samples.last().map_or(0.0, TimedSample::time_s);
        let offset_samples = self.samples.len() as u64 - 1;
        self.samples
            .extend(next.samples.iter().skip(1).enumerate().map(|(k, sample)| {
                let index = offset_samples + k as u64 + 1;
                TimedSample {
                    time_ns: (index as f64 * 1e9 / rate_hz).round() as u64,
                    ..*sample
                }
            }));
        let offset_s = self.grid_s.last().copied().unwrap_or(0.0);
        self.grid_s
            .extend(next.grid_s.iter().skip(1).map(|s| s + offset_s));
        let (before, after) = (&self.report, &next.report);
        let duration_s = self.samples.last().map_or(0.0, TimedSample::time_s);
        self.report = TimingReport {
            duration_s,
            time_optimal_s: before.time_optimal_s + after.time_optimal_s,
            tool_speed_share: (before.tool_speed_share * before.duration_s
                + after.tool_speed_share * after.duration_s)
                / (before.duration_s + after.duration_s).max(f64::MIN_POSITIVE),
            path_travel_m: before.path_travel_m + after.path_travel_m,
            refined_knots: before.refined_knots + after.refined_knots,
            cut: after
                .cut
                .as_ref()
                .map(|(waypoint, why)| (first_waypoint + waypoint, why.clone())),
            grid_points: before.grid_points + after.grid_points,
            slowdowns: before.slowdowns.max(after.slowdowns),
            rests_s: before
                .rests_s
                .iter()
                .copied()
                .chain(std::iter::once(rest_s))
                .collect(),
        };
        self.paths.extend(next.paths);
        if let (
            MotionDefinition::Splines { stretches, .. },
            MotionDefinition::Splines {
                stretches: following,
                ..
            },
        ) = (&mut self.definition, next.definition)
        {
            stretches.extend(following);
        }
        self
    }
}

/// One stretch from rest to rest through `waypoints` (the first `from_s` along the task): the
/// smooth path, then TOPP-RA on a grid of
/// at most [`GRID_STEP_M`], the moving average over `w = 2 max_j a_j / j_j`, samples at the
/// requested rate, and, while a sample breaks a limit, the speed and acceleration bounds around
/// it lowered by [`SLOWDOWN`].
fn time_stretch(
    problem: &TimingProblem,
    waypoints: &[JointVector],
    from_s: f64,
) -> Result<TimedMotion, StretchError> {
    let TimingProblem {
        robot,
        task,
        constraints,
        request,
        even_postures,
    } = *problem;
    let path = SmoothPath::fit(robot, task, constraints, waypoints, from_s, even_postures);
    let cut = path
        .cut
        .as_ref()
        .map(|(waypoint, violation)| (*waypoint, violation.to_string()));
    let Some(spline) = path.spline() else {
        let start = path.start();
        return Ok(TimedMotion {
            samples: vec![at_rest(start)],
            grid_s: Vec::new(),
            report: TimingReport {
                duration_s: 0.0,
                time_optimal_s: 0.0,
                tool_speed_share: 0.0,
                path_travel_m: 0.0,
                refined_knots: path.refined_knots,
                cut,
                grid_points: 0,
                slowdowns: 0,
                rests_s: Vec::new(),
            },
            paths: vec![path],
            definition: MotionDefinition::Splines {
                start,
                stretches: Vec::new(),
            },
        });
    };
    let length = spline.end();
    let intervals = ((length / GRID_STEP_M).ceil() as usize).max(MIN_GRID_INTERVALS);
    let limits = &request.limits;
    let mut tool_gain = Vec::with_capacity(intervals + 1);
    let grid: Vec<GridPoint> = (0..=intervals)
        .map(|i| {
            let s = if i == intervals {
                length
            } else {
                length * i as f64 / intervals as f64
            };
            let point = spline.eval(s);
            let gain = (robot.forward(&point.q).jacobian() * point.dq).norm();
            tool_gain.push(gain);
            let mut x_max = (request.tool_speed_m_per_s / gain).powi(2);
            for j in 0..limits.velocity.len() {
                x_max = x_max.min((limits.velocity[j] / point.dq[j].abs()).powi(2));
            }
            GridPoint {
                s,
                dq: point.dq,
                ddq: point.ddq,
                x_max,
            }
        })
        .collect();
    let window = 2.0
        * limits
            .acceleration
            .iter()
            .zip(limits.jerk.iter())
            .map(|(a, j)| a / j)
            .fold(0.0, f64::max);
    let mut factor = vec![1.0; grid.len()];
    let time_optimal_s = profile_duration(&grid, &topp_ra(&grid, &limits.acceleration, &factor));
    let grid_s: Vec<f64> = grid.iter().map(|g| g.s).collect();
    for slowdowns in 0..=MAX_SLOWDOWNS {
        let definition = planned_profile(&grid, &grid_s, limits, &factor, window);
        let profile = definition.smoothed();
        let samples = profile.duration() * request.rate_hz;
        if samples > MAX_SAMPLES {
            return Err(StretchError::Timing(TimingError::TooManySamples {
                duration_s: profile.duration(),
                samples,
                rate_hz: request.rate_hz,
            }));
        }
        let (samples, states) = sample(spline, &profile, request.rate_hz);
        let found = breaches(&samples, limits);
        let Some(first) = found.first() else {
            let duration_s = samples[samples.len() - 1].time_s();
            let tool_speed_share = tool_speed_share(&states, &grid, &tool_gain, request);
            return Ok(TimedMotion {
                definition: MotionDefinition::Splines {
                    start: samples[0].q,
                    stretches: vec![SplineStretch {
                        spline: spline.clone(),
                        profile: definition,
                    }],
                },
                samples,
                grid_s,
                report: TimingReport {
                    duration_s,
                    time_optimal_s,
                    tool_speed_share,
                    path_travel_m: length,
                    refined_knots: path.refined_knots,
                    cut,
                    grid_points: grid.len(),
                    slowdowns,
                    rests_s: Vec::new(),
                },
                paths: vec![path],
            });
        };
        if slowdowns == MAX_SLOWDOWNS {
            return Err(StretchError::Unmet(Unmet {
                breach: first.clone(),
                at: samples[first.sample].q,
                between: (0, waypoints.len() - 1),
            }));
        }
        slow_down(
            &mut factor,
            &grid,
            &profile,
            &samples,
            &found,
            request.rate_hz,
        );
    }
    unreachable!("the loop returns by its last round")
}

/// The speed profile planned over `grid` (its parameters `grid_s`) in a round of local
/// slow-downs: TOPP-RA within [`ACCELERATION_MARGIN`] of the acceleration limits, each grid
/// point's bound lowered by its `factor`, averaged over `window_s`.
pub(crate) fn planned_profile(
    grid: &[GridPoint],
    grid_s: &[f64],
    limits: &DynamicLimits,
    factor: &[f64],
    window_s: f64,
) -> ProfileGrid {
    ProfileGrid {
        s: grid_s.to_vec(),
        x: topp_ra(grid, &(limits.acceleration * ACCELERATION_MARGIN), factor),
        window_s,
    }
}

/// Lowers `factor` by [`SLOWDOWN`] on the stretches of path that the windows of the samples
/// `found` breaching a limit cover (the profile's averaging window and three samples to each
/// side), once per round however many breaches cover a grid point.
pub(crate) fn slow_down(
    factor: &mut [f64],
    grid: &[GridPoint],
    profile: &SmoothedProfile,
    samples: &[TimedSample],
    found: &[LimitBreach],
    rate_hz: f64,
) {
    let margin = 2.0 * profile.window() + 3.0 / rate_hz;
    let mut lowered = vec![false; grid.len()];
    for breach in found {
        let t = samples[breach.sample].time_s();
        let from = profile.state(t - margin).s;
        let to = profile.state(t + margin).s;
        let first = grid.partition_point(|g| g.s < from).saturating_sub(2);
        let last = (grid.partition_point(|g| g.s <= to) + 2).min(grid.len());
        lowered[first..last].fill(true);
    }
    for (f, lowered) in factor.iter_mut().zip(lowered) {
        if lowered {
            *f *= SLOWDOWN;
        }
    }
}

/// Share of the sampling intervals in which the tool speed `|p'(s)| ṡ` (with `|p'|`
/// interpolated between grid points) is at least [`AT_TOOL_SPEED`] × the requested speed.
fn tool_speed_share(
    states: &[PathState],
    grid: &[GridPoint],
    tool_gain: &[f64],
    request: &TimingRequest,
) -> f64 {
    let fast = states
        .iter()
        .filter(|state| {
            let i = grid
                .partition_point(|g| g.s <= state.s)
                .clamp(1, grid.len() - 1);
            let w = (state.s - grid[i - 1].s) / (grid[i].s - grid[i - 1].s);
            let gain = tool_gain[i - 1] + (tool_gain[i] - tool_gain[i - 1]) * w;
            gain * state.sd >= AT_TOOL_SPEED * request.tool_speed_m_per_s
        })
        .count();
    fast as f64 / states.len() as f64
}
