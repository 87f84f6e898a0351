//! The drawn geometry of a parsed SVG: every subpath of every visible path (usvg turns `rect`,
//! `circle`, `ellipse`, `line`, `polyline`, `polygon` and `use` into paths), in document order,
//! with its transforms applied, in the drawing's units, and their bounding box.

use super::bezier::{Cubic, V2};
use super::bounds::DrawingBounds;
use super::error::SvgError;

/// One drawn segment, from where the one before it ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Segment {
    /// A straight line to a point.
    Line(V2),
    /// A cubic Bézier (quadratics are raised to cubics); its first control point is where the
    /// segment before it ends.
    Cubic(Cubic),
}

impl Segment {
    /// Where the segment ends.
    pub fn end(&self) -> V2 {
        match self {
            Segment::Line(to) => *to,
            Segment::Cubic(curve) => curve.p[3],
        }
    }
}

/// One subpath: a pen-down stroke of the drawing.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Subpath {
    /// The `id` of the element it was drawn by (empty when it has none).
    pub element: String,
    /// Where the pen goes down.
    pub start: V2,
    /// The segments in the order drawn.
    pub segments: Vec<Segment>,
    /// Whether the subpath ends with a `Z` (closed back to its start).
    pub closed: bool,
}

impl Subpath {
    /// The subpath with every point mapped by `f` (an affine map).
    pub fn map(&self, f: impl Fn(V2) -> V2 + Copy) -> Self {
        Self {
            element: self.element.clone(),
            start: f(self.start),
            segments: self
                .segments
                .iter()
                .map(|segment| match segment {
                    Segment::Line(to) => Segment::Line(f(*to)),
                    Segment::Cubic(curve) => Segment::Cubic(curve.map(f)),
                })
                .collect(),
            closed: self.closed,
        }
    }
}

/// Parses `text` as SVG: the XML must parse and its root element must be `<svg>` in the SVG
/// namespace. Images are never loaded (they are not drawn).
pub(crate) fn parse(text: &str) -> Result<usvg::Tree, SvgError> {
    let not_svg = |reason: String| SvgError::NotSvg { reason };
    let xml_options = usvg::roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    let document = usvg::roxmltree::Document::parse_with_options(text, xml_options)
        .map_err(|e| not_svg(e.to_string()))?;
    let root = document.root_element();
    let name = root.tag_name();
    if name.name() != "svg" {
        return Err(not_svg(format!(
            "its root element is <{}>, not <svg>",
            name.name()
        )));
    }
    if name.namespace() != Some(SVG_NAMESPACE) {
        return Err(not_svg(format!(
            "its <svg> element is not in the SVG namespace (add xmlns=\"{SVG_NAMESPACE}\")"
        )));
    }
    let options = usvg::Options {
        image_href_resolver: usvg::ImageHrefResolver {
            resolve_data: Box::new(|_, _, _| None),
            resolve_string: Box::new(|_, _| None),
        },
        ..usvg::Options::default()
    };
    usvg::Tree::from_xmltree(&document, &options).map_err(|e| not_svg(e.to_string()))
}

/// The SVG namespace.
const SVG_NAMESPACE: &str = "http://www.w3.org/2000/svg";

/// Every subpath drawn in `tree`, in document order, in the drawing's units.
pub(crate) fn subpaths(tree: &usvg::Tree) -> Vec<Subpath> {
    let mut out = Vec::new();
    collect(tree.root(), &mut out);
    out
}

/// Appends the subpaths of `group`'s visible paths (filled or stroked) to `out`.
fn collect(group: &usvg::Group, out: &mut Vec<Subpath>) {
    for node in group.children() {
        match node {
            usvg::Node::Group(group) => collect(group, out),
            usvg::Node::Path(path)
                if path.is_visible() && (path.fill().is_some() || path.stroke().is_some()) =>
            {
                read_path(path, out);
            }
            _ => {}
        }
    }
}

/// Appends the subpaths of one path, its absolute transform applied (in double precision).
fn read_path(path: &usvg::Path, out: &mut Vec<Subpath>) {
    let ts = path.abs_transform();
    let [sx, kx, ky, sy, tx, ty] = [ts.sx, ts.kx, ts.ky, ts.sy, ts.tx, ts.ty].map(f64::from);
    let place = |p: usvg::tiny_skia_path::Point| {
        let (x, y) = (f64::from(p.x), f64::from(p.y));
        V2::new(sx * x + kx * y + tx, ky * x + sy * y + ty)
    };
    let element = path.id().to_string();
    let mut current: Option<Subpath> = None;
    // Where the pen is, and where the last subpath started (a segment after `Z` continues
    // from there).
    let (mut at, mut subpath_start) = (V2::zeros(), V2::zeros());
    let finish = |subpath: Option<Subpath>, out: &mut Vec<Subpath>| {
        if let Some(subpath) = subpath.filter(|s| !s.segments.is_empty()) {
            out.push(subpath);
        }
    };
    let open = |current: &mut Option<Subpath>, at: V2| {
        current.get_or_insert_with(|| Subpath {
            element: element.clone(),
            start: at,
            segments: Vec::new(),
            closed: false,
        });
    };
    for segment in path.data().segments() {
        use usvg::tiny_skia_path::PathSegment;
        match segment {
            PathSegment::MoveTo(p) => {
                finish(current.take(), out);
                at = place(p);
                subpath_start = at;
            }
            PathSegment::LineTo(p) => {
                open(&mut current, at);
                let to = place(p);
                push(&mut current, Segment::Line(to));
                at = to;
            }
            PathSegment::QuadTo(q, p) => {
                open(&mut current, at);
                let curve = Cubic::from_quadratic(at, place(q), place(p));
                push(&mut current, Segment::Cubic(curve));
                at = curve.p[3];
            }
            PathSegment::CubicTo(c1, c2, p) => {
                open(&mut current, at);
                let curve = Cubic {
                    p: [at, place(c1), place(c2), place(p)],
                };
                push(&mut current, Segment::Cubic(curve));
                at = curve.p[3];
            }
            PathSegment::Close => {
                if let Some(subpath) = current.as_mut() {
                    subpath.closed = true;
                }
                finish(current.take(), out);
                at = subpath_start;
            }
        }
    }
    finish(current.take(), out);
}

/// Appends `segment` to the open subpath.
fn push(current: &mut Option<Subpath>, segment: Segment) {
    if let Some(subpath) = current.as_mut() {
        subpath.segments.push(segment);
    }
}

/// The bounding box of the subpaths' geometry (curves by their extreme points, not their
/// control points); `None` when there are none.
pub(crate) fn bounds(subpaths: &[Subpath]) -> Option<DrawingBounds> {
    let mut points = Vec::new();
    for subpath in subpaths {
        points.push(subpath.start);
        for segment in &subpath.segments {
            match segment {
                Segment::Line(to) => points.push(*to),
                Segment::Cubic(curve) => points.extend(curve.extreme_points()),
            }
        }
    }
    let first = points.first()?;
    let (mut min, mut max) = (*first, *first);
    for p in &points {
        min = min.inf(p);
        max = max.sup(p);
    }
    Some(DrawingBounds {
        min: [min.x, min.y],
        max: [max.x, max.y],
    })
}
