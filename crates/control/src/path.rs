//! Paths on a work surface: a start point and a sequence of straight and circular segments in
//! the plane through it normal to `n`, parameterised by arc length `s`.
//!
//! A path is given as a [`PathSpec`] (the JSON path format, docs/paths.md) and validated into a
//! [`Path`]: every segment starts where the one before it ends, lies in the plane through the
//! start normal to `n`, and is longer than [`MIN_SEGMENT_M`]; a corner between two segments,
//! straight or circular, may be rounded by a blend arc of the radius the spec gives, tangent to
//! both. A straight line is the one-segment path.

use std::cell::Cell;
use std::f64::consts::PI;

use emg_kinematics::Vec3;
use serde::{Deserialize, Serialize};

mod bounds;
use bounds::{Ball, PieceTree};

/// The version of the path format this build reads and writes.
pub const PATH_FORMAT_VERSION: u32 = 1;

/// Shortest segment (m) a path may hold.
pub const MIN_SEGMENT_M: f64 = 1e-4;

/// Largest distance (m) of a given point from the plane through the start normal to `n`.
pub const PLANE_TOLERANCE_M: f64 = 1e-6;

/// Smallest turn (rad) between the tangents of two segments that counts as a corner; a
/// smaller one is passed as if smooth.
pub const CORNER_RAD: f64 = 1e-6;

/// A path as written in a path file: its start, the surface normal and the segments in the
/// order travelled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathSpec {
    /// The path format version ([`PATH_FORMAT_VERSION`]).
    pub version: u32,
    /// Start point (m).
    pub start: [f64; 3],
    /// Normal `n` of the work surface; the tool axis stays within the cone around it.
    pub normal: [f64; 3],
    /// Radius (m) of the arcs that round the corners between segments (tangent to both); 0
    /// passes every corner at rest.
    #[serde(default)]
    pub blend_radius_m: f64,
    /// The segments, each starting where the one before it ends.
    pub segments: Vec<SegmentSpec>,
}

/// One segment of a [`PathSpec`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum SegmentSpec {
    /// A straight segment to `to`.
    Line {
        /// End point (m).
        to: [f64; 3],
    },
    /// A circular arc, given as a circular motion command takes it: by its `centre` and its end
    /// `to` (the shorter way round), by its `centre` and its signed `sweep_deg` about `n`
    /// (counter-clockwise seen from where `n` points; a full circle is ±360), or by a point
    /// `through` which it passes on its way to `to`.
    Arc {
        /// Centre of the circle (m).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        centre: Option<[f64; 3]>,
        /// A point the arc passes through between its start and `to` (m).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        through: Option<[f64; 3]>,
        /// End point (m).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        to: Option<[f64; 3]>,
        /// Signed angle swept about `n` (degrees).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        sweep_deg: Option<f64>,
    },
}

impl PathSpec {
    /// The path moved rigidly by `motion` (points transformed, the normal turned; a signed
    /// sweep keeps its sense, which turns with the normal).
    pub fn moved(&self, motion: &nalgebra::Isometry3<f64>) -> Self {
        let point = |p: &[f64; 3]| -> [f64; 3] {
            (motion * nalgebra::Point3::from(Vec3::from(*p)))
                .coords
                .into()
        };
        Self {
            version: self.version,
            start: point(&self.start),
            normal: (motion.rotation * Vec3::from(self.normal)).into(),
            blend_radius_m: self.blend_radius_m,
            segments: self
                .segments
                .iter()
                .map(|segment| match segment {
                    SegmentSpec::Line { to } => SegmentSpec::Line { to: point(to) },
                    SegmentSpec::Arc {
                        centre,
                        through,
                        to,
                        sweep_deg,
                    } => SegmentSpec::Arc {
                        centre: centre.as_ref().map(point),
                        through: through.as_ref().map(point),
                        to: to.as_ref().map(point),
                        sweep_deg: *sweep_deg,
                    },
                })
                .collect(),
        }
    }
}

/// The arc segment about `centre` of `length_m` on a circle of `radius_m`, turning the way the
/// sign of `turn` says; a whole circle's sweep, recomputed from its length, may round past 360°
/// and is held at it.
fn arc_of_length(centre: Vec3, turn: f64, length_m: f64, radius_m: f64) -> SegmentSpec {
    SegmentSpec::Arc {
        centre: Some(centre.into()),
        through: None,
        to: None,
        sweep_deg: Some(turn.signum() * (length_m / radius_m).to_degrees().min(360.0)),
    }
}

/// Why a path was refused; names the field and what is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PathError {
    /// The file is of another format version.
    #[error("path field 'version' is {found}; this build reads version {PATH_FORMAT_VERSION}")]
    Version {
        /// The version given.
        found: u32,
    },
    /// A field is malformed: what is wrong with it.
    #[error("path field '{field}' {problem}")]
    Field {
        /// The field, e.g. `segments[2].arc.to`.
        field: String,
        /// What is wrong.
        problem: String,
    },
}

impl PathError {
    fn field(field: impl Into<String>, problem: impl Into<String>) -> Self {
        Self::Field {
            field: field.into(),
            problem: problem.into(),
        }
    }
}

/// A straight piece of a path.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Straight {
    start: Vec3,
    direction: Vec3,
}

/// A circular piece of a path: `centre + r (u cos(σ/r) + w sin(σ/r))` for `σ ∈ [0, length]`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Circular {
    centre: Vec3,
    radius_m: f64,
    /// Unit vector from the centre to the start.
    u: Vec3,
    /// Unit direction of travel at the start (`±n × u`).
    w: Vec3,
}

/// The shape of one piece.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    Straight(Straight),
    Circular(Circular),
}

/// One piece of a validated path: its shape, its length and where along the path it starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    shape: Shape,
    /// Arc length of the path where the piece starts (m).
    pub start_s: f64,
    /// The piece's length (m).
    pub length_m: f64,
    /// Whether the tool must come to rest where the piece starts: its tangent turns there.
    pub corner_before: bool,
}

impl Piece {
    /// The ball around the piece's middle holding all of it ([`Ball::of_curve`]).
    fn ball(&self) -> Ball {
        Ball::of_curve(self.point(0.5 * self.length_m), self.length_m)
    }

    /// The piece's start and end points, and for an arc its centre and the unit axis it turns
    /// about (right hand).
    pub fn outline(&self) -> (Vec3, Vec3, Option<(Vec3, Vec3)>) {
        let arc = match self.shape {
            Shape::Straight(_) => None,
            Shape::Circular(arc) => Some((arc.centre, arc.u.cross(&arc.w))),
        };
        (self.point(0.0), self.point(self.length_m), arc)
    }

    /// The smallest and largest `x·direction` over the piece's points `x`.
    fn range_along(&self, direction: &Vec3) -> (f64, f64) {
        let ends = [self.point(0.0), self.point(self.length_m)].map(|p| p.dot(direction));
        let (mut low, mut high) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
        if let Shape::Circular(arc) = self.shape {
            // `x·v = c·v + r (u·v cos φ + w·v sin φ)` is extreme at `φ*` and `φ* + π`.
            let extreme = libm::atan2(direction.dot(&arc.w), direction.dot(&arc.u));
            let sweep = self.length_m / arc.radius_m;
            for angle in [extreme, extreme + PI] {
                let angle = angle.rem_euclid(2.0 * PI);
                if angle <= sweep {
                    let value = self.point(angle * arc.radius_m).dot(direction);
                    low = low.min(value);
                    high = high.max(value);
                }
            }
        }
        (low, high)
    }

    /// The shape of the piece's part from `σ` (m) on.
    fn from(&self, sigma: f64) -> Shape {
        match self.shape {
            Shape::Straight(line) => Shape::Straight(Straight {
                start: line.start + line.direction * sigma,
                direction: line.direction,
            }),
            Shape::Circular(arc) => Shape::Circular(Circular {
                u: (self.point(sigma) - arc.centre) / arc.radius_m,
                w: self.tangent(sigma),
                ..arc
            }),
        }
    }

    /// The point at `σ` (m) along the piece.
    fn point(&self, sigma: f64) -> Vec3 {
        match self.shape {
            Shape::Straight(line) => line.start + line.direction * sigma,
            Shape::Circular(arc) => {
                let angle = sigma / arc.radius_m;
                let (sin, cos) = libm::sincos(angle);
                arc.centre + (arc.u * cos + arc.w * sin) * arc.radius_m
            }
        }
    }

    /// The unit tangent at `σ` (m) along the piece.
    fn tangent(&self, sigma: f64) -> Vec3 {
        match self.shape {
            Shape::Straight(line) => line.direction,
            Shape::Circular(arc) => {
                let angle = sigma / arc.radius_m;
                let (sin, cos) = libm::sincos(angle);
                arc.w * cos - arc.u * sin
            }
        }
    }

    /// The `σ ∈ [0, length]` of the piece's point nearest `p`.
    fn nearest(&self, p: &Vec3) -> f64 {
        let sigma = match self.shape {
            Shape::Straight(line) => (p - line.start).dot(&line.direction),
            Shape::Circular(arc) => {
                let offset = p - arc.centre;
                let angle = libm::atan2(offset.dot(&arc.w), offset.dot(&arc.u));
                let sweep = self.length_m / arc.radius_m;
                // Angles past the sweep are nearer one end or the other.
                let angle = if angle < 0.0 && angle + 2.0 * PI <= sweep {
                    angle + 2.0 * PI
                } else if angle < 0.0 || angle > sweep {
                    let beyond_end = angle.rem_euclid(2.0 * PI) - sweep;
                    let before_start = 2.0 * PI - angle.rem_euclid(2.0 * PI);
                    if beyond_end <= before_start {
                        sweep
                    } else {
                        0.0
                    }
                } else {
                    angle
                };
                angle * arc.radius_m
            }
        };
        sigma.clamp(0.0, self.length_m)
    }
}

/// What a metre of arc length between a candidate point and the last known progress adds to
/// the candidate's distance from the TCP when [`Path::locate`] picks the nearest path point (m
/// per m). Of points equally near the TCP (the start and the end of a closed stroke, where the
/// tool stands before it moves) the one the TCP came along wins; points whose distances differ
/// by more than a hundredth of their arc-length gap rank as by distance alone.
pub const PROGRESS_CONTINUITY: f64 = 1e-2;

/// Where a point lies relative to a path: the nearest path point in the window searched.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Located {
    /// Arc length of the nearest point (m).
    pub s: f64,
    /// The nearest point.
    pub point: Vec3,
    /// Unit tangent there.
    pub tangent: Vec3,
}

/// How far a path reaches from its start in the surface, in the frame of its start tangent
/// `d` and `n × d`: the extent a work plate must cover.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathExtent {
    /// Farthest reach against `d` (m, ≥ 0).
    pub behind_m: f64,
    /// Farthest reach along `d` (m, ≥ 0).
    pub ahead_m: f64,
    /// Farthest reach to either side, along `±(n × d)` (m, ≥ 0).
    pub across_m: f64,
}

/// A validated path (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "PathSpec", into = "PathSpec")]
pub struct Path {
    spec: PathSpec,
    normal: Vec3,
    pieces: Vec<Piece>,
    /// The ball around each piece ([`Piece::ball`]), for [`Path::locate`].
    balls: Vec<Ball>,
    /// Balls bounding runs of the pieces, for [`Path::nearest_point`].
    tree: PieceTree,
    /// Arc lengths of the corners (the starts of pieces with `corner_before`), increasing.
    corners_m: Vec<f64>,
    length_m: f64,
    extent: PathExtent,
}

impl TryFrom<PathSpec> for Path {
    type Error = PathError;

    fn try_from(spec: PathSpec) -> Result<Self, PathError> {
        Path::new(spec)
    }
}

impl From<Path> for PathSpec {
    fn from(path: Path) -> Self {
        path.spec
    }
}

impl Path {
    /// Validates `spec` (see the module documentation); errors name the field.
    pub fn new(spec: PathSpec) -> Result<Self, PathError> {
        if spec.version != PATH_FORMAT_VERSION {
            return Err(PathError::Version {
                found: spec.version,
            });
        }
        let start = point("start", spec.start)?;
        let normal = point("normal", spec.normal)?;
        if normal.norm() < 1e-9 {
            return Err(PathError::field(
                "normal",
                "is a zero vector; it must be a direction",
            ));
        }
        let normal = normal.normalize();
        let blend = spec.blend_radius_m;
        if !blend.is_finite() || blend < 0.0 {
            return Err(PathError::field(
                "blend_radius_m",
                format!("is {blend}; it must be 0 or more"),
            ));
        }
        if spec.segments.is_empty() {
            return Err(PathError::field(
                "segments",
                "is empty; a path needs a segment",
            ));
        }
        let in_plane = |field: String, p: Vec3| {
            let height = (p - start).dot(&normal);
            if height.abs() > PLANE_TOLERANCE_M {
                Err(PathError::field(
                    field,
                    format!(
                        "lies {height:.3e} m off the plane through 'start' normal to 'normal' \
                         (at most {PLANE_TOLERANCE_M:e})"
                    ),
                ))
            } else {
                Ok(p - normal * height)
            }
        };
        let mut shapes: Vec<(Shape, f64)> = Vec::new();
        let mut at = start;
        for (index, segment) in spec.segments.iter().enumerate() {
            let name = |field: &str| format!("segments[{index}].{field}");
            let (shape, length) = match segment {
                SegmentSpec::Line { to } => {
                    let to = in_plane(name("line.to"), point(&name("line.to"), *to)?)?;
                    let length = (to - at).norm();
                    if length < MIN_SEGMENT_M {
                        return Err(zero_length(name("line.to"), length));
                    }
                    let direction = (to - at) / length;
                    (
                        Shape::Straight(Straight {
                            start: at,
                            direction,
                        }),
                        length,
                    )
                }
                SegmentSpec::Arc {
                    centre,
                    through,
                    to,
                    sweep_deg,
                } => arc(
                    &name, at, normal, *centre, *through, *to, *sweep_deg, &in_plane,
                )?,
            };
            at = end_of(&shape, length);
            shapes.push((shape, length));
        }
        let pieces = blended(shapes, normal, blend)?;
        let length_m = pieces.last().map_or(0.0, |p| p.start_s + p.length_m);
        let balls: Vec<Ball> = pieces.iter().map(Piece::ball).collect();
        let corners_m = pieces
            .iter()
            .filter(|piece| piece.corner_before)
            .map(|piece| piece.start_s)
            .collect();
        let mut path = Self {
            spec,
            normal,
            pieces,
            tree: PieceTree::new(&balls),
            balls,
            corners_m,
            length_m,
            extent: PathExtent {
                behind_m: 0.0,
                ahead_m: 0.0,
                across_m: 0.0,
            },
        };
        path.extent = path.measured_extent();
        Ok(path)
    }

    /// The path's extent: each piece's range along `d` and across it (exact for arcs).
    fn measured_extent(&self) -> PathExtent {
        let start = self.point_at(0.0);
        let d = self.tangent_at(0.0);
        let across = self.normal.cross(&d);
        let range = |direction: &Vec3| {
            self.pieces
                .iter()
                .map(|piece| piece.range_along(direction))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(low, high), (l, h)| {
                    (low.min(l), high.max(h))
                })
        };
        let (back, ahead) = range(&d);
        let (left, right) = range(&across);
        PathExtent {
            behind_m: (start.dot(&d) - back).max(0.0),
            ahead_m: (ahead - start.dot(&d)).max(0.0),
            across_m: (start.dot(&across) - left)
                .max(right - start.dot(&across))
                .max(0.0),
        }
    }

    /// How far the path reaches from its start ([`PathExtent`]).
    pub fn extent(&self) -> PathExtent {
        self.extent
    }

    /// A straight path from `start` along the unit direction `direction` for `length_m`, on the
    /// surface of normal `normal` (perpendicular to `direction`).
    pub fn straight(
        start: Vec3,
        direction: Vec3,
        normal: Vec3,
        length_m: f64,
    ) -> Result<Self, PathError> {
        let to = start + direction * length_m;
        Self::new(PathSpec {
            version: PATH_FORMAT_VERSION,
            start: start.into(),
            normal: normal.into(),
            blend_radius_m: 0.0,
            segments: vec![SegmentSpec::Line { to: to.into() }],
        })
    }

    /// Whether the path ends where it starts (within [`MIN_SEGMENT_M`]): a closed stroke, which
    /// may be started anywhere on it ([`Path::started_at`]).
    pub fn is_closed(&self) -> bool {
        (self.point_at(self.length_m) - self.point_at(0.0)).norm() <= MIN_SEGMENT_M
    }

    /// The closed path started at arc length `s`: its stretch from `s` to its end, then from
    /// its start to `s` ([`Path::joined`], moved by the closing gap); `None` where the path is
    /// not closed or either stretch holds less than [`MIN_SEGMENT_M`].
    pub fn started_at(&self, s: f64) -> Option<Self> {
        if !self.is_closed() {
            return None;
        }
        self.stretch(s, self.length_m)?
            .joined(&self.stretch(0.0, s)?)
    }

    /// The stretch of the path from arc length `from_s` to `to_s` (clamped to it), its pieces,
    /// blends included, as segments of their own (no blend radius: a blend is already an arc
    /// tangent to its neighbours); `None` where it holds less than [`MIN_SEGMENT_M`].
    pub fn stretch(&self, from_s: f64, to_s: f64) -> Option<Self> {
        let (from_s, to_s) = (from_s.max(0.0), to_s.min(self.length_m));
        let mut segments = Vec::new();
        let mut start = None;
        for piece in &self.pieces {
            let begin = from_s.max(piece.start_s);
            let end = to_s.min(piece.start_s + piece.length_m);
            if end - begin < MIN_SEGMENT_M {
                continue;
            }
            let from = piece.point(begin - piece.start_s);
            let to = piece.point(end - piece.start_s);
            start.get_or_insert(from);
            segments.push(match piece.outline().2 {
                None => SegmentSpec::Line { to: to.into() },
                Some((centre, axis)) => {
                    let turn = if axis.dot(&self.normal) >= 0.0 {
                        1.0
                    } else {
                        -1.0
                    };
                    arc_of_length(centre, turn, end - begin, (from - centre).norm())
                }
            });
        }
        Self::new(PathSpec {
            version: PATH_FORMAT_VERSION,
            start: start?.into(),
            normal: self.normal.into(),
            blend_radius_m: 0.0,
            segments,
        })
        .ok()
    }

    /// The same path travelled from its end to its start (its pieces as segments of their own,
    /// as [`Path::stretch`] gives them); `None` where a piece, a short blend, is shorter than a
    /// segment may be.
    pub fn reversed(&self) -> Option<Self> {
        let mut segments = Vec::new();
        for piece in self.pieces.iter().rev() {
            let (from, to, arc) = piece.outline();
            segments.push(match arc {
                None => SegmentSpec::Line { to: from.into() },
                Some((centre, axis)) => {
                    let turn = if axis.dot(&self.normal) >= 0.0 {
                        -1.0
                    } else {
                        1.0
                    };
                    arc_of_length(centre, turn, piece.length_m, (to - centre).norm())
                }
            });
        }
        Self::new(PathSpec {
            version: PATH_FORMAT_VERSION,
            start: self.point_at(self.length_m).into(),
            normal: self.normal.into(),
            blend_radius_m: 0.0,
            segments,
        })
        .ok()
    }

    /// This path, then `next` moved by the gap from its start to this path's end, as one path:
    /// each piece of both a segment of its own (as [`Path::stretch`] gives them), so every point
    /// of `next` lies on the joined path moved by that gap and its length is the sum of both.
    /// `None` where their normals differ or a piece, a short blend, is shorter than a segment
    /// may be.
    pub fn joined(&self, next: &Path) -> Option<Self> {
        if self.normal.dot(&next.normal) < 1.0 - 1e-12 {
            return None;
        }
        let gap = self.point_at(self.length_m) - next.point_at(0.0);
        let segments = self
            .pieces
            .iter()
            .map(|piece| self.piece_segment(piece, Vec3::zeros()))
            .chain(
                next.pieces
                    .iter()
                    .map(|piece| next.piece_segment(piece, gap)),
            )
            .collect::<Option<Vec<_>>>()?;
        Self::new(PathSpec {
            version: PATH_FORMAT_VERSION,
            start: self.point_at(0.0).into(),
            normal: self.normal.into(),
            blend_radius_m: 0.0,
            segments,
        })
        .ok()
    }

    /// `piece`, one of this path's, as a segment moved by `offset`; `None` where it is shorter
    /// than [`MIN_SEGMENT_M`].
    fn piece_segment(&self, piece: &Piece, offset: Vec3) -> Option<SegmentSpec> {
        if piece.length_m < MIN_SEGMENT_M {
            return None;
        }
        let (from, to, arc) = piece.outline();
        Some(match arc {
            None => SegmentSpec::Line {
                to: (to + offset).into(),
            },
            Some((centre, axis)) => {
                let turn = if axis.dot(&self.normal) >= 0.0 {
                    1.0
                } else {
                    -1.0
                };
                arc_of_length(
                    centre + offset,
                    turn,
                    piece.length_m,
                    (from - centre).norm(),
                )
            }
        })
    }

    /// The spec the path was validated from.
    pub fn spec(&self) -> &PathSpec {
        &self.spec
    }

    /// The unit surface normal `n`.
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// The path's length (m).
    pub fn length_m(&self) -> f64 {
        self.length_m
    }

    /// The pieces in the order travelled (segments and blend arcs).
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// The arc lengths (m) at which the tool must come to rest: the corners left unblended.
    pub fn corners_m(&self) -> impl Iterator<Item = f64> + '_ {
        self.corners_m.iter().copied()
    }

    /// The first corner (m) after `s`, if any (by bisection).
    pub fn next_corner_m(&self, s: f64) -> Option<f64> {
        let after = self.corners_m.partition_point(|&corner| corner <= s);
        self.corners_m.get(after).copied()
    }

    /// The point at arc length `s` (clamped to the path).
    pub fn point_at(&self, s: f64) -> Vec3 {
        let (piece, sigma) = self.piece_at(s);
        piece.point(sigma)
    }

    /// The unit tangent at arc length `s` (clamped to the path); at a corner, the tangent of
    /// the piece that starts there.
    pub fn tangent_at(&self, s: f64) -> Vec3 {
        let (piece, sigma) = self.piece_at(s);
        piece.tangent(sigma)
    }

    /// The piece holding arc length `s` (the last one starting at or before it, by bisection:
    /// the pieces lie in order along the path) and how far into it `s` lies.
    fn piece_at(&self, s: f64) -> (&Piece, f64) {
        let s = s.clamp(0.0, self.length_m);
        let index = self
            .pieces
            .partition_point(|piece| piece.start_s <= s)
            .saturating_sub(1);
        let piece = &self.pieces[index];
        (piece, (s - piece.start_s).min(piece.length_m))
    }

    /// The point of the path nearest `p` among those from `s_hint` to `window_m` of arc length
    /// beyond it, each metre of arc length away from `s_hint` counting as
    /// [`PROGRESS_CONTINUITY`] m of distance: the path's progress is followed locally,
    /// continuously and never back, so that a path passing near itself (a full circle at its
    /// start, the two ends of a closed stroke, the legs of a reversal) is never taken for its
    /// other part.
    pub fn locate(&self, p: &Vec3, s_hint: f64, window_m: f64) -> Located {
        let low = s_hint.clamp(0.0, self.length_m);
        let high = (s_hint + window_m).min(self.length_m);
        self.nearest_between(p, s_hint, low, high)
            .unwrap_or_else(|| self.located(s_hint.clamp(0.0, self.length_m)))
    }

    /// The point of the whole path nearest `p` (of equally near ones the first along the
    /// path): the pieces looked at are those whose bounding balls ([`bounds`]) come nearer
    /// `p` than the nearest point found so far, so a long path costs few.
    pub fn nearest_point(&self, p: &Vec3) -> Located {
        let best: Cell<Option<(f64, f64)>> = Cell::new(None);
        self.tree.visit(
            p,
            &|| best.get().map_or(f64::INFINITY, |(_, cost)| cost),
            &mut |k| {
                let mut found = best.get();
                self.consider(k, p, 0.0, self.length_m, &|_| 0.0, &mut found);
                best.set(found);
            },
        );
        let (s, _) = best.get().expect("a path has a piece");
        self.located(s)
    }

    /// The point at arc length within `[low, high]` whose distance from `p` plus
    /// [`PROGRESS_CONTINUITY`] times its arc length's distance from `s_hint` is least (of equal
    /// ones the first along the path); `None` where no piece reaches into the range.
    ///
    /// The pieces are visited outward from the one holding `s_hint`. A side ends where the
    /// progress cost alone exceeds the least cost found, and a piece is passed over where its
    /// bounding ball's distance from `p` plus its progress cost does: neither can hold a point
    /// as cheap, so the result is that of looking at every piece in the range, at the cost of
    /// the few near `s_hint`.
    fn nearest_between(&self, p: &Vec3, s_hint: f64, low: f64, high: f64) -> Option<Located> {
        let progress_cost = |s: f64| PROGRESS_CONTINUITY * (s - s_hint).abs();
        let mut best: Option<(f64, f64)> = None;
        // Whether a point costing at least `cost` is dearer than the best (with a margin for
        // the rounding of the bounds).
        let dearer = |best: &Option<(f64, f64)>, cost: f64| {
            best.is_some_and(|(_, least)| cost > least * (1.0 + 1e-9) + 1e-12)
        };
        let look = |k: usize, best: &mut Option<(f64, f64)>| {
            let piece = &self.pieces[k];
            let (start, end) = (piece.start_s, piece.start_s + piece.length_m);
            let gap_cost = PROGRESS_CONTINUITY * (start - s_hint).max(s_hint - end).max(0.0);
            if dearer(best, gap_cost) {
                return false;
            }
            if !dearer(best, self.balls[k].distance_below(p) + gap_cost) {
                self.consider(k, p, low, high, &progress_cost, best);
            }
            true
        };
        // The pieces lie in order along the path: the one holding `s_hint` is found by
        // bisection, those after it go on until one starts after `high`, those before it
        // until one ends before `low`.
        let middle = self
            .pieces
            .partition_point(|piece| piece.start_s <= s_hint.clamp(low, high))
            .saturating_sub(1);
        for k in middle..self.pieces.len() {
            if self.pieces[k].start_s > high || !look(k, &mut best) {
                break;
            }
        }
        for k in (0..middle).rev() {
            let piece = &self.pieces[k];
            if piece.start_s + piece.length_m < low || !look(k, &mut best) {
                break;
            }
        }
        best.map(|(s, _)| self.located(s))
    }

    /// Lowers `best` (arc length, cost) to piece `k`'s point nearest `p` within `[low, high]`
    /// where its distance plus `extra_cost` is less, or as much at a smaller arc length.
    fn consider(
        &self,
        k: usize,
        p: &Vec3,
        low: f64,
        high: f64,
        extra_cost: &dyn Fn(f64) -> f64,
        best: &mut Option<(f64, f64)>,
    ) {
        let piece = &self.pieces[k];
        // On a closed circle the nearest angle is also one turn further or back, and a
        // point just before the start is just before the end: the ends are candidates too.
        let turn = match piece.shape {
            Shape::Straight(_) => f64::INFINITY,
            Shape::Circular(arc) => 2.0 * PI * arc.radius_m,
        };
        let sigma = piece.nearest(p);
        for sigma in [sigma, sigma - turn, sigma + turn, 0.0, piece.length_m] {
            if !(0.0..=piece.length_m).contains(&sigma) {
                continue;
            }
            let s = (piece.start_s + sigma).clamp(low, high);
            let cost = (self.point_near(k, s) - p).norm() + extra_cost(s);
            if best.is_none_or(|(best_s, c)| cost < c || (cost == c && s < best_s)) {
                *best = Some((s, cost));
            }
        }
    }

    /// [`Path::point_at`] of an `s` on the path that is likely held by piece `k` or begins the
    /// next: taken from the piece [`Path::piece_at`] would find where it is one of those two,
    /// which saves the bisection.
    fn point_near(&self, k: usize, s: f64) -> Vec3 {
        let start_of = |j: usize| {
            self.pieces
                .get(j)
                .map_or(f64::INFINITY, |piece| piece.start_s)
        };
        if s <= self.length_m
            && let Some(j) = (k..k + 2).find(|&j| (start_of(j)..start_of(j + 1)).contains(&s))
        {
            let piece = &self.pieces[j];
            piece.point((s - piece.start_s).min(piece.length_m))
        } else {
            self.point_at(s)
        }
    }

    /// The path point at arc length `s` with its tangent.
    fn located(&self, s: f64) -> Located {
        Located {
            s,
            point: self.point_at(s),
            tangent: self.tangent_at(s),
        }
    }
}

fn zero_length(field: String, length: f64) -> PathError {
    PathError::field(
        field,
        format!("makes a segment {length:.3e} m long; the shortest allowed is {MIN_SEGMENT_M:e} m"),
    )
}

/// A finite point or vector from a path file.
fn point(field: &str, values: [f64; 3]) -> Result<Vec3, PathError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(Vec3::from(values))
    } else {
        Err(PathError::field(
            field,
            format!("is not finite: {values:?}"),
        ))
    }
}

/// The end point of a piece of `length`.
fn end_of(shape: &Shape, length: f64) -> Vec3 {
    Piece {
        shape: *shape,
        start_s: 0.0,
        length_m: length,
        corner_before: false,
    }
    .point(length)
}

/// A circular segment from `at` in one of the three forms of [`SegmentSpec::Arc`].
#[allow(clippy::too_many_arguments)]
fn arc(
    name: &dyn Fn(&str) -> String,
    at: Vec3,
    normal: Vec3,
    centre: Option<[f64; 3]>,
    through: Option<[f64; 3]>,
    to: Option<[f64; 3]>,
    sweep_deg: Option<f64>,
    in_plane: &dyn Fn(String, Vec3) -> Result<Vec3, PathError>,
) -> Result<(Shape, f64), PathError> {
    let given = |field: &str, value: Option<[f64; 3]>| -> Result<Option<Vec3>, PathError> {
        value
            .map(|v| in_plane(name(field), point(&name(field), v)?))
            .transpose()
    };
    let centre = given("arc.centre", centre)?;
    let through = given("arc.through", through)?;
    let to = given("arc.to", to)?;
    let forms = "an arc takes 'centre' and 'to', 'centre' and 'sweep_deg', or 'through' and 'to'";
    // The centre and the signed sweep about `n` of each form.
    let (centre, sweep) = match (centre, through, to, sweep_deg) {
        (Some(centre), None, Some(to), None) => {
            let (u, v) = (at - centre, to - centre);
            let radius = u.norm();
            if radius < MIN_SEGMENT_M {
                return Err(PathError::field(
                    name("arc.centre"),
                    "lies on the arc's start; the radius must be positive",
                ));
            }
            if (v.norm() - radius).abs() > 1e-6 * radius.max(1.0) {
                return Err(PathError::field(
                    name("arc.to"),
                    format!(
                        "lies {:.4} m from 'centre', the start {:.4} m: not on one circle",
                        v.norm(),
                        radius
                    ),
                ));
            }
            let sweep = libm::atan2(normal.dot(&u.cross(&v)), u.dot(&v));
            if sweep.abs() > PI - 1e-9 {
                return Err(PathError::field(
                    name("arc.to"),
                    "lies opposite the start across 'centre': the way round is ambiguous \
                     (give 'sweep_deg' or 'through')",
                ));
            }
            (centre, sweep)
        }
        (Some(centre), None, None, Some(sweep_deg)) => {
            if !sweep_deg.is_finite() || sweep_deg == 0.0 || sweep_deg.abs() > 360.0 {
                return Err(PathError::field(
                    name("arc.sweep_deg"),
                    format!("is {sweep_deg}; it must be nonzero and within [−360, 360]"),
                ));
            }
            (centre, sweep_deg.to_radians())
        }
        (None, Some(through), Some(to), None) => {
            if (to - at).norm() < MIN_SEGMENT_M {
                return Err(PathError::field(
                    name("arc.to"),
                    "is the arc's start: a full circle takes 'centre' and 'sweep_deg'",
                ));
            }
            let centre = circumcentre(at, through, to, normal).ok_or_else(|| {
                PathError::field(
                    name("arc.through"),
                    "lies on the line through the start and 'to': no circle passes",
                )
            })?;
            let angle = |p: Vec3| {
                let (u, v) = (at - centre, p - centre);
                libm::atan2(normal.dot(&u.cross(&v)), u.dot(&v)).rem_euclid(2.0 * PI)
            };
            // Counter-clockwise about `n` reaches `to` after `through`, or the arc runs the
            // other way.
            let (to_ccw, through_ccw) = (angle(to), angle(through));
            let sweep = if through_ccw < to_ccw {
                to_ccw
            } else {
                to_ccw - 2.0 * PI
            };
            (centre, sweep)
        }
        _ => return Err(PathError::field(name("arc"), forms)),
    };
    let offset = at - centre;
    let radius = offset.norm();
    if radius < MIN_SEGMENT_M {
        return Err(PathError::field(
            name("arc.centre"),
            "lies on the arc's start; the radius must be positive",
        ));
    }
    let u = offset / radius;
    let w = normal.cross(&u) * sweep.signum();
    let length = radius * sweep.abs();
    if length < MIN_SEGMENT_M {
        return Err(zero_length(name("arc"), length));
    }
    Ok((
        Shape::Circular(Circular {
            centre,
            radius_m: radius,
            u,
            w,
        }),
        length,
    ))
}

/// The centre of the circle through `a`, `b`, `c` (in the plane normal to `normal`), or `None`
/// when they lie on one line.
fn circumcentre(a: Vec3, b: Vec3, c: Vec3, normal: Vec3) -> Option<Vec3> {
    let (ab, ac) = (b - a, c - a);
    let cross = ab.cross(&ac);
    let area2 = cross.dot(&normal);
    if area2.abs() < 1e-12 * ab.norm().max(1.0) * ac.norm().max(1.0) {
        return None;
    }
    // a + (|ac|² n × ab − |ab|² n × ac) / (2 (ab × ac)·n).
    let offset = (normal.cross(&ab) * ac.norm_squared() - normal.cross(&ac) * ab.norm_squared())
        / (2.0 * area2);
    Some(a + offset)
}

/// The pieces of the segments in order, with each corner rounded by a blend arc of `radius`
/// tangent to both its segments (when positive; [`fillet`]) and the remaining corners marked.
fn blended(shapes: Vec<(Shape, f64)>, normal: Vec3, radius: f64) -> Result<Vec<Piece>, PathError> {
    let segments: Vec<Piece> = shapes
        .into_iter()
        .map(|(shape, length_m)| Piece {
            shape,
            start_s: 0.0,
            length_m,
            corner_before: false,
        })
        .collect();
    let count = segments.len();
    // How much of each segment's start and end the blends take (m).
    let mut trimmed = vec![(0.0, 0.0); count];
    let mut blends: Vec<Option<Piece>> = vec![None; count];
    for index in 1..count {
        let (before, after) = (&segments[index - 1], &segments[index]);
        let (a, b) = (before.tangent(before.length_m), after.tangent(0.0));
        let turn = libm::acos(a.dot(&b).clamp(-1.0, 1.0));
        if radius == 0.0 || turn <= CORNER_RAD {
            continue;
        }
        let corner = |problem: &str| {
            PathError::field(
                "blend_radius_m",
                format!(
                    "cannot round the corner between segments {} and {}: {problem}",
                    index - 1,
                    index
                ),
            )
        };
        if turn > PI - 1e-6 {
            return Err(corner("the path turns back on itself there"));
        }
        let (before_m, after_m, blend) = fillet(before, after, normal, radius)
            .ok_or_else(|| corner("the radius is too large for the segments that meet there"))?;
        trimmed[index - 1].1 = before_m;
        trimmed[index].0 = after_m;
        blends[index] = Some(blend);
    }
    let mut pieces: Vec<Piece> = Vec::new();
    let mut s = 0.0;
    for (index, segment) in segments.into_iter().enumerate() {
        let (head, tail) = trimmed[index];
        let length = segment.length_m;
        if head + tail > length + 1e-12 {
            return Err(PathError::field(
                "blend_radius_m",
                format!(
                    "is too large for segment {index}: its blends need {:.4} m of it, which is \
                     {length:.4} m long",
                    head + tail
                ),
            ));
        }
        if let Some(blend) = blends[index] {
            pieces.push(Piece {
                start_s: s,
                ..blend
            });
            s += blend.length_m;
        }
        let shape = segment.from(head);
        let mut corner_before = false;
        if let Some(before) = pieces.last()
            && blends[index].is_none()
        {
            let a = before.tangent(before.length_m);
            let b = segment.tangent(head);
            corner_before = libm::acos(a.dot(&b).clamp(-1.0, 1.0)) > CORNER_RAD;
        }
        let remaining = length - head - tail;
        if remaining > 0.0 {
            pieces.push(Piece {
                shape,
                start_s: s,
                length_m: remaining,
                corner_before,
            });
            s += remaining;
        }
    }
    Ok(pieces)
}

/// Steps in which [`fillet`] scans a segment for where its blend starts.
const FILLET_SCAN_STEPS: usize = 1000;

/// The arc of `radius` tangent to `before` near its end and to `after` near its start, on the
/// side the path turns to at their corner (lines and arcs alike): how much of `before`'s end and
/// of `after`'s start it replaces, and the arc; `None` when no such arc fits on the two
/// segments.
///
/// The blend's start lies `t` before `before`'s end, its centre `radius` from there on the
/// turning side; `t` is found where that centre lies `radius` from `after`'s line or circle on
/// the same side (bisection: the distance grows with `t`, from `radius · cos(turn)` at the
/// corner; for two lines `t = radius · tan(turn / 2)`).
fn fillet(before: &Piece, after: &Piece, normal: Vec3, radius: f64) -> Option<(f64, f64, Piece)> {
    let turning = normal
        .dot(&before.tangent(before.length_m).cross(&after.tangent(0.0)))
        .signum();
    let centre_at = |t: f64| {
        let sigma = before.length_m - t;
        before.point(sigma) + normal.cross(&before.tangent(sigma)) * (turning * radius)
    };
    // How far `centre` lies from `after`'s line or circle, on the turning side.
    let beside_after = |centre: Vec3| match after.shape {
        Shape::Straight(line) => {
            (centre - line.start).dot(&(normal.cross(&line.direction) * turning))
        }
        Shape::Circular(arc) => {
            let inward = normal.cross(&arc.w).dot(&arc.u) < 0.0;
            let from_centre = (centre - arc.centre).norm();
            // The turning side of a circle is its inside when it turns the way the path does.
            let arc_turning = if inward { 1.0 } else { -1.0 };
            if arc_turning == turning {
                arc.radius_m - from_centre
            } else {
                from_centre - arc.radius_m
            }
        }
    };
    let gap = |t: f64| beside_after(centre_at(t)) - radius;
    // The first `t` where the gap closes: scanned in steps, then bisected (inside a circle the
    // gap opens again further back, so only the first crossing is the blend).
    let step = before.length_m / FILLET_SCAN_STEPS as f64;
    let crossing = (1..=FILLET_SCAN_STEPS).find(|&k| gap(k as f64 * step) >= 0.0)?;
    let (mut low, mut high) = ((crossing - 1) as f64 * step, crossing as f64 * step);
    for _ in 0..200 {
        let middle = 0.5 * (low + high);
        if middle <= low || middle >= high {
            break;
        }
        if gap(middle) < 0.0 {
            low = middle;
        } else {
            high = middle;
        }
    }
    let before_m = high;
    let centre = centre_at(before_m);
    let after_m = after.nearest(&centre);
    let start = before.point(before.length_m - before_m);
    let end = after.point(after_m);
    if after_m >= after.length_m || ((end - centre).norm() - radius).abs() > 1e-9 * radius.max(1.0)
    {
        return None;
    }
    let u = (start - centre) / radius;
    let v = (end - centre) / radius;
    let sweep = libm::atan2(turning * normal.dot(&u.cross(&v)), u.dot(&v)).rem_euclid(2.0 * PI);
    Some((
        before_m,
        after_m,
        Piece {
            shape: Shape::Circular(Circular {
                centre,
                radius_m: radius,
                u,
                w: before.tangent(before.length_m - before_m),
            }),
            start_s: 0.0,
            length_m: radius * sweep,
            corner_before: false,
        },
    ))
}
