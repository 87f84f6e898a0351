//! The data blob a page animates: world-frame geometry of every recorded step.

use emg_control::{ActingController, StepRecord};
use emg_kinematics::{MAX_DOF, Shape, Vec3, WorkSurface};
use serde::Serialize;

use crate::ViewerInput;

/// Metres (and unit-vector components) are written to 10 µm: far below a pixel, and it keeps the
/// page small.
const LENGTH_SCALE: f64 = 1e5;
/// Seconds are written to 1 µs.
const TIME_SCALE: f64 = 1e6;
/// Degrees and `ρ` are written to 1e-4.
const VALUE_SCALE: f64 = 1e4;

/// The page's whole input, serialised as JSON.
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

/// A path sampled every [`PATH_SAMPLE_M`] of arc length (and at its end), with the unit
/// direction across it in the surface (`n × t`) at each sample.
#[derive(Debug, Serialize)]
struct ScenePath {
    step_m: f64,
    length_m: f64,
    points: Vec<[f64; 3]>,
    sides: Vec<[f64; 3]>,
}

/// Arc length (m) between the samples of a path the page draws.
const PATH_SAMPLE_M: f64 = 0.005;

impl ScenePath {
    fn new(task: &emg_control::Task) -> Option<Self> {
        let length = task.length_m()?;
        let count = (length / PATH_SAMPLE_M).ceil() as usize;
        let at = |k: usize| (k as f64 * PATH_SAMPLE_M).min(length);
        Some(Self {
            step_m: PATH_SAMPLE_M,
            length_m: self::length(length),
            points: (0..=count).map(|k| point(&task.point_at(at(k)))).collect(),
            sides: (0..=count)
                .map(|k| point(&task.n.cross(&task.heading_at(at(k)))))
                .collect(),
        })
    }
}

#[derive(Debug, Serialize)]
struct SceneConstraints {
    line_tolerance_m: f64,
    theta_max_deg: f64,
    /// Whether the work surface is the half-space behind the plane through `p0` with normal
    /// `n` (a work plate is drawn as an obstacle named [`emg_control::WORK_SURFACE`]).
    work_surface: bool,
}

/// One obstacle of the cell, in world coordinates.
#[derive(Debug, Serialize)]
struct SceneObstacle<'a> {
    name: &'a str,
    clearance_m: f64,
    #[serde(flatten)]
    solid: SceneSolid,
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

/// One capsule of the arm; its end points per step are in [`SceneStep::capsules`].
#[derive(Debug, Serialize)]
struct SceneCapsule<'a> {
    link: &'a str,
    radius: f64,
    /// Part of the pen ([`emg_kinematics::Robot::tool_capsules`]): drawn highlighted.
    pen: bool,
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
    /// Base origin, then the origin of every joint, then the TCP.
    joints: Vec<[f64; 3]>,
    tool_axis: [f64; 3],
    /// Both end points `[x0, y0, z0, x1, y1, z1]` of every capsule, in capsule order.
    capsules: Vec<[f64; 6]>,
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
        let tool = robot.tool_capsules();
        let capsules = robot
            .capsules()
            .iter()
            .enumerate()
            .map(|(index, c)| SceneCapsule {
                link: &c.link,
                radius: c.radius,
                pen: tool.contains(&index),
            })
            .collect();
        let plate = match constraints.work_surface {
            WorkSurface::Plate(_) => task
                .work_surface(&constraints.work_surface)
                .shape(&task.p0, &task.d, &task.n),
            WorkSurface::Off | WorkSurface::HalfSpace => None,
        };
        let obstacles = plate
            .map(|shape| SceneObstacle {
                name: emg_control::WORK_SURFACE,
                clearance_m: 0.0,
                solid: SceneSolid::new(&shape),
            })
            .into_iter()
            .chain(
                constraints
                    .scene
                    .obstacles
                    .iter()
                    .map(|obstacle| SceneObstacle {
                        name: &obstacle.name,
                        clearance_m: length(obstacle.clearance_m),
                        solid: SceneSolid::new(&obstacle.shape),
                    }),
            )
            .collect();
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
                path: ScenePath::new(task),
            },
            constraints: SceneConstraints {
                line_tolerance_m: constraints.line_tolerance_m,
                theta_max_deg: constraints.theta_max_deg,
                work_surface: constraints.work_surface == WorkSurface::HalfSpace,
            },
            obstacles,
            capsules,
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
    let tcp = kin.tcp();
    let along = input.task.along(&tcp, *s_m);
    *s_m = along.s_m;
    let mut joints = Vec::with_capacity(MAX_DOF + 2);
    joints.push(point(&kin.segment_point(0, &Vec3::zeros())));
    joints.extend((0..input.robot.dof()).map(|i| point(&kin.joint_origin(i))));
    joints.push(point(&tcp));
    let capsules = input
        .robot
        .capsules()
        .iter()
        .map(|c| {
            let [a, b] = [&c.start, &c.end].map(|p| point(&kin.segment_point(c.segment, p)));
            [a[0], a[1], a[2], b[0], b[1], b[2]]
        })
        .collect();
    SceneStep {
        t: round(step.time_s, TIME_SCALE),
        s: length(along.s_m),
        lateral: length(along.lateral.norm()),
        tool_angle_deg: round(step.tool_angle_deg, VALUE_SCALE),
        rho: round(step.rho, VALUE_SCALE),
        controller: step.controller,
        joints,
        tool_axis: point(&kin.tool_axis()),
        capsules,
    }
}

fn point(p: &Vec3) -> [f64; 3] {
    [length(p.x), length(p.y), length(p.z)]
}

fn length(x: f64) -> f64 {
    round(x, LENGTH_SCALE)
}

fn round(x: f64, scale: f64) -> f64 {
    (x * scale).round() / scale
}
