//! The data blob a page animates: world-frame geometry of every recorded step. The pieces both
//! pages draw (the arm's pose and capsules, the cell's solids, a sampled path, rounding) are
//! defined here once; [`Scene`] is the motion page's whole input, [`crate::job`] the job page's.

use emg_control::{ActingController, Path, StepRecord};
use emg_kinematics::{JointVector, MAX_DOF, Robot, Shape, Vec3, WorkSurface};
use serde::Serialize;

use crate::input::ViewerInput;

/// Metres (and unit-vector components) are written to 10 µm: far below a pixel, and it keeps the
/// page small.
const LENGTH_SCALE: f64 = 1e5;
/// Seconds are written to 1 µs.
const TIME_SCALE: f64 = 1e6;
/// Degrees and `ρ` are written to 1e-4.
const VALUE_SCALE: f64 = 1e4;

/// The motion page's whole input, serialised as JSON.
#[derive(Debug, Serialize)]
pub(crate) struct Scene<'a> {
    title: &'a str,
    robot: &'a str,
    task: SceneTask,
    constraints: SceneConstraints,
    obstacles: Vec<SceneObstacle<'a>>,
    capsules: Vec<SceneCapsule<'a>>,
    path_length_m: f64,
    termination: String,
    steps: Vec<SceneStep>,
}

#[derive(Debug, Serialize)]
struct SceneTask {
    p0: [f64; 3],
    d: [f64; 3],
    n: [f64; 3],
    /// A path task's path, sampled; absent for a line.
    #[serde(skip_serializing_if = "Option::is_none")]
    path: Option<ScenePath>,
}

/// A path as the page draws it: points at the arc lengths `s` (every piece's ends, and along an
/// arc every [`PATH_SAMPLE_M`] or [`PATH_SAMPLE_RAD`] of turn, whichever is shorter; a straight
/// piece needs only its ends), with the unit direction across it in the surface (`n × t`) at
/// each. The page interpolates between them by arc length.
#[derive(Debug, Serialize)]
pub(crate) struct ScenePath {
    pub(crate) length_m: f64,
    pub(crate) s: Vec<f64>,
    pub(crate) points: Vec<[f64; 3]>,
    pub(crate) sides: Vec<[f64; 3]>,
}

/// Longest arc length (m) between the samples of an arc the page draws.
pub(crate) const PATH_SAMPLE_M: f64 = 0.005;
/// Largest turn (rad) between the samples of an arc the page draws: 5°, a chord within 0.1 % of
/// the radius.
pub(crate) const PATH_SAMPLE_RAD: f64 = 5.0 * std::f64::consts::PI / 180.0;

impl ScenePath {
    /// `path` sampled for the page.
    pub(crate) fn new(path: &Path) -> Self {
        let mut s = vec![0.0];
        for piece in path.pieces() {
            let (start, _, arc) = piece.outline();
            let step = match arc {
                None => f64::INFINITY,
                Some((centre, _)) => PATH_SAMPLE_M.min((start - centre).norm() * PATH_SAMPLE_RAD),
            };
            let count = (piece.length_m / step).ceil().max(1.0) as usize;
            s.extend((1..=count).map(|k| piece.start_s + piece.length_m * k as f64 / count as f64));
        }
        let normal = path.normal();
        Self {
            length_m: length(path.length_m()),
            points: s.iter().map(|&s| point(&path.point_at(s))).collect(),
            sides: s
                .iter()
                .map(|&s| point(&normal.cross(&path.tangent_at(s))))
                .collect(),
            s: s.into_iter().map(length).collect(),
        }
    }
}

/// The limits drawn: the line tolerance, the tool cone, and whether the work surface is the
/// half-space behind the task's plane (drawn around the line; a work plate is an obstacle,
/// [`SceneObstacle::surface`]).
#[derive(Debug, Serialize)]
pub(crate) struct SceneConstraints {
    pub(crate) line_tolerance_m: f64,
    pub(crate) theta_max_deg: f64,
    pub(crate) work_surface: bool,
}

/// One obstacle of the cell, in world coordinates.
#[derive(Debug, Serialize)]
pub(crate) struct SceneObstacle<'a> {
    name: &'a str,
    clearance_m: f64,
    /// A work surface ([`emg_control::WORK_SURFACE`]): the part only the pen may touch, drawn
    /// in the surface's colours.
    surface: bool,
    #[serde(flatten)]
    solid: SceneSolid,
}

/// The cell's solids: the work surfaces `surfaces` (named [`emg_control::WORK_SURFACE`]) and
/// then the scene's obstacles.
pub(crate) fn cell<'a>(
    surfaces: impl IntoIterator<Item = Shape>,
    scene: &'a emg_kinematics::Scene,
) -> Vec<SceneObstacle<'a>> {
    surfaces
        .into_iter()
        .map(|shape| SceneObstacle {
            name: emg_control::WORK_SURFACE,
            clearance_m: 0.0,
            surface: true,
            solid: SceneSolid::new(&shape),
        })
        .chain(scene.obstacles.iter().map(|obstacle| SceneObstacle {
            name: &obstacle.name,
            clearance_m: length(obstacle.clearance_m),
            surface: false,
            solid: SceneSolid::new(&obstacle.shape),
        }))
        .collect()
}

/// An obstacle's solid as the page draws it.
#[derive(Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
enum SceneSolid {
    /// The solid behind the plane through `point`; `normal` points into free space.
    HalfSpace { point: [f64; 3], normal: [f64; 3] },
    /// The eight corners, corner `i` at `+` half extent along box axis `k` where bit `k` of `i`
    /// is set.
    Box { corners: Vec<[f64; 3]> },
    /// A ball.
    Sphere { centre: [f64; 3], radius: f64 },
    /// A capsule.
    Capsule {
        start: [f64; 3],
        end: [f64; 3],
        radius: f64,
    },
}

impl SceneSolid {
    fn new(shape: &Shape) -> Self {
        match shape {
            Shape::HalfSpace { point: p, normal } => Self::HalfSpace {
                point: point(p),
                normal: point(normal),
            },
            Shape::Cuboid {
                centre,
                rotation,
                half_extents,
            } => Self::Box {
                corners: (0..8)
                    .map(|i| {
                        let sign = |k: usize| if i & (1 << k) != 0 { 1.0 } else { -1.0 };
                        let local = Vec3::new(
                            sign(0) * half_extents.x,
                            sign(1) * half_extents.y,
                            sign(2) * half_extents.z,
                        );
                        point(&(centre + rotation * local))
                    })
                    .collect(),
            },
            Shape::Sphere { centre, radius } => Self::Sphere {
                centre: point(centre),
                radius: length(*radius),
            },
            Shape::Capsule { start, end, radius } => Self::Capsule {
                start: point(start),
                end: point(end),
                radius: length(*radius),
            },
        }
    }
}

/// One capsule of the arm; its end points per step are in [`ScenePose::capsules`].
#[derive(Debug, Serialize)]
pub(crate) struct SceneCapsule<'a> {
    link: &'a str,
    radius: f64,
    /// Part of the pen ([`emg_kinematics::Robot::tool_capsules`]): drawn highlighted.
    pen: bool,
}

/// The arm's capsules, in the order [`ScenePose::capsules`] lists their end points.
pub(crate) fn capsules(robot: &Robot) -> Vec<SceneCapsule<'_>> {
    let tool = robot.tool_capsules();
    robot
        .capsules()
        .iter()
        .enumerate()
        .map(|(index, c)| SceneCapsule {
            link: &c.link,
            radius: c.radius,
            pen: tool.contains(&index),
        })
        .collect()
}

/// The arm in one configuration, in world coordinates.
#[derive(Debug, Serialize)]
pub(crate) struct ScenePose {
    /// Base origin, then the origin of every joint, then the TCP.
    joints: Vec<[f64; 3]>,
    tool_axis: [f64; 3],
    /// Both end points `[x0, y0, z0, x1, y1, z1]` of every capsule, in capsule order.
    capsules: Vec<[f64; 6]>,
}

impl ScenePose {
    /// The pose of `robot` at `q` (forward kinematics `kin` of it, already run).
    pub(crate) fn new(robot: &Robot, kin: &emg_kinematics::Kinematics) -> Self {
        let mut joints = Vec::with_capacity(MAX_DOF + 2);
        joints.push(point(&kin.segment_point(0, &Vec3::zeros())));
        joints.extend((0..robot.dof()).map(|i| point(&kin.joint_origin(i))));
        joints.push(point(&kin.tcp()));
        let capsules = robot
            .capsules()
            .iter()
            .map(|c| {
                let [a, b] = [&c.start, &c.end].map(|p| point(&kin.segment_point(c.segment, p)));
                [a[0], a[1], a[2], b[0], b[1], b[2]]
            })
            .collect();
        Self {
            joints,
            tool_axis: point(&kin.tool_axis()),
            capsules,
        }
    }

    /// The pose of `robot` at `q`.
    pub(crate) fn at(robot: &Robot, q: &JointVector) -> Self {
        Self::new(robot, &robot.forward(q))
    }
}

/// One recorded step in world coordinates.
#[derive(Debug, Serialize)]
struct SceneStep {
    t: f64,
    /// Progress `(p − p0)·d` along the line, or the arc length along the path (m).
    s: f64,
    /// Lateral distance of the TCP from the line or the path (m).
    lateral: f64,
    tool_angle_deg: f64,
    rho: f64,
    controller: Option<ActingController>,
    #[serde(flatten)]
    pose: ScenePose,
}

impl<'a> Scene<'a> {
    /// Runs forward kinematics on every step of the input's trajectory.
    pub(crate) fn new(input: &ViewerInput<'a>) -> Self {
        let ViewerInput {
            robot,
            task,
            trajectory,
            constraints,
            title,
        } = *input;
        let plate = match constraints.work_surface {
            WorkSurface::Plate(_) => task
                .work_surface(&constraints.work_surface)
                .shape(&task.p0, &task.d, &task.n),
            WorkSurface::Off | WorkSurface::HalfSpace => None,
        };
        let mut s_m = 0.0;
        let steps = trajectory
            .steps
            .iter()
            .map(|step| scene_step(input, step, &mut s_m))
            .collect();
        Self {
            title,
            robot: robot.name(),
            task: SceneTask {
                p0: point(&task.p0),
                d: point(&task.d),
                n: point(&task.n),
                path: task.path.as_ref().map(ScenePath::new),
            },
            constraints: SceneConstraints {
                line_tolerance_m: constraints.line_tolerance_m,
                theta_max_deg: constraints.theta_max_deg,
                work_surface: constraints.work_surface == WorkSurface::HalfSpace,
            },
            obstacles: cell(plate, &constraints.scene),
            capsules: capsules(robot),
            path_length_m: length(trajectory.path_length_m),
            termination: trajectory.termination.to_string(),
            steps,
        }
    }
}

/// A recorded step as the page draws it; `s_m` is the progress of the step before (followed
/// along a path), updated to this one's.
fn scene_step(input: &ViewerInput<'_>, step: &StepRecord, s_m: &mut f64) -> SceneStep {
    let kin = input.robot.forward(&step.q);
    let along = input.task.along(&kin.tcp(), *s_m);
    *s_m = along.s_m;
    SceneStep {
        t: time(step.time_s),
        s: length(along.s_m),
        lateral: length(along.lateral.norm()),
        tool_angle_deg: value(step.tool_angle_deg),
        rho: value(step.rho),
        controller: step.controller,
        pose: ScenePose::new(input.robot, &kin),
    }
}

/// A point (m) as the page holds it.
pub(crate) fn point(p: &Vec3) -> [f64; 3] {
    [length(p.x), length(p.y), length(p.z)]
}

/// A length (m) as the page holds it.
pub(crate) fn length(x: f64) -> f64 {
    round(x, LENGTH_SCALE)
}

/// A time (s) as the page holds it.
pub(crate) fn time(x: f64) -> f64 {
    round(x, TIME_SCALE)
}

/// An angle (degrees) or a ratio as the page holds it.
pub(crate) fn value(x: f64) -> f64 {
    round(x, VALUE_SCALE)
}

fn round(x: f64, scale: f64) -> f64 {
    (x * scale).round() / scale
}
