//! What the checker is given: the task line, the bounds, and a recorded motion, as plain data
//! that any planner (or any file reader) fills in.

use nalgebra::{Matrix3, SVector, Vector3};

/// Most revolute joints of an arm the checker verifies.
pub const MAX_JOINTS: usize = 7;

/// Fewest revolute joints of an arm the checker verifies.
pub const MIN_JOINTS: usize = 6;

/// A joint configuration or joint velocity, one value per revolute joint, base to tip; an arm of
/// six joints leaves the last entry zero.
pub type Joints = SVector<f64, MAX_JOINTS>;

/// The task line: start `p0`, unit direction `d`, unit normal `n` (the tool axis must stay near
/// it); on a path task, also the path's pieces from `p0` (`d` then is its tangent at the start).
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// Start position (m).
    pub p0: Vector3<f64>,
    /// Unit direction of motion.
    pub d: Vector3<f64>,
    /// Unit task-plane normal.
    pub n: Vector3<f64>,
    /// The path's pieces in the order travelled; empty on a straight-line task.
    pub path: Vec<PathPiece>,
}

/// One piece of a path, as plain data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PathPiece {
    /// The segment from `start` to `end`.
    Straight {
        /// Start point (m).
        start: Vector3<f64>,
        /// End point (m).
        end: Vector3<f64>,
    },
    /// The arc from `start` about `centre`, swept by `sweep_rad` about the unit `axis` (right
    /// hand).
    Arc {
        /// Centre of the circle (m).
        centre: Vector3<f64>,
        /// Start point (m).
        start: Vector3<f64>,
        /// Unit rotation axis.
        axis: Vector3<f64>,
        /// Signed angle swept (rad).
        sweep_rad: f64,
    },
}

impl PathPiece {
    /// The unit tangents at the piece's start and end.
    fn end_tangents(&self) -> [Vector3<f64>; 2] {
        match *self {
            Self::Straight { start, end } => [(end - start).normalize(); 2],
            Self::Arc { .. } => {
                let ahead = |length: f64| {
                    let turned = self.point(length) - self.centre();
                    self.axis().cross(&turned).normalize() * self.sweep().signum()
                };
                [ahead(0.0), ahead(self.length())]
            }
        }
    }

    /// An arc's centre, axis and sweep (rad); a straight piece has none.
    fn centre(&self) -> Vector3<f64> {
        match *self {
            Self::Arc { centre, .. } => centre,
            Self::Straight { start, .. } => start,
        }
    }

    /// See [`PathPiece::centre`].
    fn axis(&self) -> Vector3<f64> {
        match *self {
            Self::Arc { axis, .. } => axis,
            Self::Straight { .. } => Vector3::zeros(),
        }
    }

    /// See [`PathPiece::centre`].
    fn sweep(&self) -> f64 {
        match *self {
            Self::Arc { sweep_rad, .. } => sweep_rad,
            Self::Straight { .. } => 0.0,
        }
    }

    /// Length of the piece (m).
    fn length(&self) -> f64 {
        match *self {
            Self::Straight { start, end } => (end - start).norm(),
            Self::Arc {
                centre,
                start,
                sweep_rad,
                ..
            } => (start - centre).norm() * sweep_rad.abs(),
        }
    }

    /// The point `length` (m) along the piece.
    fn point(&self, length: f64) -> Vector3<f64> {
        match *self {
            Self::Straight { start, end } => start + (end - start).normalize() * length,
            Self::Arc {
                centre,
                start,
                axis,
                sweep_rad,
            } => {
                let radius = (start - centre).norm();
                let angle = sweep_rad.signum() * length / radius;
                let r = start - centre;
                // Rodrigues' rotation of `r` about `axis` by `angle`.
                let (sin, cos) = libm::sincos(angle);
                centre + r * cos + axis.cross(&r) * sin + axis * axis.dot(&r) * (1.0 - cos)
            }
        }
    }

    /// The lengths along the piece, each within `[low, high]`, of its point nearest `point` and
    /// of its ends (the window's ends where they lie inside it): on a closed circle, also that
    /// point one turn on (the first `count` entries).
    fn nearest(&self, point: &Vector3<f64>, low: f64, high: f64) -> ([f64; 4], usize) {
        match *self {
            Self::Straight { start, end } => (
                [
                    (point - start)
                        .dot(&(end - start).normalize())
                        .clamp(low, high),
                    low.max(0.0),
                    high.min(self.length()),
                    0.0,
                ],
                3,
            ),
            Self::Arc {
                centre,
                start,
                axis,
                sweep_rad,
            } => {
                let r = start - centre;
                let radius = r.norm();
                let offset = point - centre;
                let turned = axis.cross(&r) * sweep_rad.signum();
                let angle = libm::atan2(offset.dot(&turned), offset.dot(&r));
                let full = std::f64::consts::TAU;
                let angle = if angle < 0.0 { angle + full } else { angle };
                let sweep = sweep_rad.abs();
                // Past the sweep: whichever end lies at the smaller angle.
                let angle = if angle <= sweep {
                    angle
                } else if angle - sweep < full - angle {
                    sweep
                } else {
                    0.0
                };
                // One turn on lies on a closed circle too, and a point just before the start
                // is just before the end: the ends are candidates as well.
                let mut lengths = [angle * radius, 0.0, sweep * radius, 0.0];
                let mut count = 3;
                if angle + full <= sweep {
                    lengths[3] = (angle + full) * radius;
                    count = 4;
                }
                for length in &mut lengths[..count] {
                    *length = length.clamp(low, high);
                }
                (lengths, count)
            }
        }
    }
}

/// How far (m, of arc length) from its last known place along a path the checker looks for a
/// recorded TCP's nearest path point.
pub const PATH_WINDOW_M: f64 = 0.05;

/// What each metre of arc length between a candidate path point and a recorded TCP's last known
/// place adds to the candidate's distance when the checker follows the TCP along a path (m per
/// m): the progress is followed continuously, so that where the path comes back to a point it
/// passed (the start and the end of a closed stroke) the TCP is placed where it came from.
pub const PATH_CONTINUITY: f64 = 0.01;

/// How far (m of arc length per m of distance) a recorded TCP's progress along a path may
/// advance from its last known place `s`, for a TCP at `p`: `PATH_PROGRESS_PER_DISTANCE ·
/// |p − P(s)| +` [`PATH_PROGRESS_SLACK_M`], at most [`PATH_WINDOW_M`]; it never goes back. A
/// TCP that moves along the path keeps its progress (an arc is at most π/2 times its chord up
/// to a half-turn); one near both legs of a reversal, or near a stretch the path comes back
/// over, is measured against the leg it has travelled to, never against the other.
pub const PATH_PROGRESS_PER_DISTANCE: f64 = 1.6;

/// The move of the progress allowed for a TCP exactly at its last known path point (m).
pub const PATH_PROGRESS_SLACK_M: f64 = 1e-5;

/// How near (m of arc length) its last known place must lie to a corner of the path (a join
/// where the tangent turns by more than [`PATH_CORNER_RAD`]) for a recorded TCP's progress to
/// pass it, unless the TCP's nearest path point short of the corner is the corner itself (it
/// stands past it): a TCP that never came to a corner is measured against it.
pub const PATH_CORNER_PASS_M: f64 = 1e-4;

/// Smallest turn (rad) of the tangent between two pieces that makes their join a corner: far
/// above the rounding of a join made tangent (a biarc's, a blend's), far below any corner a
/// drawing holds.
pub const PATH_CORNER_RAD: f64 = 1e-3;

impl Line {
    /// A straight-line task.
    pub fn straight(p0: Vector3<f64>, d: Vector3<f64>, n: Vector3<f64>) -> Self {
        Self {
            p0,
            d,
            n,
            path: Vec::new(),
        }
    }

    /// Lateral distance of `point` from the line (m).
    pub fn lateral_distance(&self, point: &Vector3<f64>) -> f64 {
        let offset = point - self.p0;
        (offset - self.d * offset.dot(&self.d)).norm()
    }

    /// Progress `(point − p0)·d` of `point` along the line (m).
    pub fn progress(&self, point: &Vector3<f64>) -> f64 {
        (point - self.p0).dot(&self.d)
    }

    /// The distance (m) of `point` from the line, or from the nearest point of the path.
    pub fn distance(&self, point: &Vector3<f64>) -> f64 {
        if self.path.is_empty() {
            return self.lateral_distance(point);
        }
        let (s, _) = self.nearest_on_path(point, 0.0, 0.0, f64::INFINITY, 0.0);
        (self.point_on_path(s) - point).norm()
    }

    /// The path's length (m); `None` on a line.
    pub fn path_length(&self) -> Option<f64> {
        (!self.path.is_empty()).then(|| self.path.iter().map(PathPiece::length).sum())
    }

    /// How far `points` (a motion's TCPs in order) get: on a line the last one's progress, on
    /// a path the arc length of its nearest point, followed from the start ([`Line::follow`]).
    pub fn reached(&self, points: impl IntoIterator<Item = Vector3<f64>>) -> f64 {
        self.progresses(points).last().copied().unwrap_or(0.0)
    }

    /// The stretch `points` (a motion's TCPs in order) cover: the least and the greatest of
    /// their progresses as [`Line::reached`] follows them (m); `None` without points.
    pub fn covered(&self, points: impl IntoIterator<Item = Vector3<f64>>) -> Option<(f64, f64)> {
        self.progresses(points).into_iter().fold(None, |span, s| {
            Some(span.map_or((s, s), |(low, high): (f64, f64)| (low.min(s), high.max(s))))
        })
    }

    /// Each point's progress: on a line `(p − p0)·d`, on a path the arc length of its nearest
    /// point, followed from the start ([`Line::follow`]).
    pub(crate) fn progresses(&self, points: impl IntoIterator<Item = Vector3<f64>>) -> Vec<f64> {
        let mut s = 0.0;
        points
            .into_iter()
            .map(|point| {
                s = self.follow(&point, s).0;
                s
            })
            .collect()
    }

    /// Where `point` stands along the task, the point before it having stood at `hint`, and
    /// its distance (m) from the task there: on a line its progress `(p − p0)·d` and lateral
    /// distance; on a path the arc length of its nearest path point within the window the
    /// point's distance from the path point at `hint` allows
    /// ([`PATH_PROGRESS_PER_DISTANCE`]), and the distance from that path point, so that every
    /// point is measured against the stretch of the path it has reached.
    pub fn follow(&self, point: &Vector3<f64>, hint: f64) -> (f64, f64) {
        if self.path.is_empty() {
            return (self.progress(point), self.lateral_distance(point));
        }
        let from_hint = (self.point_on_path(hint) - point).norm();
        let window =
            (PATH_PROGRESS_PER_DISTANCE * from_hint + PATH_PROGRESS_SLACK_M).min(PATH_WINDOW_M);
        let reach = hint + window;
        let mut corner = self.corner_after(hint + PATH_CORNER_PASS_M);
        loop {
            let to = corner.map_or(reach, |corner| corner.min(reach));
            let (s, _) = self.nearest_on_path(point, hint, hint, to, PATH_CONTINUITY);
            // A point whose nearest path point short of the corner is the corner itself stands
            // past it (or at it): it is measured against what follows the corner too.
            match corner {
                Some(at) if s >= at - 1e-9 && at < reach => {
                    corner = self.corner_after(at + PATH_CORNER_PASS_M);
                }
                _ => return (s, (self.point_on_path(s) - point).norm()),
            }
        }
    }

    /// The arc length in `[from, to]` whose path point lies nearest `point`, each metre of arc
    /// length from `hint` adding `continuity` m to its distance, and that distance (with what
    /// was added).
    fn nearest_on_path(
        &self,
        point: &Vector3<f64>,
        hint: f64,
        from: f64,
        to: f64,
        continuity: f64,
    ) -> (f64, f64) {
        let mut best = (hint, f64::INFINITY);
        let mut start = 0.0;
        for piece in &self.path {
            let length = piece.length();
            let low = (from - start).max(0.0);
            let high = (to - start).min(length);
            if low <= high {
                let (candidates, count) = piece.nearest(point, low, high);
                for &along in &candidates[..count] {
                    let cost = (piece.point(along) - point).norm()
                        + continuity * (start + along - hint).abs();
                    if cost < best.1 {
                        best = (start + along, cost);
                    }
                }
            }
            start += length;
        }
        best
    }

    /// The arc length of the first corner of the path after `s`, if any: a join of two pieces
    /// whose tangents differ by more than [`PATH_CORNER_RAD`].
    fn corner_after(&self, s: f64) -> Option<f64> {
        let mut start = 0.0;
        for pair in self.path.windows(2) {
            start += pair[0].length();
            let (before, after) = (pair[0].end_tangents()[1], pair[1].end_tangents()[0]);
            if start > s
                && libm::atan2(before.cross(&after).norm(), before.dot(&after)) > PATH_CORNER_RAD
            {
                return Some(start);
            }
        }
        None
    }

    /// The path point at arc length `s`.
    fn point_on_path(&self, s: f64) -> Vector3<f64> {
        let mut start = 0.0;
        for piece in &self.path {
            let length = piece.length();
            if s <= start + length {
                return piece.point((s - start).max(0.0));
            }
            start += length;
        }
        let last = self.path.last().expect("a path holds a piece");
        last.point(last.length())
    }
}

/// The bounds every recorded point must hold.
#[derive(Clone, Debug, PartialEq)]
pub struct Bounds {
    /// Largest lateral distance of the TCP from the line (m).
    pub line_tolerance_m: f64,
    /// Largest angle between the tool axis and `n` (degrees).
    pub theta_max_deg: f64,
    /// Smallest clearance between checked capsule pairs (m).
    pub collision_margin_m: f64,
    /// Joint speeds stay within this fraction of the robot file's velocity limits; `None` when
    /// joint speeds are not bounded.
    pub velocity_limit_fraction: Option<f64>,
    /// The line's work surface, which every capsule but the tool's stays off; `None` when
    /// there is none.
    pub work_surface: Option<Surface>,
    /// Obstacles every capsule of the arm keeps its distance from.
    pub obstacles: Vec<Obstacle>,
}

/// The part a line is drawn on, its material where `(x − p0)·n > 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface {
    /// Everything beyond the plane through `p0` with normal `n`.
    HalfSpace,
    /// A plate whose top face lies in that plane: from `behind_m` before `p0` to `ahead_m`
    /// beyond it along `d`, `half_width_m` to each side of the line, `thickness_m` deep.
    Plate {
        /// Half the width across the line (m).
        half_width_m: f64,
        /// Extent before `p0`, against `d` (m).
        behind_m: f64,
        /// Extent beyond `p0`, along `d` (m).
        ahead_m: f64,
        /// Depth along `n` (m).
        thickness_m: f64,
    },
}

impl Surface {
    /// The solid of this surface under `line`.
    pub fn solid(&self, line: &Line) -> Solid {
        match *self {
            Self::HalfSpace => Solid::HalfSpace {
                point: line.p0,
                outward: -line.n,
            },
            Self::Plate {
                half_width_m,
                behind_m,
                ahead_m,
                thickness_m,
            } => Solid::Box {
                centre: line.p0
                    + line.d * ((ahead_m - behind_m) / 2.0)
                    + line.n * (thickness_m / 2.0),
                axes: Matrix3::from_columns(&[line.d, line.n.cross(&line.d), line.n]),
                half_extents: Vector3::new(
                    (ahead_m + behind_m) / 2.0,
                    half_width_m,
                    thickness_m / 2.0,
                ),
            },
        }
    }
}

/// A solid in the base frame that the arm must not come near.
#[derive(Clone, Debug, PartialEq)]
pub enum Solid {
    /// The points `x` with `(x − point)·outward < 0`.
    HalfSpace {
        /// A point of the boundary plane (m).
        point: Vector3<f64>,
        /// Unit normal pointing away from the solid.
        outward: Vector3<f64>,
    },
    /// The points `centre + axes·x` with `|x_i| ≤ half_extents_i`; `axes` is a rotation.
    Box {
        /// Centre (m).
        centre: Vector3<f64>,
        /// The box's axes as columns.
        axes: Matrix3<f64>,
        /// Half edge lengths (m).
        half_extents: Vector3<f64>,
    },
    /// The points within `radius` of `centre`.
    Ball {
        /// Centre (m).
        centre: Vector3<f64>,
        /// Radius (m).
        radius: f64,
    },
    /// The points within `radius` of the segment `a`–`b`.
    Capsule {
        /// First end of the axis (m).
        a: Vector3<f64>,
        /// Second end of the axis (m).
        b: Vector3<f64>,
        /// Radius (m).
        radius: f64,
    },
}

/// A named solid and the distance every capsule of the arm keeps from it.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// Name used in failures.
    pub name: String,
    /// The solid.
    pub solid: Solid,
    /// Smallest allowed surface distance (m).
    pub clearance_m: f64,
    /// Whether the tool's capsules may touch it (the part the tool works on).
    pub tool_may_touch: bool,
}

/// One recorded point of a motion, with what the planner says it measured there.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordedStep {
    /// Time since the start (s).
    pub time_s: f64,
    /// Joint configuration (rad).
    pub q: Joints,
    /// TCP position the planner recorded (m).
    pub tcp: Vector3<f64>,
    /// Angle between the tool axis and `n` the planner recorded (degrees).
    pub tool_angle_deg: f64,
}

/// A constraint a planner blames for the end of a motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blame {
    /// Joint `joint` (1-based) left its position limits.
    JointLimit {
        /// 1-based joint number.
        joint: usize,
    },
    /// The TCP left the line tolerance.
    LineTolerance,
    /// The tool axis left the cone around `n`.
    ToolCone,
    /// Two capsules of the arm touch.
    SelfCollision,
    /// A capsule of the arm came too near an obstacle or the work surface.
    SceneContact,
}

/// Why a recorded motion ended, as its planner claims.
#[derive(Clone, Debug, PartialEq)]
pub enum Ending {
    /// The next configuration `rejected_q` breaks `blame`, so it was not taken.
    Rejected {
        /// The constraint blamed.
        blame: Blame,
        /// The configuration that was not taken.
        rejected_q: Joints,
    },
    /// The first configuration already breaks `blame`; the motion holds only that point.
    InvalidStart {
        /// The constraint blamed.
        blame: Blame,
    },
    /// The planner stopped with every constraint held (a step cap, or a file of points that
    /// says nothing about why the motion ended).
    Stopped,
    /// The tool reached the end of its path (path tasks only).
    Completed,
}

/// A recorded motion: its points, why it ended and the length it reports.
#[derive(Clone, Debug, PartialEq)]
pub struct Recording {
    /// The points, the start first.
    pub steps: Vec<RecordedStep>,
    /// Why it ended.
    pub ending: Ending,
    /// The reported path length `(p_last − p0)·d` (m); on a path, the arc length reached.
    pub path_length_m: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two straight legs of 10 mm from the origin along x, then turning by `turn` (rad).
    fn corner(turn: f64) -> Line {
        let x = Vector3::x();
        let bend = Vector3::new(libm::cos(turn), libm::sin(turn), 0.0);
        let at = x * 0.01;
        Line {
            p0: Vector3::zeros(),
            d: x,
            n: Vector3::z(),
            path: vec![
                PathPiece::Straight {
                    start: Vector3::zeros(),
                    end: at,
                },
                PathPiece::Straight {
                    start: at,
                    end: at + bend * 0.01,
                },
            ],
        }
    }

    /// Each point's progress and distance, followed from the start.
    fn followed(line: &Line, points: &[Vector3<f64>]) -> Vec<(f64, f64)> {
        let mut hint = 0.0;
        points
            .iter()
            .map(|p| {
                let (s, distance) = line.follow(p, hint);
                hint = s;
                (s, distance)
            })
            .collect()
    }

    #[test]
    fn a_point_past_a_corner_is_measured_against_what_follows_it() {
        // A right-angle corner at (10, 0) mm; the TCP 0.15 mm short of it (farther than
        // PATH_CORNER_PASS_M), then at (10.2, 0.3) mm: past the corner, 0.2 mm from the second
        // leg, 0.36 mm from the corner point.
        let line = corner(std::f64::consts::FRAC_PI_2);
        let points = [
            Vector3::new(0.005, 0.0, 0.0),
            Vector3::new(0.00985, 0.0, 0.0),
            Vector3::new(0.0102, 0.0003, 0.0),
            Vector3::new(0.01, 0.001, 0.0),
        ];
        let followed = followed(&line, &points);
        assert!((followed[1].0 - 0.00985).abs() < 1e-12);
        let (s, distance) = followed[2];
        assert!((s - 0.0103).abs() < 1e-9, "{s}");
        assert!((distance - 2e-4).abs() < 1e-9, "{distance}");
        assert!((followed[3].0 - 0.011).abs() < 1e-9);
        // Short of the corner's foot, it is measured against the first leg.
        let (s, distance) = line.follow(&Vector3::new(0.0099, 0.0003, 0.0), 0.00985);
        assert!((s - 0.0099).abs() < 1e-9 && (distance - 3e-4).abs() < 1e-9);
    }

    #[test]
    fn a_reversal_turned_back_short_of_its_vertex_is_not_passed() {
        // Legs turning back by 173°, the TCP along the first leg to 4.65 mm short of the
        // vertex and back along the second leg's side: it never passes the vertex, and is
        // measured against the first leg (farther and farther) as it comes back.
        let line = corner(173f64.to_radians());
        let mut points: Vec<Vector3<f64>> =
            (0..=18).map(|i| Vector3::x() * (i as f64 * 3e-4)).collect();
        let back = Vector3::new(
            libm::cos(173f64.to_radians()),
            libm::sin(173f64.to_radians()),
            0.0,
        );
        let turn = Vector3::x() * 0.00535;
        points.extend((1..=20).map(|i| turn + back * (i as f64 * 3e-4)));
        let followed = followed(&line, &points);
        assert!(followed.iter().all(|(s, _)| *s < 0.0054));
        assert!(followed.last().unwrap().1 > 0.5e-3);
    }
}
