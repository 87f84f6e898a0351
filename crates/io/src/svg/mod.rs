//! SVG drawings as strokes: every subpath of every drawn element, placed on the work surface as
//! a path of lines and circular arcs ([`read_svg`], whose documentation tells how).

mod bezier;
mod biarc;
mod bounds;
mod error;
mod outline;
mod piece;
mod placement;
mod scattered;
mod simplify;
mod stroke;

use std::path::Path;

use emg_control::{PATH_FORMAT_VERSION, PathSpec, SegmentSpec};
use serde::{Deserialize, Serialize};

pub use bounds::DrawingBounds;
pub use error::{SvgError, SvgFileError};
pub use placement::{Placement, SVG_PX_M};
pub use scattered::scattered_strokes_svg;

use bezier::V2;
use piece::Piece;
use placement::Frame;

/// The finest curve tolerance (m) accepted: 1 µm, the path format's own precision
/// ([`emg_control::PLANE_TOLERANCE_M`]).
pub const MIN_CURVE_TOLERANCE_M: f64 = 1e-6;

/// The largest [`SvgOptions::smooth_join_deg`] accepted (degrees): a turn beyond it is a
/// corner the drawing means.
pub const MAX_SMOOTH_JOIN_DEG: f64 = 45.0;

/// How closely the strokes follow the drawing, which joints are smooth, and which strokes are
/// too short to draw (JSON: every field optional).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SvgOptions {
    /// The largest distance (m) between a curve of the drawing and the arcs that stand for it
    /// (default 5e-5: 0.05 mm; at least [`MIN_CURVE_TOLERANCE_M`]).
    pub curve_tolerance_m: f64,
    /// Strokes shorter than this (m) are dropped and counted (default 1e-3: 1 mm).
    pub min_stroke_m: f64,
    /// A joint turning by less than this (degrees, default 15, at most 45) is made smooth: the
    /// path passes it without a corner, a curve bent to the common tangent within the
    /// tolerance, two lines joined by an arc tangent to both within the tolerance of their
    /// corner. Bending by `φ` takes about
    /// `4 curve_tolerance_m / φ` of the curve, so a joint turning more than
    /// `curve_tolerance_m / 0.2 mm` radians stays a corner whatever this says (14° at the
    /// default tolerance, 0.3° at 1 µm). `0` keeps every corner of the drawing.
    pub smooth_join_deg: f64,
    /// How far (m) the rounding of a corner may leave it (default 0: every corner the drawing
    /// means stays one, passed at rest). Above 0, corners of polylines and joins of curves are
    /// rounded by arcs tangent to both sides within it (each taking at most half of each side),
    /// so a flattened curve, an outline or a letter is drawn without a stop at every vertex; a
    /// corner whose rounding would be shorter than [`emg_control::MIN_SEGMENT_M`] (a reversal)
    /// stays one.
    pub corner_tolerance_m: f64,
}

impl Default for SvgOptions {
    fn default() -> Self {
        Self {
            curve_tolerance_m: 5e-5,
            min_stroke_m: 1e-3,
            smooth_join_deg: 15.0,
            corner_tolerance_m: 0.0,
        }
    }
}

impl SvgOptions {
    fn validate(&self) -> Result<(), SvgError> {
        let tolerance = self.curve_tolerance_m;
        if !(tolerance.is_finite() && tolerance >= MIN_CURVE_TOLERANCE_M) {
            return Err(SvgError::Options {
                field: "curve_tolerance_m",
                problem: format!("is {tolerance}; it must be at least {MIN_CURVE_TOLERANCE_M} m"),
            });
        }
        let shortest = self.min_stroke_m;
        if !(shortest.is_finite() && shortest >= 0.0) {
            return Err(SvgError::Options {
                field: "min_stroke_m",
                problem: format!("is {shortest}; it must be 0 or more (m)"),
            });
        }
        let smooth = self.smooth_join_deg;
        if !(0.0..=MAX_SMOOTH_JOIN_DEG).contains(&smooth) {
            return Err(SvgError::Options {
                field: "smooth_join_deg",
                problem: format!(
                    "is {smooth}; it must be within [0, {MAX_SMOOTH_JOIN_DEG}] degrees"
                ),
            });
        }
        let corner = self.corner_tolerance_m;
        if !(corner.is_finite() && corner >= 0.0) {
            return Err(SvgError::Options {
                field: "corner_tolerance_m",
                problem: format!("is {corner}; it must be 0 or more (m)"),
            });
        }
        Ok(())
    }
}

/// A drawing read into strokes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Drawing {
    /// One path per stroke (subpath), in document order, each valid for
    /// [`emg_control::Path::new`].
    pub strokes: Vec<PathSpec>,
    /// How many subpaths were dropped as shorter than [`SvgOptions::min_stroke_m`].
    pub dropped_tiny: usize,
    /// Metres per unit of the drawing, as placed.
    pub scale_m_per_unit: f64,
    /// The bounding box of the drawing (its units), whose centre went to `origin_m`.
    pub bounds: DrawingBounds,
}

impl Drawing {
    /// Units of the drawing per metre.
    pub fn svg_units_per_m(&self) -> f64 {
        1.0 / self.scale_m_per_unit
    }

    /// The placed drawing's width and height (m).
    pub fn size_m(&self) -> [f64; 2] {
        [
            self.bounds.width() * self.scale_m_per_unit,
            self.bounds.height() * self.scale_m_per_unit,
        ]
    }
}

/// Reads the SVG `text` into strokes placed by `placement`: every subpath of every drawn
/// element, as a path of lines and circular arcs ([`emg_control::PathSpec`]).
///
/// * **Reading** ([`usvg`]): shapes (`rect`, `circle`, `ellipse`, `line`, `polyline`,
///   `polygon`, `path`), `use`, groups, transforms, units and the viewBox are resolved by usvg;
///   every subpath of every visible element, stroked or filled, is one stroke, in document
///   order. The drawing's units are usvg's: CSS pixels of the root's `width` and `height`, the
///   viewBox mapped onto them ([`SVG_PX_M`] metres each at the drawing's own size). usvg hands
///   over arcs, circles and ellipses as cubic Béziers (within 2.7e-4 of their radius) and
///   coordinates in single precision; the strokes follow that geometry. Text, images, clipping
///   and masks are not drawn.
/// * **Placing** ([`Placement`]): the centre of the drawing's bounding box (of all its
///   subpaths' geometry, tiny ones included) goes to `origin_m`, its x along `x_axis` and its
///   y along `normal × x_axis`, so that it reads right, never mirrored, seen along `normal`.
/// * **Fitting**: straight segments stay lines; quadratic and cubic Béziers become biarcs
///   (pairs of tangent arcs), halved until each is within [`SvgOptions::curve_tolerance_m`] of
///   its curve (measured both ways, at 32 points of the curve and 16 of each arc, in metres
///   after placement). Where the drawing is smooth the path is too: its pieces meet within
///   [`emg_control::CORNER_RAD`], so the tool passes without stopping. Joints that turn less
///   than [`SvgOptions::smooth_join_deg`] count as smooth (drawings round their coordinates:
///   icon sets leave joints they mean to be smooth a few degrees off): the curves there are
///   fitted to one tangent, still within the tolerance, and two lines are joined by the arc
///   tangent to both that leaves their corner by at most the tolerance (taking at most half
///   of each line), so a polyline that flattens a curve is drawn without a stop at every
///   vertex. Sharper corners are rounded too, within [`SvgOptions::corner_tolerance_m`]
///   where it is above 0. A `Z` adds
///   the closing line when it is at least the path format's shortest segment
///   ([`emg_control::MIN_SEGMENT_M`], 0.1 mm) long, and leaves a shorter gap open. Shorter
///   pieces are merged with a neighbour: where a drawing has features that fine (an `h.04`
///   at 1 mm per unit), the path may leave it by about the length merged.
/// * **Checking**: every stroke is validated as an [`emg_control::Path`] (the checks the path
///   file reader makes); strokes shorter than [`SvgOptions::min_stroke_m`] are dropped and
///   counted.
///
/// Refused ([`SvgError`], never a panic) when the text is not SVG, when nothing drawn is long
/// enough, when `width_m` is asked of a drawing without width, and when a placement field or
/// an option is unusable (each message names which and why).
///
/// ```
/// use emg_io::{Placement, SvgOptions, read_svg};
/// let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 50">
///                <rect x="0" y="0" width="100" height="50"/>
///                <circle cx="50" cy="25" r="20"/>
///              </svg>"#;
/// let drawing = read_svg(svg, &Placement::default(), &SvgOptions::default())?;
/// assert_eq!(drawing.strokes.len(), 2);
/// assert!((drawing.size_m()[0] - 0.2).abs() < 1e-12);
/// let rect = emg_control::Path::new(drawing.strokes[0].clone())?;
/// assert!((rect.length_m() - 0.6).abs() < 1e-9); // 0.2 m by 0.1 m, closed
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn read_svg(
    text: &str,
    placement: &Placement,
    options: &SvgOptions,
) -> Result<Drawing, SvgError> {
    options.validate()?;
    let frame = placement.frame()?;
    let tree = outline::parse(text)?;
    let subpaths = outline::subpaths(&tree);
    let empty = |dropped| SvgError::Empty {
        min_stroke_m: options.min_stroke_m,
        dropped,
    };
    let bounds = outline::bounds(&subpaths).ok_or_else(|| empty(0))?;
    let scale = placement.scale(&bounds)?;
    let centre = V2::from(bounds.centre());
    let mut strokes = Vec::new();
    let mut dropped_tiny = 0;
    for (index, subpath) in subpaths.iter().enumerate() {
        let plane = subpath.map(|p| (p - centre) * scale);
        let pieces = stroke::pieces(
            &plane,
            options.curve_tolerance_m,
            options.smooth_join_deg.to_radians(),
            options.corner_tolerance_m,
        );
        let length: f64 = pieces.iter().map(Piece::length).sum();
        let too_short = pieces
            .iter()
            .any(|p| p.length() < emg_control::MIN_SEGMENT_M);
        if pieces.is_empty() || too_short || length < options.min_stroke_m {
            dropped_tiny += 1;
            continue;
        }
        let spec = spec_of(&pieces, &frame);
        emg_control::Path::new(spec.clone()).map_err(|error| SvgError::Stroke {
            index,
            element: subpath.element.clone(),
            error,
        })?;
        strokes.push(spec);
    }
    if strokes.is_empty() {
        return Err(empty(dropped_tiny));
    }
    Ok(Drawing {
        strokes,
        dropped_tiny,
        scale_m_per_unit: scale,
        bounds,
    })
}

/// Reads the SVG file at `path` into strokes (see [`read_svg`]); errors name the file.
pub fn read_svg_file(
    path: &Path,
    placement: &Placement,
    options: &SvgOptions,
) -> Result<Drawing, SvgFileError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| SvgFileError::Io {
        path: name.clone(),
        source,
    })?;
    read_svg(&text, placement, options).map_err(|error| SvgFileError::Svg { path: name, error })
}

/// The path of a chain of pieces on the placed surface.
fn spec_of(pieces: &[Piece], frame: &Frame) -> PathSpec {
    let segments = pieces
        .iter()
        .map(|piece| match *piece {
            Piece::Line { to, .. } => SegmentSpec::Line {
                to: frame.point(to),
            },
            Piece::Arc { centre, sweep, .. } => SegmentSpec::Arc {
                centre: Some(frame.point(centre)),
                through: None,
                to: None,
                sweep_deg: Some(sweep.to_degrees()),
            },
        })
        .collect();
    PathSpec {
        version: PATH_FORMAT_VERSION,
        start: frame.point(pieces[0].start()),
        normal: frame.normal.into(),
        blend_radius_m: 0.0,
        segments,
    }
}
