//! The place stage: where to put the part, or the robot's base, so that the job reaches
//! furthest. A place is the part shifted in its surface's plane and turned about its normal, or
//! the base shifted on its mount and turned about its vertical axis ([`Place`], in the
//! [`PlaceFrame`], [`Moving`]); the places of a [`Region`] are
//!
//! 1. **screened** on a coarse grid by a cheap score: the reachability bound of every stroke
//!    (the part under the strokes kept off, as the job plans; in the shortest order the sum
//!    of its two ways' bounds, as the job draws a short stroke from both ends, for a closed
//!    one the better of its start and [`reachable_start_s`]), and between them the points
//!    with a configuration, a grid step each (the job's searches skip ahead to where a motion
//!    starts again), Σ min(bound, length) / Σ length, from a coarse scan
//!    ([`PlaceSettings::coarse_grid_m`], fewer restarts);
//! 2. **refined**: the best [`PlaceSettings::refine`] of them, and the places half a grid step
//!    round the best one, scored again by the full scan;
//! 3. **certified**: the best [`PlaceSettings::certify`] planned as full jobs ([`plan_job`]),
//!    then the next ones while a place's score exceeds the share drawn at the best planned place
//!    (the score bounds the share drawn: no refined place left unplanned could draw more), and
//!    ranked by pen-down length drawn, then by the program's duration.
//!
//! Every score and plan is deterministic and independent of the number of threads; ties keep
//! the grid's order.

use emg_control::{ConstraintConfig, Path, Task};
use emg_kinematics::{Vec3, rotation_about};
use emg_planner::{MotionTiming, PlanRequest, Planner, ReachConfig, reach, reachable_points};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::free_space::{job_part, with_part};
use crate::measures::SAME_LENGTH_M;
use crate::pipeline::plan_job;
use crate::plan_error::JobPlanError;
use crate::program::JobFile;
use crate::spec::{Job, JobError, Order, Transform};
use crate::stroke::reachable_start_s;
use crate::watch::{Stopped, StopsWith, Watch};

/// The step scores are ranked in: within one, the place deeper inside the arm's reach goes
/// first.
pub const SAME_SCORE: f64 = 1e-3;

/// How far a refined place's score must exceed the share drawn at the best planned place for
/// the place to be planned too, past the first [`PlaceSettings::certify`]: one ranking step.
const SCORE_MARGIN: f64 = SAME_SCORE;

/// What a placement moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Moving {
    /// The part, with the strokes on it: shifted on its surface, turned about its normal through
    /// the strokes' centre. The cell stays.
    #[default]
    Part,
    /// The robot's base on its mount: shifted along the base's x and y, turned about its z axis
    /// through its origin. The part and the cell stay, so in the base's frame both move back.
    Base,
}

/// The places searched: the shift along the [`PlaceFrame`]'s axes (m), its normal included, and
/// the turn about its normal (degrees), each a closed range `[low, high]`, of the part or the
/// base.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    /// What moves.
    #[serde(default)]
    pub moving: Moving,
    /// Shift along the frame's x axis (m).
    pub x_m: [f64; 2],
    /// Shift along the frame's y axis (m).
    pub y_m: [f64; 2],
    /// Shift along the frame's normal, toward the tool's side (m); [`Region::DEFAULT_Z_M`] where
    /// absent.
    #[serde(default = "Region::default_z_m")]
    pub z_m: [f64; 2],
    /// Turn about the normal (degrees, counter-clockwise seen from the tool's side).
    pub rotation_deg: [f64; 2],
}

/// How densely the places are searched.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlaceSettings {
    /// Grid positions along each of x and y.
    pub positions: usize,
    /// Grid heights along the normal.
    pub heights: usize,
    /// Grid turns.
    pub rotations: usize,
    /// Best screened places scored again by the full scan.
    pub refine: usize,
    /// Best refined places planned as full jobs at least; the next ones are planned too while
    /// a place's score exceeds the share drawn at the best planned so far (by more than
    /// [`SAME_SCORE`]), so no refined place left unplanned scores above what the chosen one
    /// draws.
    pub certify: usize,
    /// Grid spacing of the screening's scan along each stroke (m).
    pub coarse_grid_m: f64,
    /// Random IK restarts of the screening's scan where warm starts fail.
    pub coarse_restarts: usize,
}

impl Default for PlaceSettings {
    /// 10 × 10 positions × 3 heights × 5 turns (1,500 places), the best 20 refined, the best 5
    /// certified; the screening scans every 2 cm with 8 restarts.
    fn default() -> Self {
        Self {
            positions: 10,
            heights: 3,
            rotations: 5,
            refine: 20,
            certify: 5,
            coarse_grid_m: 0.02,
            coarse_restarts: 8,
        }
    }
}

/// Why no place can be chosen.
#[derive(Debug, thiserror::Error)]
pub enum PlaceError {
    /// A range of the region is empty or not finite.
    #[error(
        "region field '{field}' must be a finite range [low, high] with low ≤ high, got {value:?}"
    )]
    Region {
        /// The field.
        field: &'static str,
        /// Its value.
        value: [f64; 2],
    },
    /// A setting is out of range.
    #[error("placement setting '{field}' must be {allowed}, got {value}")]
    Setting {
        /// The field.
        field: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range.
        allowed: &'static str,
    },
    /// A place moves a stroke into an invalid path.
    #[error(transparent)]
    Job(#[from] JobError),
    /// The watcher asked the placement to stop.
    #[error(transparent)]
    Stopped(#[from] Stopped),
    /// No place of the region lets the arm reach any stroke.
    #[error(
        "no place of the region lets the arm reach any of the job's strokes (the best screened \
         score is 0): move the region nearer the arm"
    )]
    Unreachable,
    /// No certified place draws anything.
    #[error("no certified place draws anything: {0}")]
    NothingDrawn(JobPlanError),
}

/// The frame places are measured in. Moving the part: the centre of the strokes' points, the
/// surface normal pointing to the tool's side (−n of the first stroke), x the base's x axis laid
/// on the surface (its y axis where x stands along the normal), y = normal × x. Moving the base:
/// the base's own origin and axes (normal z).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlaceFrame {
    /// What moves.
    pub moving: Moving,
    /// Centre of the strokes' points (m).
    pub centre: [f64; 3],
    /// Unit normal toward the tool.
    pub normal: [f64; 3],
    /// Unit x axis on the surface.
    pub x: [f64; 3],
    /// Unit y axis on the surface.
    pub y: [f64; 3],
}

impl PlaceFrame {
    /// The frame of `job`'s part, or of the base, as `moving` says.
    pub fn of(job: &Job, moving: Moving) -> Self {
        if moving == Moving::Base {
            return Self {
                moving,
                centre: [0.0; 3],
                normal: Vec3::z().into(),
                x: Vec3::x().into(),
                y: Vec3::y().into(),
            };
        }
        let points: Vec<Vec3> = job
            .strokes
            .iter()
            .flat_map(|path| {
                let samples = (path.length_m() / 0.01).ceil().max(1.0) as usize;
                (0..=samples)
                    .map(move |k| path.point_at(path.length_m() * k as f64 / samples as f64))
            })
            .collect();
        let centre = points.iter().sum::<Vec3>() / points.len().max(1) as f64;
        let normal = -job.strokes[0].normal();
        let on_surface = |axis: Vec3| axis - normal * axis.dot(&normal);
        let x = [Vec3::x(), Vec3::y()]
            .into_iter()
            .map(on_surface)
            .find(|x| x.norm() > 0.1)
            .unwrap_or_else(|| on_surface(Vec3::z()))
            .normalize();
        Self {
            moving,
            centre: centre.into(),
            normal: normal.into(),
            x: x.into(),
            y: normal.cross(&x).into(),
        }
    }

    /// The motion of the job and of the cell in the base's frame at `place`: the part's
    /// [`PlaceFrame::motion`] moving the part (the cell stays), its inverse moving the base;
    /// rounded through the [`Transform`] a file writes, so that a job (and a scene) read back
    /// with the exported transform is bit for bit the one planned.
    pub fn job_motion(&self, place: &Place) -> Isometry3<f64> {
        let motion = match self.moving {
            Moving::Part => self.motion(place),
            Moving::Base => self.motion(place).inverse(),
        };
        Transform::of(&motion).isometry()
    }

    /// The rigid motion that puts what moves at `place`: turned about the normal through the
    /// centre, then shifted along x, y and the normal.
    pub fn motion(&self, place: &Place) -> Isometry3<f64> {
        let centre = Vec3::from(self.centre);
        let turn = UnitQuaternion::from_rotation_matrix(&rotation_about(
            &Vec3::from(self.normal),
            place.rotation_deg.to_radians(),
        ));
        let shift = Vec3::from(self.x) * place.x_m
            + Vec3::from(self.y) * place.y_m
            + Vec3::from(self.normal) * place.z_m;
        Isometry3::from_parts(Translation3::from(centre + shift - turn * centre), turn)
    }
}

/// One place of the part: its shift along the frame's axes (m) and its turn (degrees).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Place {
    /// Shift along x (m).
    pub x_m: f64,
    /// Shift along y (m).
    pub y_m: f64,
    /// Shift along the normal, toward the tool's side (m).
    #[serde(default)]
    pub z_m: f64,
    /// Turn about the normal (degrees).
    pub rotation_deg: f64,
}

/// A place and its score: Σ min(bound, length) / Σ length over the strokes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scored {
    /// The place.
    pub place: Place,
    /// Its score in [0, 1].
    pub score: f64,
    /// How deep inside the sphere the arm reaches the strokes lie: the smallest distance of
    /// their points from its surface (m), which breaks ties between equal scores (a bound
    /// reads full well before the arm's reach ends).
    pub depth_m: f64,
}

/// A place planned as a full job.
#[derive(Clone, Debug, Serialize)]
pub struct Certified {
    /// The place and its refined score.
    pub scored: Scored,
    /// Pen-down length drawn (m), 0 where nothing could be drawn.
    pub drawn_m: f64,
    /// Pen-down length in all (m).
    pub total_m: f64,
    /// Strokes drawn whole.
    pub complete: usize,
    /// Strokes.
    pub strokes: usize,
    /// The program's duration (s).
    pub duration_s: f64,
    /// The program, where one was planned.
    #[serde(skip)]
    pub program: Option<Box<JobFile>>,
}

impl Certified {
    /// The certificate of `scored`'s place, where the job moved there (`moved`) was planned as
    /// `program` (`None` where it could not be).
    fn of(scored: Scored, moved: &Job, program: Option<JobFile>) -> Self {
        Self {
            scored,
            drawn_m: program.as_ref().map_or(0.0, |p| p.summary.drawn_m),
            total_m: moved.strokes.iter().map(|s| s.length_m()).sum(),
            complete: program.as_ref().map_or(0, |p| p.summary.complete),
            strokes: moved.strokes.len(),
            duration_s: program.as_ref().map_or(0.0, |p| p.summary.duration_s),
            program: program.map(Box::new),
        }
    }
}

/// What the place stage found.
#[derive(Clone, Debug, Serialize)]
pub struct Placement {
    /// The frame places are measured in.
    pub frame: PlaceFrame,
    /// The region searched.
    pub region: Region,
    /// Every screened place, in grid order (x slowest, then y, then the turn).
    pub screened: Vec<Scored>,
    /// The refined places, best first.
    pub refined: Vec<Scored>,
    /// The certified places, best first: the chosen place is the first.
    pub certified: Vec<Certified>,
    /// Wall time of the screening on this machine (s): reported, never decided on.
    pub screening_s: f64,
}

impl Placement {
    /// The chosen place.
    pub fn best(&self) -> &Certified {
        &self.certified[0]
    }

    /// The chosen place as the transform a job file (and, moving the base, a scene file)
    /// takes: the motion of the job and the cell in the base's frame.
    pub fn transform(&self) -> Transform {
        Transform::of(&self.frame.job_motion(&self.best().scored.place))
    }

    /// Moving the base: where the chosen place puts it, in its present frame.
    pub fn base_pose(&self) -> Option<Transform> {
        (self.frame.moving == Moving::Base)
            .then(|| Transform::of(&self.frame.motion(&self.best().scored.place)))
    }
}

/// The places of the region's grid: `count` values spread evenly over `[low, high]` (the middle
/// where `count` is 1 or the range a point). Each is the weighted mean
/// `(low (n - 1 - k) + high k) / (n - 1)`, so the ends and a middle between opposite ends come
/// out exact (`0`, not a rounding residue of `low + (high - low) k / (n - 1)`).
fn spread(range: [f64; 2], count: usize) -> Vec<f64> {
    if count <= 1 || range[0] == range[1] {
        return vec![0.5 * (range[0] + range[1])];
    }
    let [low, high] = range;
    let steps = (count - 1) as f64;
    (0..count)
        .map(|k| (low * (steps - k as f64) + high * k as f64) / steps)
        .collect()
}

/// An end of one of the region's ranges that a place lies on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegionEdge {
    /// The range: `x`, `y`, `z` or `rotation` (as the options name them).
    pub range: &'static str,
    /// Whether the place lies at its maximum (else its minimum).
    pub at_maximum: bool,
    /// The end's value (m, or degrees for the turn).
    pub value: f64,
}

impl Region {
    /// The shifts along the normal searched unless a region says (m): 3 cm either side, where a
    /// part lowered or raised a little may draw more.
    pub const DEFAULT_Z_M: [f64; 2] = [-0.03, 0.03];

    fn default_z_m() -> [f64; 2] {
        Self::DEFAULT_Z_M
    }

    /// The ends of the region's ranges that `place` lies on: of each range wider than a point
    /// (and, for the turn, narrower than a whole turn, which has no end), its minimum or
    /// maximum where the place's value is it. A chosen place there may draw more past it.
    pub fn edges_of(&self, place: &Place) -> Vec<RegionEdge> {
        [
            ("x", self.x_m, place.x_m),
            ("y", self.y_m, place.y_m),
            ("z", self.z_m, place.z_m),
            ("rotation", self.rotation_deg, place.rotation_deg),
        ]
        .into_iter()
        .filter(|&(range, [low, high], _)| {
            low < high && (range != "rotation" || high - low < 360.0)
        })
        .filter_map(|(range, [low, high], value)| {
            let at = |end: f64| (value - end).abs() <= 1e-9 * (1.0 + end.abs());
            let edge = |at_maximum, value| RegionEdge {
                range,
                at_maximum,
                value,
            };
            match (at(low), at(high)) {
                (true, _) => Some(edge(false, low)),
                (_, true) => Some(edge(true, high)),
                _ => None,
            }
        })
        .collect()
    }

    /// Checks every range.
    pub fn validate(&self) -> Result<(), PlaceError> {
        for (field, value) in [
            ("x_m", self.x_m),
            ("y_m", self.y_m),
            ("z_m", self.z_m),
            ("rotation_deg", self.rotation_deg),
        ] {
            if !(value[0].is_finite() && value[1].is_finite() && value[0] <= value[1]) {
                return Err(PlaceError::Region { field, value });
            }
        }
        Ok(())
    }
}

impl PlaceSettings {
    /// Checks every setting.
    pub fn validate(&self) -> Result<(), PlaceError> {
        let require = |field, value: f64, allowed, ok: bool| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(PlaceError::Setting {
                    field,
                    value,
                    allowed,
                })
            }
        };
        for (field, value) in [
            ("positions", self.positions),
            ("heights", self.heights),
            ("rotations", self.rotations),
            ("refine", self.refine),
            ("certify", self.certify),
        ] {
            require(
                field,
                value as f64,
                "in [1, 1000]",
                (1..=1000).contains(&value),
            )?;
        }
        require(
            "coarse_grid_m",
            self.coarse_grid_m,
            "in [0.001, 0.2] m",
            (0.001..=0.2).contains(&self.coarse_grid_m),
        )?;
        require(
            "coarse_restarts",
            self.coarse_restarts as f64,
            "in [0, 10000]",
            self.coarse_restarts <= 10_000,
        )
    }
}

/// What a place is scored by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Score {
    /// The reachability bound of each stroke: how far along it one motion could go.
    Bound,
    /// The share of the strokes' points that have an IK solution in the cone, each on its own:
    /// what reachability studies score.
    PointIk,
}

/// The score of `job` moved to `place` by `planner`'s constraints with the part under its
/// strokes, each stroke scanned with `config`: Σ min(bound, length) / Σ length
/// ([`Score::Bound`]) or the share of scanned points with a configuration ([`Score::PointIk`]).
pub fn place_score(
    planner: &Planner,
    job: &Job,
    frame: &PlaceFrame,
    place: &Place,
    config: &ReachConfig,
    score: Score,
) -> Result<Scored, JobError> {
    let robot = planner.robot();
    let motion = frame.job_motion(place);
    let moved = job.moved(&motion)?;
    let (centre, radius) = robot.reach_sphere();
    let depth_m = moved
        .strokes
        .iter()
        .flat_map(|path| {
            let samples = (path.length_m() / 0.01).ceil().max(1.0) as usize;
            (0..=samples).map(move |k| path.point_at(path.length_m() * k as f64 / samples as f64))
        })
        .map(|point| radius - (point - centre).norm())
        .fold(f64::INFINITY, f64::min);
    let constraints = with_part(
        &cell_at(&planner.config().rollout.constraints, frame, &motion),
        &job_part(robot, &moved),
    );
    let (mut reached, mut total) = (0.0, 0.0);
    for stroke in &moved.strokes {
        let Ok(task) = Task::on_path(robot, stroke.clone(), None) else {
            total += stroke.length_m();
            continue;
        };
        match score {
            Score::Bound => {
                let bound_of = |path: &Path| {
                    Task::on_path(robot, path.clone(), None).map_or(0.0, |task| {
                        reach(robot, &task, &constraints, config, &[]).reachable_m
                    })
                };
                // The points of a stretch with a configuration, a grid step each: no motion
                // draws more of it.
                let points_m = |path: &Path| {
                    Task::on_path(robot, path.clone(), None).map_or(0.0, |task| {
                        let (found, _) = reachable_points(robot, &task, &constraints, config);
                        (found as f64 * config.grid_m).min(path.length_m())
                    })
                };
                // The job draws what one motion from the start reaches; in the shortest order
                // also what one from the end reaches, and a closed stroke may be started where
                // the arm reaches it (`plan_job`); between them its searches skip ahead to
                // where a motion starts again (`plan_stroke`), which draws at most the points
                // there with a configuration.
                let shortest = moved.settings.order == Order::Shortest;
                let drawable = |path: &Path, forward: f64| {
                    let length = path.length_m();
                    if forward >= length {
                        return forward;
                    }
                    let backward = if shortest {
                        path.reversed().map_or(0.0, |reversed| bound_of(&reversed))
                    } else {
                        0.0
                    };
                    let between = path
                        .stretch(forward, length - backward)
                        .map_or(0.0, |middle| points_m(&middle));
                    forward + backward + between
                };
                let forward = reach(robot, &task, &constraints, config, &[]).reachable_m;
                let mut bound = drawable(stroke, forward);
                if bound < stroke.length_m() && shortest {
                    let restarted = stroke.started_at(reachable_start_s(stroke, robot));
                    if let Some(restarted) = restarted {
                        bound = bound.max(drawable(&restarted, bound_of(&restarted)));
                    }
                }
                reached += bound.min(stroke.length_m());
                total += stroke.length_m();
            }
            Score::PointIk => {
                let (found, points) = reachable_points(robot, &task, &constraints, config);
                reached += found as f64;
                total += points as f64;
            }
        }
    }
    Ok(Scored {
        place: *place,
        score: if total > 0.0 { reached / total } else { 0.0 },
        depth_m,
    })
}

/// The places of `region` for `job`, screened, refined and certified as the module says, by
/// `score`; `watch` is told each stage's progress ("screen", "refine" and "certify", in places)
/// and asked between places whether to stop ([`PlaceError::Stopped`]).
#[allow(clippy::too_many_arguments)]
pub fn place_job(
    planner: &Planner,
    request: &PlanRequest,
    job: &Job,
    timing: &MotionTiming,
    robot_file: &str,
    region: &Region,
    settings: &PlaceSettings,
    score: Score,
    watch: &dyn Watch,
) -> Result<Placement, PlaceError> {
    region.validate()?;
    settings.validate()?;
    let search = PlaceSearch {
        planner,
        request,
        job,
        timing,
        robot_file,
        frame: PlaceFrame::of(job, region.moving),
        score,
        watch,
    };
    let axes = PlaceAxes::of(region, settings);
    let full = planner.config().reach.clone();
    let coarse = ReachConfig {
        grid_m: settings.coarse_grid_m.max(full.grid_m),
        restarts: settings.coarse_restarts.min(full.restarts),
        ..full.clone()
    };
    let started = std::time::Instant::now();
    let screened = search.scored("screen", &axes.places(), &coarse)?;
    let screening_s = started.elapsed().as_secs_f64();
    let ranked = best_first(&screened);
    if ranked[0].score <= 0.0 {
        return Err(PlaceError::Unreachable);
    }
    // The best screened places, and the places half a step round the best one.
    let mut refine: Vec<Place> = ranked
        .iter()
        .take(settings.refine)
        .map(|s| s.place)
        .collect();
    for near in axes.round(&ranked[0].place, region) {
        if !refine.contains(&near) {
            refine.push(near);
        }
    }
    let refined = best_first(&search.scored("refine", &refine, &full)?);
    let certified = search.certified(&refined, settings.certify)?;
    Ok(Placement {
        frame: search.frame,
        region: *region,
        screened,
        refined,
        certified,
        screening_s,
    })
}

/// The values a placement tries along each of its region's ranges.
struct PlaceAxes {
    x_m: Vec<f64>,
    y_m: Vec<f64>,
    z_m: Vec<f64>,
    rotation_deg: Vec<f64>,
}

impl PlaceAxes {
    /// `settings`' counts of values spread evenly over each of `region`'s ranges.
    fn of(region: &Region, settings: &PlaceSettings) -> Self {
        Self {
            x_m: spread(region.x_m, settings.positions),
            y_m: spread(region.y_m, settings.positions),
            z_m: spread(region.z_m, settings.heights),
            rotation_deg: spread(region.rotation_deg, settings.rotations),
        }
    }

    /// Every combination of the values, x outermost, the turn innermost.
    fn places(&self) -> Vec<Place> {
        let mut grid = Vec::with_capacity(
            self.x_m.len() * self.y_m.len() * self.z_m.len() * self.rotation_deg.len(),
        );
        for &x_m in &self.x_m {
            for &y_m in &self.y_m {
                for &z_m in &self.z_m {
                    for &rotation_deg in &self.rotation_deg {
                        grid.push(Place {
                            x_m,
                            y_m,
                            z_m,
                            rotation_deg,
                        });
                    }
                }
            }
        }
        grid
    }

    /// The places half a step of each range round `top` (itself among them), within `region`.
    fn round(&self, top: &Place, region: &Region) -> Vec<Place> {
        let step = |values: &[f64]| match values {
            [a, b, ..] => 0.5 * (b - a),
            _ => 0.0,
        };
        let near = |delta: f64, values: &[f64], value: f64, range: [f64; 2]| {
            (value + delta * step(values)).clamp(range[0], range[1])
        };
        let deltas = [-1.0, 0.0, 1.0];
        let mut places = Vec::with_capacity(81);
        for dx in deltas {
            for dy in deltas {
                for dz in deltas {
                    for dr in deltas {
                        places.push(Place {
                            x_m: near(dx, &self.x_m, top.x_m, region.x_m),
                            y_m: near(dy, &self.y_m, top.y_m, region.y_m),
                            z_m: near(dz, &self.z_m, top.z_m, region.z_m),
                            rotation_deg: near(
                                dr,
                                &self.rotation_deg,
                                top.rotation_deg,
                                region.rotation_deg,
                            ),
                        });
                    }
                }
            }
        }
        places
    }
}

/// A placement's search: the job, how it is planned at a place, and how places are scored.
struct PlaceSearch<'a> {
    planner: &'a Planner,
    request: &'a PlanRequest,
    job: &'a Job,
    timing: &'a MotionTiming,
    robot_file: &'a str,
    frame: PlaceFrame,
    score: Score,
    watch: &'a dyn Watch,
}

impl PlaceSearch<'_> {
    /// `places` scored ([`place_score`]) with `config`, in parallel; `watch` told the
    /// progress as `stage` and asked whether to stop.
    fn scored(
        &self,
        stage: &str,
        places: &[Place],
        config: &ReachConfig,
    ) -> Result<Vec<Scored>, PlaceError> {
        let done = std::sync::atomic::AtomicUsize::new(0);
        places
            .par_iter()
            .map(|place| {
                if self.watch.stop_requested() {
                    return Err(PlaceError::Stopped(Stopped));
                }
                let scored = place_score(
                    self.planner,
                    self.job,
                    &self.frame,
                    place,
                    config,
                    self.score,
                )?;
                let finished = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                self.watch.progress(stage, finished, places.len());
                Ok(scored)
            })
            .collect()
    }

    /// The `refined` places, best first, planned as jobs: the first `certify`, then more while
    /// a place's score (at least the share the job draws there, `crates/job/tests/place.rs`)
    /// could beat the most drawn; ranked most drawn first (counted in steps of
    /// [`SAME_LENGTH_M`]), then the shortest program, ties in the refined order.
    fn certified(&self, refined: &[Scored], certify: usize) -> Result<Vec<Certified>, PlaceError> {
        let mut certified: Vec<Certified> = Vec::new();
        let mut first_failure = None;
        for (index, candidate) in refined.iter().enumerate() {
            let most_drawn = certified
                .iter()
                .map(|c| c.drawn_m / c.total_m.max(f64::MIN_POSITIVE))
                .fold(0.0, f64::max);
            if index >= certify && candidate.score <= most_drawn + SCORE_MARGIN {
                break;
            }
            let (planned, moved) = self.planned_at(candidate)?;
            self.watch
                .progress("certify", index + 1, certify.max(index + 1));
            let program = match planned {
                Ok(program) => Some(program),
                Err(why) => {
                    first_failure.get_or_insert(why);
                    None
                }
            };
            certified.push(Certified::of(*candidate, &moved, program));
        }
        let steps = |c: &Certified| (c.drawn_m / SAME_LENGTH_M).round();
        certified.sort_by(|a, b| {
            steps(b)
                .total_cmp(&steps(a))
                .then(a.duration_s.total_cmp(&b.duration_s))
        });
        if certified[0].program.is_none() {
            return Err(PlaceError::NothingDrawn(
                first_failure.expect("a place without a program failed to plan"),
            ));
        }
        Ok(certified)
    }

    /// The job moved to `candidate`'s place, and planned there ([`plan_job`], with the cell
    /// moved along); [`PlaceError::Stopped`] where the watcher stopped it.
    fn planned_at(
        &self,
        candidate: &Scored,
    ) -> Result<(Result<JobFile, JobPlanError>, Job), PlaceError> {
        let motion = self.frame.job_motion(&candidate.place);
        let moved = self.job.moved(&motion)?;
        let mut config = self.planner.config().clone();
        config.rollout.constraints = cell_at(&config.rollout.constraints, &self.frame, &motion);
        let at_place = self
            .planner
            .with_config(config)
            .expect("the planner's configuration with its cell moved is valid");
        let planned = plan_job(
            &at_place,
            self.request,
            &moved,
            self.timing,
            self.robot_file,
            &StopsWith(self.watch),
        );
        if let Err(JobPlanError::Stopped(stopped)) = planned {
            return Err(stopped.into());
        }
        Ok((planned, moved))
    }
}

/// `constraints` with the cell where the place puts it relative to the base: moved by `motion`
/// when the base moves, as they are when the part does.
fn cell_at(
    constraints: &ConstraintConfig,
    frame: &PlaceFrame,
    motion: &Isometry3<f64>,
) -> ConstraintConfig {
    match frame.moving {
        Moving::Part => constraints.clone(),
        Moving::Base => ConstraintConfig {
            scene: constraints.scene.moved(motion),
            ..constraints.clone()
        },
    }
}

/// `scored` best first: by score (in steps of [`SAME_SCORE`]), then deeper inside the arm's
/// reach; equal ones keep their order.
fn best_first(scored: &[Scored]) -> Vec<Scored> {
    let steps = |s: &Scored| (s.score / SAME_SCORE).round();
    let mut ranked = scored.to_vec();
    ranked.sort_by(|a, b| {
        steps(b)
            .total_cmp(&steps(a))
            .then(b.depth_m.total_cmp(&a.depth_m))
    });
    ranked
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_place_on_a_ranges_end_is_named_with_that_end() {
        let region = Region {
            moving: Moving::Part,
            x_m: [-0.1, 0.1],
            y_m: [0.0, 0.0],
            z_m: [-0.03, 0.03],
            rotation_deg: [-180.0, 180.0],
        };
        let place = |x_m, y_m, rotation_deg| Place {
            x_m,
            y_m,
            z_m: 0.0,
            rotation_deg,
        };
        // A point range and a whole turn have no end; the middle of a range is no end.
        assert!(region.edges_of(&place(0.0, 0.0, 180.0)).is_empty());
        assert_eq!(
            region.edges_of(&place(0.1, 0.0, 0.0)),
            vec![RegionEdge {
                range: "x",
                at_maximum: true,
                value: 0.1
            }]
        );
        let turned = Region {
            rotation_deg: [-30.0, 30.0],
            ..region
        };
        let edges = turned.edges_of(&place(-0.1, 0.0, -30.0));
        assert_eq!(edges.len(), 2);
        assert!(
            !edges[0].at_maximum && edges[1].range == "rotation",
            "{edges:?}"
        );
    }
}
