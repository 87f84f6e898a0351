//! The connect stage's geometry: the part under a job's strokes, which configurations are free
//! (the joint limits, self-collision, the part and the scene, the tool's tip never inside the
//! part), the straight joint-space edges between them checked at a resolution no link can step
//! over, the lifted configuration above a point of a stroke, and the collision-free move
//! between two configurations (the straight edge, else dual RRT-Connect with shortcuts).

use emg_control::{ConstraintConfig, Path, PathSpec, SegmentSpec, Task};
use emg_kinematics::{JointVector, Obstacle, Robot, Vec3, project_to_point};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// How far beyond the range between a free move's ends its sampled joint values reach first
/// (rad): a quarter turn.
pub const SAMPLE_MARGIN_RAD: f64 = std::f64::consts::FRAC_PI_2;

/// The farthest any point of the arm moves between two configurations an edge check visits
/// (m): far less than the radius of any link's capsule.
pub const MAX_POINT_TRAVEL_M: f64 = 0.005;

/// Step of the sampling planner's trees (rad, joint-space distance).
const RRT_EXTEND_RAD: f64 = 0.1;

/// Shortcut attempts on a sampled move.
const SHORTCUTS: usize = 200;

/// Share of the lift that the tool's tip keeps above the part all along a pen-up move, but on
/// the lift and the set-down themselves: within [`LIFT_CONE_RUN`] times its height across the
/// part from where the tool leaves it and where it meets it again (`emg check` measures the
/// same).
pub const PEN_UP_CLEARANCE_SHARE: f64 = 0.5;

/// How far across the part (m per m of height) the tool's tip may lie from where it lifts off
/// or sets down while it is lower than the pen-up clearance: a lift or set-down rises at least
/// half as fast as it moves aside (one along the normal, a hop at about 45°); a move that sags
/// back toward the part away from its ends does not.
pub const LIFT_CONE_RUN: f64 = 2.0;

/// How much higher (m) than the pen-up clearance a pen-up move's tip is kept where it is
/// checked ([`FreeSpace::move_free`]): between two checks a smooth move dips by far less.
pub const TIP_CLEARANCE_MARGIN_M: f64 = 5e-5;

/// The tool's tip is checked this many times per edge step ([`MAX_POINT_TRAVEL_M`] of any
/// point's travel) along a pen-up move ([`FreeSpace::move_free`]).
pub const TIP_CHECKS_PER_STEP: f64 = 10.0;

/// The shares of the job's lift height tried in turn where the tool cannot lift the whole of it
/// into free space (near an obstacle, say).
pub const LIFT_SHARES: [f64; 3] = [1.0, 0.5, 0.25];

/// Planes closer than this (m, and the same in the cosine of their normals) are one surface.
const SAME_PLANE: f64 = 1e-6;

/// The part under `job`'s strokes: [`part_surfaces`] of their tasks.
pub fn job_part(robot: &Robot, job: &crate::spec::Job) -> Vec<Task> {
    let tasks: Vec<Task> = job
        .strokes
        .iter()
        .filter_map(|stroke| Task::on_path(robot, stroke.clone(), None).ok())
        .collect();
    part_surfaces(robot, &tasks)
}

/// Orientations of a plane's rectangle tried (a half turn, in 1° steps).
pub const RECTANGLE_ANGLES: usize = 180;

/// How far a path's point may lie outside the polygon of the points [`outline_points`] samples
/// on it (m): the largest sagitta of their chords across an arc.
const OUTLINE_SAGITTA_M: f64 = 1e-5;

/// The margin the part's rectangle adds round its strokes (m): every stroke point lies at least
/// this far inside it.
const PART_ROUND_M: f64 = 1e-3;

/// Points of `path` whose polygon holds the path to within [`OUTLINE_SAGITTA_M`]: the ends of
/// every piece, and along an arc points close enough that no chord's sagitta exceeds it (the
/// extreme points of a tight arc lie between points a centimetre apart, by up to 2 mm on an arc
/// of 6 mm radius).
fn outline_points(path: &Path) -> impl Iterator<Item = Vec3> + '_ {
    path.pieces().iter().flat_map(move |piece| {
        let (start, end, arc) = piece.outline();
        let count = match arc {
            None => 1,
            Some((centre, _)) => {
                // A chord `c` across radius `r` has sagitta `c² / 8r`.
                let chord = (8.0 * (start - centre).norm() * OUTLINE_SAGITTA_M).sqrt();
                (piece.length_m / chord).ceil().max(1.0) as usize
            }
        };
        (0..count)
            .map(move |k| path.point_at(piece.start_s + piece.length_m * k as f64 / count as f64))
            .chain(std::iter::once(end))
    })
}

/// One task per plane of `tasks` whose work plate is the part those strokes lie on: its path
/// runs along the middle of the smallest rectangle (of [`RECTANGLE_ANGLES`] orientations)
/// holding all the tasks' path points on the plane ([`PART_ROUND_M`] added round) and zigzags
/// to its edges, so the plate covers the rectangle with the plate's margins and no more. A
/// plane whose rectangle makes no task keeps its strokes' own tasks.
pub fn part_surfaces(robot: &Robot, tasks: &[Task]) -> Vec<Task> {
    let mut planes: Vec<(Vec3, Vec3, Vec<&Task>)> = Vec::new();
    for task in tasks {
        let found = planes.iter_mut().find(|(point, normal, _)| {
            normal.dot(&task.n) > 1.0 - SAME_PLANE
                && (task.p0 - *point).dot(normal).abs() < SAME_PLANE
        });
        match found {
            Some((_, _, members)) => members.push(task),
            None => planes.push((task.p0, task.n, vec![task])),
        }
    }
    let mut surfaces = Vec::new();
    for (point, normal, members) in planes {
        let points: Vec<Vec3> = members
            .iter()
            .filter_map(|task| task.path.as_ref())
            .flat_map(outline_points)
            .collect();
        match rectangle_path(point, normal, members[0].d, &points)
            .and_then(|path| Task::on_path(robot, path, None).ok())
        {
            Some(task) => surfaces.push(task),
            None => surfaces.extend(members.into_iter().cloned()),
        }
    }
    surfaces
}

/// The path along the middle of the smallest rectangle on the plane through `point` with
/// normal `normal` holding `points` ([`PART_ROUND_M`] added round, and the sagitta
/// [`outline_points`] may leave out), its sides turned from `u0` by one of
/// [`RECTANGLE_ANGLES`] angles: from the middle of one end to the other's, then round the
/// rectangle's corners, so its extent across its start direction is half the rectangle's width
/// to each side.
fn rectangle_path(point: Vec3, normal: Vec3, u0: Vec3, points: &[Vec3]) -> Option<Path> {
    if points.is_empty() {
        return None;
    }
    let w0 = normal.cross(&u0);
    let round = PART_ROUND_M + OUTLINE_SAGITTA_M;
    let bounds = |u: &Vec3, w: &Vec3| {
        let mut low = [f64::INFINITY; 2];
        let mut high = [f64::NEG_INFINITY; 2];
        for p in points {
            let offset = p - point;
            for (axis, value) in [offset.dot(u), offset.dot(w)].into_iter().enumerate() {
                low[axis] = low[axis].min(value - round);
                high[axis] = high[axis].max(value + round);
            }
        }
        (low, high)
    };
    let (u, w, (low, high)) = (0..RECTANGLE_ANGLES)
        .map(|k| {
            let angle = std::f64::consts::PI * k as f64 / RECTANGLE_ANGLES as f64;
            let u = u0 * libm::cos(angle) + w0 * libm::sin(angle);
            let w = normal.cross(&u);
            (u, w, bounds(&u, &w))
        })
        .min_by(|a, b| area(&a.2).total_cmp(&area(&b.2)))?;
    let corner = |a: f64, b: f64| point + u * a + w * b;
    let middle = 0.5 * (low[1] + high[1]);
    let spec = PathSpec {
        version: emg_control::PATH_FORMAT_VERSION,
        start: corner(low[0], middle).into(),
        normal: normal.into(),
        blend_radius_m: 0.0,
        segments: [
            corner(high[0], middle),
            corner(high[0], high[1]),
            corner(low[0], high[1]),
            corner(low[0], low[1]),
            corner(high[0], low[1]),
        ]
        .into_iter()
        .map(|to| SegmentSpec::Line { to: to.into() })
        .collect(),
    };
    Path::new(spec).ok()
}

/// The area of the rectangle `[low, high]`.
fn area((low, high): &([f64; 2], [f64; 2])) -> f64 {
    (high[0] - low[0]) * (high[1] - low[1])
}

/// Name of the obstacles [`with_part`] adds.
pub const PART: &str = "part";

/// `constraints` with the part the strokes lie on added to the scene: the work plate of each task
/// of `surfaces` ([`part_surfaces`]) under `constraints.work_surface`, an obstacle the tool may
/// touch and the rest of the arm keeps off, while drawing as between strokes.
pub fn with_part(constraints: &ConstraintConfig, surfaces: &[Task]) -> ConstraintConfig {
    let mut with_part = constraints.clone();
    with_part
        .scene
        .obstacles
        .extend(surfaces.iter().filter_map(|task| {
            let plate = task
                .work_surface(&constraints.work_surface)
                .shape(&task.p0, &task.d, &task.n)?;
            Some(Obstacle {
                name: PART.to_string(),
                shape: plate,
                clearance_m: 0.0,
                tool_may_touch: true,
            })
        }));
    with_part
}

/// Free space of a job's arm.
pub struct FreeSpace<'a> {
    robot: &'a Robot,
    /// The tasks whose work plates make the part ([`part_surfaces`]).
    surfaces: Vec<Task>,
    /// The constraints, the part in the scene ([`with_part`]).
    constraints: ConstraintConfig,
    /// Each stroke's plane (a point on it, its normal) and the radius around that point inside
    /// which the tool's tip stays on the near side of it.
    planes: Vec<(Vec3, Vec3, f64)>,
    /// Largest `Σ|Δq_i|` between two checked configurations of an edge (rad).
    step_l1_rad: f64,
}

impl<'a> FreeSpace<'a> {
    /// The free space of `robot` around the part the tasks `surfaces` make ([`with_part`]: their
    /// plates under `constraints`, with its scene and margin), the tool's tip kept on the near
    /// side of each task's plane within its path's extent and 5 cm more.
    pub fn new(robot: &'a Robot, surfaces: Vec<Task>, constraints: &ConstraintConfig) -> Self {
        let planes = surfaces
            .iter()
            .map(|task| {
                let radius = task.path.as_ref().map_or(0.0, |path| {
                    let extent = path.extent();
                    extent.behind_m.max(extent.ahead_m) + extent.across_m
                });
                (task.p0, task.n, radius + 0.05)
            })
            .collect();
        // A joint turning by Δ moves a point at most |Δ| times its distance from the joint's
        // axis, which is at most the diameter of the sphere the arm reaches.
        let (_, reach) = robot.reach_sphere();
        Self {
            robot,
            constraints: with_part(constraints, &surfaces),
            surfaces,
            planes,
            step_l1_rad: MAX_POINT_TRAVEL_M / (2.0 * reach),
        }
    }

    /// The arm.
    pub fn robot(&self) -> &'a Robot {
        self.robot
    }

    /// The tasks whose work plates make the part.
    pub fn surfaces(&self) -> &[Task] {
        &self.surfaces
    }

    /// The constraints the arm keeps: the scene with the part in it, the margin.
    pub fn constraints(&self) -> &ConstraintConfig {
        &self.constraints
    }

    /// Whether `q` is free: within the joint limits, no link touching another, a plate or an
    /// obstacle, the tool's tip not inside the part.
    pub fn free(&self, q: &JointVector) -> bool {
        self.free_by(q, 0.0)
    }

    /// Whether `q` is free with `margin` (m) more clearance than the constraints ask from the
    /// plates and from the obstacles (not between the arm's own links, some of which always lie
    /// closer than that to one another).
    fn free_by(&self, q: &JointVector, margin: f64) -> bool {
        if self.robot.limits().first_violation(q, 0.0).is_some() {
            return false;
        }
        let kinematics = self.robot.forward(q);
        let tcp = kinematics.tcp();
        let inside = self.planes.iter().any(|(point, normal, radius)| {
            let offset = tcp - point;
            let depth = offset.dot(normal);
            depth > self.constraints.line_tolerance_m && (offset - normal * depth).norm() <= *radius
        });
        if inside
            || self
                .robot
                .first_collision(&kinematics, self.constraints.collision_margin_m)
                .is_some()
        {
            return false;
        }
        self.constraints.scene.obstacles.iter().all(|obstacle| {
            self.robot
                .first_contact(
                    &kinematics,
                    &obstacle.shape,
                    obstacle.clearance_m + margin,
                    obstacle.tool_contact(),
                )
                .is_none()
        })
    }

    /// Whether the straight joint-space edge from `a` to `b` is free at every configuration
    /// visited, no two of them more than [`MAX_POINT_TRAVEL_M`] apart at any point of the arm,
    /// the ones inside it with half that more clearance: free all along.
    pub fn edge_free(&self, a: &JointVector, b: &JointVector) -> bool {
        let steps = ((b - a).abs().sum() / self.step_l1_rad).ceil().max(1.0) as usize;
        // Between two checked configurations no point of the arm moves more than
        // `MAX_POINT_TRAVEL_M`, so none comes closer than half of it to where it was checked:
        // the configurations inside the edge keep that much more clearance from the part and the
        // cell.
        self.free(a)
            && self.free(b)
            && (1..steps).all(|k| {
                self.free_by(
                    &(a + (b - a) * (k as f64 / steps as f64)),
                    MAX_POINT_TRAVEL_M / 2.0,
                )
            })
    }

    /// Whether the motion through `path` (a timed motion's samples, close together) is free:
    /// its ends, and the configurations along the polyline of its samples every
    /// [`FreeSpace::edge_free`] step of joint-space length (`Σ|Δq_i|`), those with half
    /// [`MAX_POINT_TRAVEL_M`] more clearance, as an edge is checked.
    pub fn path_free(&self, path: &[JointVector]) -> bool {
        let (Some(first), Some(last)) = (path.first(), path.last()) else {
            return true;
        };
        if !(self.free(first) && self.free(last)) {
            return false;
        }
        // Joint-space length walked since the last configuration checked.
        let mut since = 0.0;
        for pair in path.windows(2) {
            let chord = pair[1] - pair[0];
            let length = chord.abs().sum();
            let mut along = self.step_l1_rad - since;
            while along < length {
                if !self.free_by(
                    &(pair[0] + chord * (along / length)),
                    MAX_POINT_TRAVEL_M / 2.0,
                ) {
                    return false;
                }
                along += self.step_l1_rad;
            }
            since = length - (along - self.step_l1_rad);
        }
        true
    }
    /// Whether the pen-up move through `path` (from where the tool leaves the part, or from
    /// above it, to where it meets the next part, or above it) is free ([`FreeSpace::path_free`])
    /// and keeps the tool's tip `clearance_m` (and [`TIP_CLEARANCE_MARGIN_M`]) above the part at
    /// every configuration checked,
    /// but within the lift cones ([`LIFT_CONE_RUN`]) of the tips of its first and last
    /// configurations (the lift and the set-down): a move that sags between two lifted
    /// configurations would drag the tool across the part.
    pub fn move_free(&self, path: &[JointVector], clearance_m: f64) -> bool {
        let (Some(first), Some(last)) = (path.first(), path.last()) else {
            return true;
        };
        let ends = [first, last].map(|q| self.robot.forward(q).tcp());
        let clearance_m = clearance_m + TIP_CLEARANCE_MARGIN_M;
        let clear =
            |q: &JointVector| self.tip_clear(&self.robot.forward(q).tcp(), &ends, clearance_m);
        // The tip is checked at every point of `path` and, between two points further apart,
        // every [`TIP_CHECKS_PER_STEP`]th of an edge step: a sag is shallow and short.
        let step = self.step_l1_rad / TIP_CHECKS_PER_STEP;
        let tips_clear = path.iter().all(clear)
            && path.windows(2).all(|pair| {
                let checks = ((pair[1] - pair[0]).abs().sum() / step).ceil() as usize;
                (1..checks)
                    .all(|k| clear(&(pair[0] + (pair[1] - pair[0]) * (k as f64 / checks as f64))))
            });
        tips_clear && self.path_free(path)
    }

    /// Whether the tool's tip at `tip` lies `clearance_m` above every plate of the part it lies
    /// over, or across that plate from one of `ends` by at most [`LIFT_CONE_RUN`] times its
    /// height above that end.
    fn tip_clear(&self, tip: &Vec3, ends: &[Vec3], clearance_m: f64) -> bool {
        self.surfaces.iter().all(|task| {
            let emg_kinematics::WorkSurface::Plate(plate) =
                task.work_surface(&self.constraints.work_surface)
            else {
                return true;
            };
            let offset = tip - task.p0;
            let (along, height) = (offset.dot(&task.d), -offset.dot(&task.n));
            let across = offset.dot(&task.n.cross(&task.d));
            let over = along >= -plate.behind_m
                && along <= plate.ahead_m
                && across.abs() <= plate.half_width_m;
            let on_a_lift = || {
                ends.iter().any(|end| {
                    let beside = tip - end;
                    let risen = -beside.dot(&task.n);
                    (beside + task.n * risen).norm() <= LIFT_CONE_RUN * risen.max(0.0) + 1e-9
                })
            };
            !over || height >= clearance_m || on_a_lift()
        })
    }

    /// Whether the joint-space triangle with corners `a`, `w` and `b` is free all over: its
    /// corners, and a grid over it whose cells are at most half a [`FreeSpace::edge_free`] step
    /// across along each side (every point within half a step of a grid point, as along a
    /// checked edge), the grid points with half [`MAX_POINT_TRAVEL_M`] more clearance. Any path
    /// inside the triangle (a blend rounding the corner `w` between the edges `a`–`w` and
    /// `w`–`b`, whatever its shape) is then free.
    pub fn triangle_free(&self, a: &JointVector, w: &JointVector, b: &JointVector) -> bool {
        let longer = (w - a).abs().sum().max((w - b).abs().sum());
        let cells = (2.0 * longer / self.step_l1_rad).ceil().max(1.0) as usize;
        let (towards_a, towards_b) = ((a - w) / cells as f64, (b - w) / cells as f64);
        self.free(a)
            && self.free(w)
            && self.free(b)
            && (0..=cells).all(|i| {
                (0..=cells - i).all(|j| {
                    let q = w + towards_a * i as f64 + towards_b * j as f64;
                    self.free_by(&q, MAX_POINT_TRAVEL_M / 2.0)
                })
            })
    }

    /// The configuration near `q` whose TCP lies at `target` ([`project_to_point`]), if the
    /// Newton steps converge to a free configuration joined to `q` by a free edge.
    pub fn reach_point(&self, q: &JointVector, target: &Vec3) -> Option<JointVector> {
        project_to_point(self.robot, q, target)
            .filter(|reached| self.free(reached) && self.edge_free(q, reached))
    }

    /// Why a tool cannot lift `lift_m` off the `what` (start or end) of a stroke part where
    /// [`FreeSpace::lifted`] finds no configuration.
    pub fn cannot_lift(lift_m: f64, what: &str) -> String {
        format!(
            "the tool cannot lift {lift_m} m (or a quarter of it) off its {what} into free space"
        )
    }

    /// The configuration near `q` with the TCP lifted `lift_m` along the unit vector `up`
    /// ([`FreeSpace::reach_point`]), else half or a quarter of that ([`LIFT_SHARES`]): where
    /// the tool leaves or meets the part. `None` where none of them is free.
    pub fn lifted(&self, q: &JointVector, up: &Vec3, lift_m: f64) -> Option<JointVector> {
        let tcp = self.robot.forward(q).tcp();
        LIFT_SHARES
            .iter()
            .find_map(|share| self.reach_point(q, &(tcp + up * (lift_m * share))))
    }

    /// A free move from `a` to `b`: the straight edge where it is free, else a path of dual
    /// RRT-Connect (the `rrt` crate, at most `max_samples` samples from `seed`), every edge
    /// checked as [`FreeSpace::edge_free`] checks it, then shortened by shortcuts. The samples
    /// are drawn uniform within the joint limits narrowed to [`SAMPLE_MARGIN_RAD`] beyond
    /// the range between `a` and `b` (so that no joint wanders a turn away, on an arm whose
    /// joints span ±2π), and within the whole limits where no move is found there. `None`
    /// where no free move was found.
    pub fn connect(
        &self,
        a: &JointVector,
        b: &JointVector,
        seed: u64,
        max_samples: usize,
    ) -> Option<Vec<JointVector>> {
        if self.edge_free(a, b) {
            return Some(vec![*a, *b]);
        }
        let limits = self.robot.limits();
        let near = (a.inf(b).add_scalar(-SAMPLE_MARGIN_RAD)).sup(&limits.lower);
        let far = (a.sup(b).add_scalar(SAMPLE_MARGIN_RAD)).inf(&limits.upper);
        let sampled = self
            .sampled_move(a, b, (&near, &far), seed, max_samples)
            .or_else(|| {
                let whole = (near != limits.lower || far != limits.upper)
                    .then_some((&limits.lower, &limits.upper))?;
                self.sampled_move(a, b, whole, seed, max_samples)
            })?;
        let mut path: Vec<JointVector> =
            sampled.iter().map(|q| self.robot.joint_vector(q)).collect();
        // The trees checked their nodes only: split every edge that is not free at the check's
        // resolution by its midpoint, where that is free, a few times.
        path = self.refine(path)?;
        Some(self.shortcut(path, seed))
    }

    /// Dual RRT-Connect from `a` to `b`, its samples uniform between `lower` and `upper`.
    fn sampled_move(
        &self,
        a: &JointVector,
        b: &JointVector,
        (lower, upper): (&JointVector, &JointVector),
        seed: u64,
        max_samples: usize,
    ) -> Option<Vec<Vec<f64>>> {
        let dof = self.robot.dof();
        // The sampler is called as a shared closure: its generator sits in a cell.
        let rng = std::cell::RefCell::new(ChaCha8Rng::seed_from_u64(seed));
        rrt::dual_rrt_connect(
            &a.as_slice()[..dof],
            &b.as_slice()[..dof],
            // The trees' nodes keep the clearance an edge's inner configurations keep, so that
            // the edges between them are free too; the ends are free as they are.
            |q: &[f64]| {
                let q = self.robot.joint_vector(q);
                q == *a || q == *b || self.free_by(&q, MAX_POINT_TRAVEL_M / 2.0)
            },
            || {
                let mut rng = rng.borrow_mut();
                (0..dof)
                    .map(|i| rng.random_range(lower[i]..=upper[i]))
                    .collect()
            },
            RRT_EXTEND_RAD,
            max_samples,
        )
        .ok()
    }

    /// `path` with every edge free, midpoints inserted where an edge is not (up to 6 halvings);
    /// `None` where an edge stays blocked.
    fn refine(&self, path: Vec<JointVector>) -> Option<Vec<JointVector>> {
        let mut refined = vec![path[0]];
        for pair in path.windows(2) {
            self.refine_edge(&pair[0], &pair[1], 6, &mut refined)?;
        }
        Some(refined)
    }

    fn refine_edge(
        &self,
        a: &JointVector,
        b: &JointVector,
        depth: usize,
        out: &mut Vec<JointVector>,
    ) -> Option<()> {
        if self.edge_free(a, b) {
            out.push(*b);
            return Some(());
        }
        let middle = (a + b) / 2.0;
        if depth == 0 || !self.free(&middle) {
            return None;
        }
        self.refine_edge(a, &middle, depth - 1, out)?;
        self.refine_edge(&middle, b, depth - 1, out)
    }

    /// Shortcuts: two vertices drawn from `seed`, joined straight where that edge is free.
    fn shortcut(&self, mut path: Vec<JointVector>, seed: u64) -> Vec<JointVector> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
        for _ in 0..SHORTCUTS {
            if path.len() <= 2 {
                break;
            }
            let i = rng.random_range(0..path.len() - 2);
            let j = rng.random_range(i + 2..path.len());
            if self.edge_free(&path[i], &path[j]) {
                path.drain(i + 1..j);
            }
        }
        path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The smallest distance (m) from any point of `strokes` (every 0.05 mm along them) to the
    /// edges of the rectangle of `surface` (negative outside it).
    fn least_inset(surface: &Task, strokes: &[Path]) -> f64 {
        let corner = |index: usize| match surface.path.as_ref().unwrap().spec().segments[index] {
            SegmentSpec::Line { to } => Vec3::from(to),
            _ => panic!("the rectangle's sides are lines"),
        };
        // Segments 2, 3 and 4 end at the corners (low, high), (low, low) and (high, low).
        let (origin, along_u, along_w) = (corner(3), corner(4) - corner(3), corner(2) - corner(3));
        let (u, w) = (along_u.normalize(), along_w.normalize());
        let mut least = f64::INFINITY;
        for stroke in strokes {
            let samples = (stroke.length_m() / 5e-5).ceil() as usize;
            for k in 0..=samples {
                let offset =
                    stroke.point_at(stroke.length_m() * k as f64 / samples as f64) - origin;
                let (a, b) = (offset.dot(&u), offset.dot(&w));
                least = least
                    .min(a)
                    .min(along_u.norm() - a)
                    .min(b)
                    .min(along_w.norm() - b);
            }
        }
        least
    }

    #[test]
    fn every_stroke_point_lies_at_least_the_round_inside_the_part() {
        let workspace = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let robot = Robot::from_chain_file(workspace.join("data/robots/fr3_pen.urdf")).unwrap();
        let drawing = std::fs::read_to_string(workspace.join("examples/drawing.svg")).unwrap();
        // A polyline and a circle 15 mm across, drawn at 1 mm per unit: the circle's extreme
        // points lie between points a centimetre apart.
        let small_circle = r#"<svg xmlns="http://www.w3.org/2000/svg" width="60" height="30">
            <polyline points="5,5 25,25 40,5" fill="none" stroke="black"/>
            <circle cx="50" cy="15" r="7.5" fill="none" stroke="black"/></svg>"#;
        let at_1mm = emg_io::Placement {
            width_m: None,
            scale_m_per_unit: Some(1e-3),
            ..emg_io::Placement::default()
        };
        for (svg, placement) in [
            (drawing.as_str(), emg_io::Placement::default()),
            (small_circle, at_1mm),
        ] {
            let strokes: Vec<Path> =
                emg_io::read_svg(svg, &placement, &emg_io::SvgOptions::default())
                    .unwrap()
                    .strokes
                    .into_iter()
                    .map(|spec| Path::new(spec).unwrap())
                    .collect();
            let tasks: Vec<Task> = strokes
                .iter()
                .map(|stroke| Task::on_path(&robot, stroke.clone(), None).unwrap())
                .collect();
            let surfaces = part_surfaces(&robot, &tasks);
            assert_eq!(surfaces.len(), 1, "one plane, one part");
            let inset = least_inset(&surfaces[0], &strokes);
            assert!(
                inset >= PART_ROUND_M - 1e-9,
                "a stroke point lies {:.4} mm inside the part's edge, less than {} mm",
                inset * 1e3,
                PART_ROUND_M * 1e3
            );
        }
    }
}
