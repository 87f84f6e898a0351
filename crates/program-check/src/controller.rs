//! How an industrial controller moves its arm through a program's targets, as the readers of
//! RAPID and KRL run them: a Cartesian run along straight lines with each fly-by corner on the
//! parabola inside the triangle of the points where the TCP enters and leaves its zone and the
//! target (the zone bounded by half of each neighbouring line), the arm followed sample by
//! sample by its closed-form solution nearest the last; a joint run linear in joint space with
//! each fly-by corner on the joint-space parabola between where the TCP enters and leaves its
//! zone. Every configuration passed is checked against the plan ([`PlanChecks`]).

use emg_job::JobFile;
use emg_kinematics::Vec3;
use emg_verify::ReferenceModel;
use nalgebra::UnitQuaternion;

use crate::plan::{Drawing, PlanChecks, checker_joints};

/// Largest spacing (m) of the TCP samples along an interpolated Cartesian path.
pub const PATH_STEP_M: f64 = 1e-4;
/// Largest step (rad, the joint moving most) between the configurations checked along a joint
/// move.
pub const JOINT_STEP_RAD: f64 = 0.01;
/// Largest change (rad) of any joint between consecutive samples of a Cartesian path: more is
/// a jump through a singularity.
pub const MAX_JOINT_JUMP_RAD: f64 = 0.05;
/// Fewest samples taken along a corner's parabola, however short: a corner turns the TCP, and
/// its progress along the stroke is followed through the turn.
pub const CORNER_SAMPLES: usize = 16;
/// How near (rad, every joint) a target's solution must be to a configuration of the plan.
pub const TARGET_MATCH_RAD: f64 = 1e-6;
/// How near (m and rad) the program's TCP must be to the checker's tip.
pub const TOOL_MATCH: f64 = 1e-6;

/// Why a reader refuses a program: the line (1-based; 0 for the program as a whole) and what
/// failed there.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{problem}", if *.line == 0 { "the program: ".to_string() } else { format!("line {}: ", .line) })]
pub struct ReadError {
    /// The line.
    pub line: usize,
    /// What failed.
    pub problem: String,
}

impl ReadError {
    /// A refusal at `line`.
    pub fn at(line: usize, problem: impl Into<String>) -> Self {
        Self {
            line,
            problem: problem.into(),
        }
    }
}

/// A [`ReadError`] at `line`.
pub fn fail<T>(line: usize, problem: impl Into<String>) -> Result<T, ReadError> {
    Err(ReadError::at(line, problem))
}

/// A pose: position (m) and orientation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// The position (m).
    pub position: Vec3,
    /// The orientation.
    pub rotation: UnitQuaternion<f64>,
}

impl Pose {
    /// The pose of the frame itself: no offset, no turn.
    pub fn identity() -> Pose {
        Pose {
            position: Vec3::zeros(),
            rotation: UnitQuaternion::identity(),
        }
    }

    /// `self` then `other` (`other` given in `self`'s frame).
    pub fn then(&self, other: &Pose) -> Pose {
        Pose {
            position: self.position + self.rotation * other.position,
            rotation: self.rotation * other.rotation,
        }
    }

    /// The pose that undoes `self`.
    pub fn inverse(&self) -> Pose {
        let rotation = self.rotation.inverse();
        Pose {
            position: -(rotation * self.position),
            rotation,
        }
    }

    /// The distance (m) and the angle (rad) between `self` and `other`.
    pub fn difference(&self, other: &Pose) -> (f64, f64) {
        (
            (self.position - other.position).norm(),
            self.rotation.angle_to(&other.rotation),
        )
    }

    /// The pose `t` of the way from `self` to `other`: the position on the line, the
    /// orientation slerped.
    pub fn toward(&self, other: &Pose, t: f64) -> Pose {
        Pose {
            position: self.position + (other.position - self.position) * t,
            rotation: self
                .rotation
                .try_slerp(&other.rotation, t, 1e-12)
                .unwrap_or(self.rotation),
        }
    }
}

/// An arm a reader solves in closed form.
pub trait ClosedForm {
    /// What the controller holds of a target's configuration data along a Cartesian path
    /// (ABB's `cfx` under `ConfL \On`, KUKA's Status).
    type Held: Copy;

    /// The flange at joints `q` (rad, the controller's axes).
    fn flange(&self, q: &[f64; 6]) -> Pose;

    /// The solution of `flange` within `limits` nearest `previous` (largest joint change) among
    /// those that keep `held`, with that change: how the controller follows a Cartesian path.
    fn follow(
        &self,
        flange: &Pose,
        previous: &[f64; 6],
        limits: &[(f64, f64)],
        held: Self::Held,
    ) -> Option<([f64; 6], f64)>;

    /// How far (m) the wrist centre of `flange` lies from axis 2 (with axis 1 turned toward
    /// it), and the farthest the arm reaches it.
    fn wrist_reach(&self, flange: &Pose) -> (f64, f64);
}

/// What the arm did as a reader ran a program through: the figures every reader reports.
#[derive(Clone, Debug, PartialEq)]
pub struct Drawn {
    /// Stroke parts drawn (tool switched on).
    pub stroke_parts: usize,
    /// Configurations checked along the moves.
    pub samples: usize,
    /// Largest distance (m) of the interpolated TCP from its task while the tool is on.
    pub worst_deviation_m: f64,
    /// Largest angle (degrees) of the tool axis from its task's normal while the tool is on.
    pub worst_tool_angle_deg: f64,
    /// Smallest self-clearance (m) along the moves.
    pub least_clearance_m: f64,
    /// Total covered while the tool is on (m).
    pub covered_m: f64,
    /// Total the plan draws (m).
    pub drawn_m: f64,
}

/// A Cartesian target of a fly-by run.
#[derive(Clone, Copy, Debug)]
pub struct CartesianTarget<H> {
    /// The TCP's pose (base frame).
    pub pose: Pose,
    /// Its solution by its configuration data.
    pub joints: [f64; 6],
    /// Its zone's (or approximation distance's) radius (m): 0 where the arm stops there.
    pub zone_m: f64,
    /// The program's line that names it.
    pub line: usize,
    /// What the controller holds of its configuration data.
    pub held: H,
}

/// A joint target of a fly-by run.
#[derive(Clone, Copy, Debug)]
pub struct JointTarget {
    /// The axes (rad).
    pub joints: [f64; 6],
    /// Its zone's radius (m, the TCP's distance): 0 where the arm stops there.
    pub zone_m: f64,
    /// The program's line that names it.
    pub line: usize,
}

/// A controller running an arm with a tool against a plan.
pub struct Controller<'a, A> {
    /// The arm.
    pub arm: A,
    /// The plan's side.
    pub plan: PlanChecks<'a>,
    /// The TCP in the flange frame.
    pub tool: Pose,
}

/// The largest change of any joint from `a` to `b` (rad).
pub fn largest_change(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The plan's configurations a target's solution is matched against: its samples and its
/// moves' vertices.
pub struct PlanConfigurations(Vec<[f64; 6]>);

impl PlanConfigurations {
    /// The configurations of the plan `file`.
    pub fn of(file: &JobFile) -> Self {
        let mut configurations: Vec<[f64; 6]> = file
            .points()
            .iter()
            .map(|p| std::array::from_fn(|i| p.positions[i]))
            .collect();
        for segment in &file.segments {
            for vertex in &segment.vertices {
                if vertex.len() >= 6 {
                    configurations.push(std::array::from_fn(|i| vertex[i]));
                }
            }
        }
        Self(configurations)
    }

    /// The first configuration, if the plan has one.
    pub fn first(&self) -> Option<&[f64; 6]> {
        self.0.first()
    }

    /// The configuration nearest `q` (largest joint difference), with that difference.
    pub fn nearest(&self, q: &[f64; 6]) -> (f64, [f64; 6]) {
        self.0
            .iter()
            .map(|c| (largest_change(c, q), *c))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap_or((f64::INFINITY, *q))
    }
}

/// The configuration `t` of the way from `a` to `b`, linear in joint space.
fn lerp(a: &[f64; 6], b: &[f64; 6], t: f64) -> [f64; 6] {
    std::array::from_fn(|j| a[j] + (b[j] - a[j]) * t)
}

impl<A: ClosedForm> Controller<'_, A> {
    /// The TCP at `joints`.
    pub fn tcp(&self, joints: &[f64; 6]) -> Pose {
        self.arm.flange(joints).then(&self.tool)
    }

    /// Checks that the program's tool, on the arm's flange at `q`, is the checker `model`'s tip
    /// (within [`TOOL_MATCH`], position and tool axis); else says how far it lies.
    pub fn tool_is_tip(&self, model: &ReferenceModel, q: &[f64; 6]) -> Result<(), String> {
        let (position, rotation) = model.tcp_frame(&checker_joints(q));
        let tip = self.tcp(q);
        let axis = tip.rotation * Vec3::z();
        let (distance, angle) = (
            (tip.position - position).norm(),
            libm::acos(axis.dot(&rotation.column(2).into_owned()).clamp(-1.0, 1.0)),
        );
        if distance > TOOL_MATCH || angle > TOOL_MATCH {
            return Err(format!(
                "the tool's TCP is not the tool's tip ({distance:.3e} m, {angle:.3e} rad away)"
            ));
        }
        Ok(())
    }

    /// What the arm drew once the program has run to its last line `last_line`: the tool off
    /// and every stroke part drawn ([`PlanChecks::finish`]), the coverage
    /// ([`PlanChecks::covered`]) and the figures met on the way.
    pub fn finish(
        &self,
        drawing: &Drawing,
        file: &JobFile,
        last_line: usize,
    ) -> Result<Drawn, ReadError> {
        self.plan
            .finish(drawing)
            .or_else(|problem| fail(last_line, problem))?;
        let covered = self
            .plan
            .covered(drawing, file)
            .or_else(|problem| fail(0, problem))?;
        Ok(Drawn {
            stroke_parts: drawing.parts_on,
            samples: drawing.samples,
            worst_deviation_m: drawing.worst_deviation_m,
            worst_tool_angle_deg: drawing.worst_tool_angle_deg,
            least_clearance_m: drawing.least_clearance_m,
            covered_m: covered.covered_m,
            drawn_m: covered.drawn_m,
        })
    }

    /// Runs the fly-by run `run` from `joints`: along straight lines, each fly-by corner on the
    /// parabola through its zone (the zone at most half of each neighbouring line), the tool
    /// followed by the nearest solution sample by sample; the joints it ends at.
    pub fn cartesian_run(
        &self,
        drawing: &mut Drawing,
        joints: [f64; 6],
        run: &[CartesianTarget<A::Held>],
    ) -> Result<[f64; 6], ReadError> {
        let start = self.tcp(&joints);
        let mut corners: Vec<Pose> = vec![start];
        corners.extend(run.iter().map(|r| r.pose));
        // Each inner corner's zone, bounded by half of either line.
        let radius = |k: usize| -> f64 {
            if k == 0 || k + 1 >= corners.len() {
                return 0.0;
            }
            let before = (corners[k].position - corners[k - 1].position).norm();
            let after = (corners[k + 1].position - corners[k].position).norm();
            run[k - 1].zone_m.min(before / 2.0).min(after / 2.0)
        };
        let mut joints = joints;
        let mut from = start;
        for k in 1..corners.len() {
            let target = &run[k - 1];
            let (a, b) = (corners[k - 1], corners[k]);
            let length = (b.position - a.position).norm().max(1e-12);
            let entry = b.toward(&a, radius(k) / length);
            // The straight line up to where the next zone begins.
            joints = self.follow_segment(drawing, [&from, &entry], joints, target)?;
            if radius(k) > 0.0 {
                let c = corners[k + 1];
                let out_length = (c.position - b.position).norm().max(1e-12);
                let exit = b.toward(&c, radius(k) / out_length);
                joints = self.follow_corner(drawing, [&entry, &b, &exit], joints, target)?;
                from = exit;
            } else {
                from = b;
                if largest_change(&joints, &target.joints) > TARGET_MATCH_RAD * 10.0 {
                    return fail(
                        target.line,
                        format!(
                            "the controller arrives at {joints:?}, not at the plan's {:?}",
                            target.joints
                        ),
                    );
                }
                joints = target.joints;
            }
        }
        Ok(joints)
    }

    /// Follows the straight line from `a` to `b`, sampled every [`PATH_STEP_M`].
    fn follow_segment(
        &self,
        drawing: &mut Drawing,
        [a, b]: [&Pose; 2],
        joints: [f64; 6],
        target: &CartesianTarget<A::Held>,
    ) -> Result<[f64; 6], ReadError> {
        let (distance, angle) = a.difference(b);
        let count = ((distance / PATH_STEP_M).max(angle / 1e-3)).ceil().max(1.0) as usize;
        let mut joints = joints;
        for k in 1..=count {
            let pose = a.toward(b, k as f64 / count as f64);
            joints = self.sample(drawing, &pose, joints, target)?;
        }
        Ok(joints)
    }

    /// Follows the corner's parabola from `entry` past `target` to `exit`, sampled every
    /// [`PATH_STEP_M`] and at least [`CORNER_SAMPLES`] times.
    fn follow_corner(
        &self,
        drawing: &mut Drawing,
        [entry, corner, exit]: [&Pose; 3],
        joints: [f64; 6],
        target: &CartesianTarget<A::Held>,
    ) -> Result<[f64; 6], ReadError> {
        let length =
            (corner.position - entry.position).norm() + (exit.position - corner.position).norm();
        let count = ((length / PATH_STEP_M).ceil() as usize).max(CORNER_SAMPLES);
        let mut joints = joints;
        for k in 1..=count {
            let t = k as f64 / count as f64;
            let position = entry.position * ((1.0 - t) * (1.0 - t))
                + corner.position * (2.0 * t * (1.0 - t))
                + exit.position * (t * t);
            let pose = Pose {
                position,
                rotation: entry.toward(exit, t).rotation,
            };
            joints = self.sample(drawing, &pose, joints, target)?;
        }
        Ok(joints)
    }

    /// One sample of a Cartesian path toward `target`: its joints by the solution nearest the
    /// last among those keeping what the target holds, no joint jumping, the configuration
    /// checked, and while the tool is on, the TCP on its task.
    fn sample(
        &self,
        drawing: &mut Drawing,
        pose: &Pose,
        joints: [f64; 6],
        target: &CartesianTarget<A::Held>,
    ) -> Result<[f64; 6], ReadError> {
        let flange = pose.then(&self.tool.inverse());
        let Some((q, change)) = self
            .arm
            .follow(&flange, &joints, self.plan.limits(), target.held)
        else {
            let (wrist, reach) = self.arm.wrist_reach(&flange);
            return fail(
                target.line,
                format!(
                    "{:?} is out of reach: its wrist centre lies {wrist:.6} m from axis 2, which \
                     the arm reaches {reach:.6} m from (or a joint limit stands in the way)",
                    pose.position.as_slice()
                ),
            );
        };
        if change > MAX_JOINT_JUMP_RAD {
            return fail(
                target.line,
                format!("a joint jumps by {change:.4} rad within {PATH_STEP_M} m of the path"),
            );
        }
        self.check_configuration(drawing, &q, target.line)?;
        if drawing.tool_on {
            let axis = pose.rotation * Vec3::z();
            self.plan
                .on_task(drawing, &pose.position, &axis)
                .or_else(|problem| fail(target.line, problem))?;
        }
        Ok(q)
    }

    /// Runs the fly-by joint run `run` from `start` (where the arm stands, if known): linear in
    /// joint space, each fly-by corner on the joint-space parabola between the points where
    /// the TCP enters and leaves its zone, every configuration checked; the joints it ends at.
    pub fn joint_run(
        &self,
        drawing: &mut Drawing,
        start: Option<[f64; 6]>,
        run: &[JointTarget],
    ) -> Result<Option<[f64; 6]>, ReadError> {
        let Some(end) = run.last() else {
            return Ok(start);
        };
        if let Some(start) = start {
            let mut vertices = vec![start];
            vertices.extend(run.iter().map(|r| r.joints));
            let tcp = |q: &[f64; 6]| self.tcp(q).position;
            // Where the TCP comes within `radius` of `w` on the edge from `from` to `w`.
            let entering = |from: &[f64; 6], w: &[f64; 6], radius: f64| -> f64 {
                let steps = (largest_change(from, w) / JOINT_STEP_RAD).ceil().max(1.0) as usize;
                let corner = tcp(w);
                (0..=steps)
                    .map(|k| k as f64 / steps as f64)
                    .find(|&t| (tcp(&lerp(from, w, t)) - corner).norm() <= radius)
                    .unwrap_or(1.0)
            };
            let mut from = start;
            for k in 1..vertices.len() {
                let (line, radius) = (run[k - 1].line, run[k - 1].zone_m);
                let w = vertices[k];
                let (entry, exit) = match vertices.get(k + 1) {
                    Some(next) if radius > 0.0 => (
                        lerp(&vertices[k - 1], &w, entering(&vertices[k - 1], &w, radius)),
                        lerp(next, &w, entering(next, &w, radius)),
                    ),
                    _ => (w, w),
                };
                self.check_joint_edge(drawing, &from, &entry, line)?;
                if entry != w {
                    let steps = (largest_change(&entry, &exit).max(largest_change(&entry, &w))
                        / JOINT_STEP_RAD)
                        .ceil()
                        .max(2.0) as usize;
                    for s in 1..=steps {
                        let t = s as f64 / steps as f64;
                        let q: [f64; 6] = std::array::from_fn(|j| {
                            entry[j] * (1.0 - t) * (1.0 - t)
                                + w[j] * 2.0 * t * (1.0 - t)
                                + exit[j] * t * t
                        });
                        self.check_configuration(drawing, &q, line)?;
                    }
                }
                from = exit;
            }
        }
        Ok(Some(end.joints))
    }

    /// Checks the configurations along the joint-space edge from `a` to `b`.
    fn check_joint_edge(
        &self,
        drawing: &mut Drawing,
        a: &[f64; 6],
        b: &[f64; 6],
        line: usize,
    ) -> Result<(), ReadError> {
        let steps = (largest_change(a, b) / JOINT_STEP_RAD).ceil().max(1.0) as usize;
        for k in 1..=steps {
            self.check_configuration(drawing, &lerp(a, b, k as f64 / steps as f64), line)?;
        }
        Ok(())
    }

    /// Checks a configuration the arm passes ([`PlanChecks::configuration`]).
    fn check_configuration(
        &self,
        drawing: &mut Drawing,
        q: &[f64; 6],
        line: usize,
    ) -> Result<(), ReadError> {
        self.plan
            .configuration(drawing, q)
            .or_else(|problem| fail(line, problem))
    }

    /// The tool switched on or off (`on`) at line `line` with the arm at rest at `joints`
    /// ([`PlanChecks::switch_on`], [`PlanChecks::switch_off`]); nothing where it already is.
    pub fn switch(
        &self,
        drawing: &mut Drawing,
        joints: Option<[f64; 6]>,
        on: bool,
        line: usize,
    ) -> Result<(), ReadError> {
        if on == drawing.tool_on {
            return Ok(());
        }
        let joints =
            joints.ok_or_else(|| ReadError::at(line, "the tool switches before the first move"))?;
        let pose = self.tcp(&joints);
        let switched = if on {
            self.plan
                .switch_on(drawing, &pose.position, &(pose.rotation * Vec3::z()))
        } else {
            self.plan.switch_off(drawing, &pose.position)
        };
        switched.or_else(|problem| fail(line, problem))
    }
}
