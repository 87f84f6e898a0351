//! SVG drawings read into strokes: real line-art icons (lucide-static, tests/data/icons) and
//! small drawings of each shape, checked against the drawing's own geometry as usvg hands it
//! over, sampled here independently of the reader.

use emg_control::{Path, PathSpec, SegmentSpec};
use emg_io::{
    Drawing, MAX_SMOOTH_JOIN_DEG, Placement, SVG_PX_M, SvgError, SvgFileError, SvgOptions,
    parse_path, read_svg, read_svg_file,
};
use emg_kinematics::Vec3;

const ICONS: [&str; 6] = ["pencil", "heart", "star", "anchor", "waves", "signature"];

fn icon_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/icons")
        .join(format!("{name}.svg"))
}

fn icon(name: &str) -> String {
    std::fs::read_to_string(icon_path(name)).unwrap()
}

fn svg(body: &str) -> String {
    format!(r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">{body}</svg>"#)
}

/// The placement's unit axes on the surface: the drawing's x, its y (`n × x`) and `n`.
fn axes(placement: &Placement) -> (Vec3, Vec3, Vec3) {
    let n = Vec3::from(placement.normal).normalize();
    let x = Vec3::from(placement.x_axis);
    let x = (x - n * x.dot(&n)).normalize();
    (x, n.cross(&x), n)
}

/// Every subpath drawn in `text` as dense points on the surface (a closed subpath with its
/// closing line), sampled from usvg's own path data and placed as `drawing` says.
fn original_strokes(text: &str, drawing: &Drawing, placement: &Placement) -> Vec<Vec<Vec3>> {
    let tree = usvg::Tree::from_str(text, &usvg::Options::default()).unwrap();
    let (x, y, _) = axes(placement);
    let [cx, cy] = drawing.bounds.centre();
    let s = drawing.scale_m_per_unit;
    let origin = Vec3::from(placement.origin_m);
    let place = move |(u, v): (f64, f64)| origin + x * ((u - cx) * s) + y * ((v - cy) * s);
    let mut strokes = Vec::new();
    collect(tree.root(), &place, &mut strokes);
    strokes
}

fn collect(group: &usvg::Group, place: &dyn Fn((f64, f64)) -> Vec3, out: &mut Vec<Vec<Vec3>>) {
    for node in group.children() {
        match node {
            usvg::Node::Group(g) => collect(g, place, out),
            usvg::Node::Path(path) => sample_path(path, place, out),
            _ => {}
        }
    }
}

fn sample_path(path: &usvg::Path, place: &dyn Fn((f64, f64)) -> Vec3, out: &mut Vec<Vec<Vec3>>) {
    use usvg::tiny_skia_path::PathSegment;
    const STEPS: usize = 400;
    let t = path.abs_transform();
    let map = |p: usvg::tiny_skia_path::Point| {
        let (px, py) = (f64::from(p.x), f64::from(p.y));
        (
            f64::from(t.sx) * px + f64::from(t.kx) * py + f64::from(t.tx),
            f64::from(t.ky) * px + f64::from(t.sy) * py + f64::from(t.ty),
        )
    };
    let lerp =
        |a: (f64, f64), b: (f64, f64), u: f64| (a.0 + (b.0 - a.0) * u, a.1 + (b.1 - a.1) * u);
    let mut current: Vec<Vec3> = Vec::new();
    let (mut at, mut start) = ((0.0, 0.0), (0.0, 0.0));
    let flush = |current: &mut Vec<Vec3>, out: &mut Vec<Vec<Vec3>>| {
        if current.len() > 1 {
            out.push(std::mem::take(current));
        }
        current.clear();
    };
    for segment in path.data().segments() {
        // A Bézier of control points `c` at `u`, by de Casteljau.
        let bezier = |c: &[(f64, f64)], u: f64| {
            let mut c = c.to_vec();
            while c.len() > 1 {
                c = c.windows(2).map(|w| lerp(w[0], w[1], u)).collect();
            }
            c[0]
        };
        let controls: Vec<(f64, f64)> = match segment {
            PathSegment::MoveTo(p) => {
                flush(&mut current, out);
                at = map(p);
                start = at;
                continue;
            }
            PathSegment::LineTo(p) => vec![at, map(p)],
            PathSegment::QuadTo(q, p) => vec![at, map(q), map(p)],
            PathSegment::CubicTo(a, b, p) => vec![at, map(a), map(b), map(p)],
            PathSegment::Close => vec![at, start],
        };
        if current.is_empty() {
            current.push(place(at));
        }
        for i in 1..=STEPS {
            current.push(place(bezier(&controls, i as f64 / STEPS as f64)));
        }
        at = *controls.last().unwrap();
        if matches!(segment, PathSegment::Close) {
            flush(&mut current, out);
        }
    }
    flush(&mut current, out);
}

fn segment_distance(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let ab = b - a;
    let t = if ab.norm_squared() > 0.0 {
        ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// The path through the path file reader's validation (JSON and back).
fn validated(spec: &PathSpec) -> Path {
    let json = serde_json::to_string(spec).unwrap();
    parse_path(&json).unwrap_or_else(|e| panic!("stroke refused: {e}\n{json}"))
}

/// Points along the path every `step` (m) at most, its end included.
fn path_points(path: &Path, step: f64) -> Vec<Vec3> {
    let n = (path.length_m() / step).ceil().max(1.0) as usize;
    (0..=n)
        .map(|i| path.point_at(path.length_m() * i as f64 / n as f64))
        .collect()
}

/// The largest distance from the original stroke to the path, and from the path to it.
fn deviations(path: &Path, original: &[Vec3]) -> (f64, f64) {
    let there = original
        .iter()
        .map(|p| (path.nearest_point(p).point - p).norm())
        .fold(0.0, f64::max);
    let back = path_points(path, 5e-5)
        .iter()
        .map(|p| {
            original
                .windows(2)
                .map(|w| segment_distance(p, &w[0], &w[1]))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max);
    (there, back)
}

/// Reads `text`, and checks that every stroke is a valid path that follows the drawing within
/// the tolerance both ways, and that the placed drawing is centred on `origin_m` with the
/// width asked for.
fn read_and_check(text: &str, placement: &Placement, options: &SvgOptions) -> Drawing {
    let drawing = read_svg(text, placement, options).unwrap();
    let originals = original_strokes(text, &drawing, placement);
    assert_eq!(drawing.dropped_tiny, 0);
    assert_eq!(originals.len(), drawing.strokes.len());
    let tolerance = options.curve_tolerance_m;
    let (x, y, n) = axes(placement);
    let origin = Vec3::from(placement.origin_m);
    let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for (index, (spec, original)) in drawing.strokes.iter().zip(&originals).enumerate() {
        let path = validated(spec);
        assert!((path.normal() - n).norm() < 1e-12);
        assert!(
            (path.point_at(0.0) - original[0]).norm() < 1e-9,
            "stroke {index} start"
        );
        let (there, back) = deviations(&path, original);
        // The fit is measured at 32 points of each curve and 16 of each arc; allow what lies
        // between them, and the sag of the 400-chord polylines sampled here.
        let allowed = tolerance * 1.03 + 2e-7;
        assert!(
            there <= allowed,
            "stroke {index}: drawing {there:.3e} m from the path"
        );
        assert!(
            back <= allowed,
            "stroke {index}: path {back:.3e} m from the drawing"
        );
        for p in path_points(&path, 1e-4) {
            for (k, axis) in [x, y].iter().enumerate() {
                let along = (p - origin).dot(axis);
                low[k] = low[k].min(along);
                high[k] = high[k].max(along);
            }
            assert!((p - origin).dot(&n).abs() < 1e-9, "off the plane");
        }
    }
    let [width, height] = drawing.size_m();
    if let Some(width_m) = placement.width_m {
        assert!((width - width_m).abs() < 1e-12);
    }
    for (k, size) in [width, height].into_iter().enumerate() {
        assert!(
            (high[k] - low[k] - size).abs() <= 2.0 * tolerance,
            "extent {k}: {} m, the drawing {size} m",
            high[k] - low[k]
        );
        assert!(
            (0.5 * (high[k] + low[k])).abs() <= tolerance,
            "centre {k} off by {}",
            0.5 * (high[k] + low[k])
        );
    }
    drawing
}

fn arcs(spec: &PathSpec) -> Vec<([f64; 3], f64)> {
    spec.segments
        .iter()
        .filter_map(|s| match s {
            SegmentSpec::Arc {
                centre: Some(c),
                sweep_deg: Some(sweep),
                ..
            } => Some((*c, *sweep)),
            _ => None,
        })
        .collect()
}

#[test]
fn icons_become_valid_paths_within_the_tolerance() {
    let placement = Placement::default();
    for name in ICONS {
        let drawing = read_and_check(&icon(name), &placement, &SvgOptions::default());
        assert!(!drawing.strokes.is_empty(), "{name}");
        // Lucide draws on a 24 px grid with a 2 px margin.
        assert!(drawing.bounds.width() > 10.0 && drawing.bounds.width() <= 24.0);
    }
}

#[test]
fn icons_hold_within_finer_and_coarser_tolerances_elsewhere_on_a_wall() {
    // A vertical wall facing −x, drawing's x along +y; 5 cm and 0.5 m wide.
    for (tolerance, width) in [(1e-5, 0.05), (2e-4, 0.5)] {
        let placement = Placement {
            origin_m: [0.6, 0.1, 0.4],
            normal: [1.0, 0.0, 0.0],
            x_axis: [0.2, 1.0, 0.0],
            width_m: Some(width),
            scale_m_per_unit: None,
        };
        let options = SvgOptions {
            curve_tolerance_m: tolerance,
            ..SvgOptions::default()
        };
        for name in ["heart", "signature", "waves"] {
            read_and_check(&icon(name), &placement, &options);
        }
    }
}

#[test]
fn a_finer_tolerance_takes_more_arcs() {
    let count = |tolerance| {
        let options = SvgOptions {
            curve_tolerance_m: tolerance,
            ..SvgOptions::default()
        };
        let drawing = read_svg(&icon("signature"), &Placement::default(), &options).unwrap();
        drawing
            .strokes
            .iter()
            .map(|s| s.segments.len())
            .sum::<usize>()
    };
    let (coarse, fine) = (count(5e-4), count(2e-6));
    assert!(
        fine > 2 * coarse,
        "{fine} segments at 2 µm, {coarse} at 0.5 mm"
    );
}

#[test]
fn smooth_joints_stay_smooth_and_corners_stay_corners() {
    let corners = |text: &str, smooth_join_deg: f64| {
        let options = SvgOptions {
            smooth_join_deg,
            ..SvgOptions::default()
        };
        let drawing = read_svg(text, &Placement::default(), &options).unwrap();
        drawing
            .strokes
            .iter()
            .map(|spec| validated(spec).corners_m().count())
            .collect::<Vec<_>>()
    };
    // The heart's lobes, tip and dip are arcs, cubics and lines meant to meet smoothly; lucide
    // rounds its coordinates, leaving those joints up to 5° off.
    assert_eq!(corners(&icon("heart"), 15.0), vec![0]);
    let kept = corners(&icon("heart"), 0.0)[0];
    assert!(kept >= 5, "{kept} corners kept");
    // The anchor's barbs are real corners (116°); its ring is smooth.
    assert_eq!(corners(&icon("anchor"), 15.0), vec![0, 2, 0, 0]);
    assert_eq!(
        corners(&svg(r#"<circle cx="50" cy="50" r="40"/>"#), 15.0),
        vec![0]
    );
    // Two lines meeting at 3° are joined by an arc; at 20° they keep their corner.
    let text = svg(r#"<path d="M 0 0 L 50 0 L 100 2.6" fill="none" stroke="black"/>"#);
    assert_eq!(corners(&text, 15.0), vec![0]);
    assert_eq!(corners(&text, 2.0), vec![1]);
    let text = svg(r#"<path d="M 0 0 L 50 0 L 100 18.2" fill="none" stroke="black"/>"#);
    assert_eq!(corners(&text, 15.0), vec![1]);
    // Smoothed joints stay within the tolerance (checked both ways).
    let options = SvgOptions {
        smooth_join_deg: MAX_SMOOTH_JOIN_DEG,
        ..SvgOptions::default()
    };
    for name in ICONS {
        read_and_check(&icon(name), &Placement::default(), &options);
    }
}

#[test]
fn a_polyline_flattening_a_spiral_is_drawn_without_a_corner_within_the_tolerance() {
    // 100 vertices, each turning 7.2°, 1.3 to 2.5 units apart: plotter and font exports are made so.
    let points: Vec<String> = (0..100)
        .map(|i| {
            let (turn, radius) = (
                f64::from(i) * 0.04 * std::f64::consts::PI,
                10.0 + 0.1 * f64::from(i),
            );
            let (sin, cos) = libm::sincos(turn);
            format!("{:.4},{:.4}", 50.0 + radius * cos, 50.0 + radius * sin)
        })
        .collect();
    let text = svg(&format!(r#"<polyline points="{}"/>"#, points.join(" ")));
    let drawing = read_and_check(&text, &Placement::default(), &SvgOptions::default());
    let path = validated(&drawing.strokes[0]);
    assert_eq!(path.corners_m().count(), 0);
    // Below the turn asked for, every vertex stays a corner.
    let options = SvgOptions {
        smooth_join_deg: 5.0,
        ..SvgOptions::default()
    };
    let drawing = read_and_check(&text, &Placement::default(), &options);
    assert_eq!(validated(&drawing.strokes[0]).corners_m().count(), 98);
}

#[test]
fn a_circle_is_one_stroke_of_arcs_round_once_counter_clockwise_about_n_from_svg_y() {
    let placement = Placement::default();
    let text = svg(r#"<circle cx="50" cy="50" r="40"/>"#);
    let drawing = read_and_check(&text, &placement, &SvgOptions::default());
    assert_eq!(drawing.strokes.len(), 1);
    let spec = &drawing.strokes[0];
    let arcs = arcs(spec);
    assert_eq!(arcs.len(), spec.segments.len(), "only arcs");
    let path = validated(spec);
    // 0.2 m wide: radius 0.1 m about the placement's origin.
    let origin = Vec3::from(placement.origin_m);
    for (centre, _) in &arcs {
        assert!((Vec3::from(*centre) - origin).norm() < 1e-4);
    }
    assert!((path.length_m() - 2.0 * std::f64::consts::PI * 0.1).abs() < 1e-4);
    assert!((path.point_at(path.length_m()) - path.point_at(0.0)).norm() < 1e-6);
    // usvg draws a circle from (cx + r, cy) towards (cx, cy + r): from SVG x towards SVG y,
    // which the placement maps to x_axis and n × x_axis — counter-clockwise about n, the
    // sign of `sweep_deg`.
    let total: f64 = arcs.iter().map(|(_, sweep)| sweep).sum();
    assert!((total - 360.0).abs() < 1e-6, "turns {total}°");
    let (x, y, _) = axes(&placement);
    assert!((path.point_at(0.0) - (origin + x * 0.1)).norm() < 1e-9);
    assert!((path.tangent_at(0.0) - y).norm() < 1e-6);
}

#[test]
fn a_rect_is_four_lines_with_three_corners() {
    let placement = Placement {
        scale_m_per_unit: Some(1e-3),
        width_m: None,
        ..Placement::default()
    };
    let text = svg(r#"<rect x="10" y="20" width="60" height="30"/>"#);
    let drawing = read_and_check(&text, &placement, &SvgOptions::default());
    let spec = &drawing.strokes[0];
    assert_eq!(spec.segments.len(), 4);
    assert!(
        spec.segments
            .iter()
            .all(|s| matches!(s, SegmentSpec::Line { .. }))
    );
    let path = validated(spec);
    assert_eq!(path.corners_m().count(), 3);
    assert!((path.length_m() - 0.18).abs() < 1e-9);
    // The rect's corner (10, 20) is 30 units left of and 15 above the centre (40, 35).
    let (x, y, _) = axes(&placement);
    let expected = Vec3::from(placement.origin_m) + x * -0.03 + y * -0.015;
    assert!((Vec3::from(spec.start) - expected).norm() < 1e-9);
    assert_eq!(drawing.size_m(), [0.06, 0.03]);
}

#[test]
fn an_ellipse_is_biarcs_within_the_tolerance() {
    let text = svg(r#"<ellipse cx="50" cy="50" rx="45" ry="15"/>"#);
    for tolerance in [5e-5, 5e-6] {
        let options = SvgOptions {
            curve_tolerance_m: tolerance,
            ..SvgOptions::default()
        };
        let drawing = read_and_check(&text, &Placement::default(), &options);
        let spec = &drawing.strokes[0];
        assert_eq!(arcs(spec).len(), spec.segments.len());
        assert!(spec.segments.len() >= 8 && spec.segments.len().is_multiple_of(2));
        assert_eq!(validated(spec).corners_m().count(), 0);
    }
}

#[test]
fn rotations_and_scales_are_honoured() {
    let placement = Placement {
        scale_m_per_unit: Some(1e-3),
        width_m: None,
        ..Placement::default()
    };
    let text = svg(concat!(
        r#"<line x1="0" y1="0" x2="10" y2="0" stroke="black"/>"#,
        r#"<line x1="0" y1="0" x2="10" y2="0" stroke="black" transform="rotate(90)"/>"#,
        r#"<g transform="translate(20 20) scale(2)">"#,
        r#"<polyline points="0,0 10,0 10,5" fill="none" stroke="black"/></g>"#,
    ));
    let drawing = read_and_check(&text, &placement, &SvgOptions::default());
    assert_eq!(drawing.strokes.len(), 3);
    let (x, y, _) = axes(&placement);
    let direction = |spec: &PathSpec, segment: usize| {
        let path = validated(spec);
        let piece = path.pieces()[segment];
        let (from, to, _) = piece.outline();
        ((to - from).normalize(), (to - from).norm())
    };
    let (d, length) = direction(&drawing.strokes[0], 0);
    assert!((d - x).norm() < 1e-9 && (length - 0.01).abs() < 1e-9);
    // rotate(90) turns SVG x onto SVG y.
    let (d, length) = direction(&drawing.strokes[1], 0);
    assert!((d - y).norm() < 1e-9 && (length - 0.01).abs() < 1e-9);
    // scale(2) doubles both legs.
    let (d, length) = direction(&drawing.strokes[2], 0);
    assert!((d - x).norm() < 1e-9 && (length - 0.02).abs() < 1e-9);
    let (d, length) = direction(&drawing.strokes[2], 1);
    assert!((d - y).norm() < 1e-9 && (length - 0.01).abs() < 1e-9);
    // The bounds hold the transformed geometry: x from 0 to 40, y from 0 to 30.
    assert_eq!(drawing.bounds.min, [0.0, 0.0]);
    assert_eq!(drawing.bounds.max, [40.0, 30.0]);
}

#[test]
fn an_l_keeps_its_handedness_seen_along_n() {
    // An "L": down its stem, then right along its foot.
    let text = svg(r#"<path d="M 10 10 V 90 H 60" fill="none" stroke="black"/>"#);
    for placement in [
        Placement::default(),
        Placement {
            origin_m: [0.5, 0.2, 0.3],
            normal: [0.0, 1.0, 0.0],
            x_axis: [1.0, 0.0, 1.0],
            width_m: Some(0.1),
            scale_m_per_unit: None,
        },
    ] {
        let drawing = read_and_check(&text, &placement, &SvgOptions::default());
        let path = validated(&drawing.strokes[0]);
        let stem = path.tangent_at(0.0);
        let foot = path.tangent_at(path.length_m());
        let (x, y, n) = axes(&placement);
        // In SVG's own frame the stem runs along +y and the foot along +x: stem × foot is
        // −(x × y). Placed, (x_axis, n × x_axis, n) is right-handed, so seen along n the turn
        // goes the same way: the L is not mirrored.
        assert!((stem - y).norm() < 1e-9 && (foot - x).norm() < 1e-9);
        assert!(x.cross(&y).dot(&n) > 0.999);
        assert!(stem.cross(&foot).dot(&n) < -0.999);
    }
    // The default placement, seen from above: the L's top is farther from the arm's base, its
    // foot runs towards −y.
    let drawing = read_svg(&text, &Placement::default(), &SvgOptions::default()).unwrap();
    let path = validated(&drawing.strokes[0]);
    let (top, bottom) = (path.point_at(0.0), path.point_at(0.16));
    assert!(top.x > bottom.x + 0.1);
    assert!((path.tangent_at(path.length_m()) - Vec3::new(0.0, -1.0, 0.0)).norm() < 1e-9);
}

#[test]
fn tiny_strokes_are_dropped_and_counted() {
    let text = svg(concat!(
        r#"<line x1="0" y1="0" x2="100" y2="0" stroke="black"/>"#,
        r#"<line x1="0" y1="50" x2="0.4" y2="50" stroke="black"/>"#,
        r#"<circle cx="50" cy="50" r="0.01"/>"#,
    ));
    // 0.2 m wide: 2 mm per unit, so the 0.4-unit line is 0.8 mm and the dot 0.13 mm round.
    let drawing = read_svg(&text, &Placement::default(), &SvgOptions::default()).unwrap();
    assert_eq!(drawing.strokes.len(), 1);
    assert_eq!(drawing.dropped_tiny, 2);
    let options = SvgOptions {
        min_stroke_m: 5e-4,
        ..SvgOptions::default()
    };
    let drawing = read_svg(&text, &Placement::default(), &options).unwrap();
    assert_eq!((drawing.strokes.len(), drawing.dropped_tiny), (2, 1));
}

#[test]
fn features_finer_than_the_path_format_are_merged_into_valid_paths() {
    // A zigzag of 0.05-unit teeth (0.05 mm at 1 mm per unit) along a line, and a small
    // squiggle of curves: every segment of the result is at least 0.1 mm long.
    let mut d = String::from("M 0 0");
    for k in 0..40 {
        d += &format!(
            " L {} {}",
            0.05 * (k + 1) as f64,
            if k % 2 == 0 { 0.04 } else { 0.0 }
        );
    }
    d += " C 3 1 4 -1 5 0 c 0.01 0.05 0.08 0.05 0.09 0";
    let text = svg(&format!(r#"<path d="{d}" fill="none" stroke="black"/>"#));
    let placement = Placement {
        scale_m_per_unit: Some(1e-3),
        width_m: None,
        ..Placement::default()
    };
    let drawing = read_svg(&text, &placement, &SvgOptions::default()).unwrap();
    let path = validated(&drawing.strokes[0]);
    for piece in path.pieces() {
        assert!(piece.length_m >= emg_control::MIN_SEGMENT_M);
    }
    let original = &original_strokes(&text, &drawing, &placement)[0];
    let (there, back) = deviations(&path, original);
    // Finer than 0.1 mm the path cannot follow; it stays within about that.
    assert!(there < 1.5e-4 && back < 1.5e-4, "{there} {back}");
}

#[test]
fn physical_units_and_the_viewbox_are_resolved() {
    // 100 mm wide on a viewBox of 50 units: at SVG_PX_M per pixel it is drawn 0.1 m wide.
    let text = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="50mm"
                       viewBox="0 0 50 25"><rect x="0" y="0" width="50" height="25"/></svg>"#;
    let placement = Placement {
        scale_m_per_unit: Some(SVG_PX_M),
        width_m: None,
        ..Placement::default()
    };
    let drawing = read_svg(text, &placement, &SvgOptions::default()).unwrap();
    let [width, height] = drawing.size_m();
    assert!((width - 0.1).abs() < 1e-6 && (height - 0.05).abs() < 1e-6);
    assert!((validated(&drawing.strokes[0]).length_m() - 0.3).abs() < 1e-5);
}

#[test]
fn empty_and_non_svg_texts_are_refused_with_what_is_wrong() {
    let message = |text: &str| {
        read_svg(text, &Placement::default(), &SvgOptions::default())
            .unwrap_err()
            .to_string()
    };
    let empty = r#"<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"></svg>"#;
    assert!(matches!(
        read_svg(empty, &Placement::default(), &SvgOptions::default()),
        Err(SvgError::Empty { dropped: 0, .. })
    ));
    assert_eq!(
        message(empty),
        "the drawing holds no stroke: no path, line, polyline, polygon, rect, circle or \
         ellipse with a length of at least 0.001 m (0 shorter dropped; text and images are \
         not drawn)"
    );
    // Invisible or unpainted elements draw nothing.
    let hidden = svg(concat!(
        r#"<rect width="10" height="10" fill="none"/>"#,
        r#"<rect width="10" height="10" visibility="hidden"/>"#
    ));
    assert!(message(&hidden).contains("holds no stroke"));
    assert!(message("hello, world").starts_with("the text is not SVG: "));
    assert_eq!(
        message("<html><body/></html>"),
        "the text is not SVG: its root element is <html>, not <svg>"
    );
    assert!(message("<svg><rect width='1' height='1'/></svg>").contains("SVG namespace"));
    assert!(
        message("<svg xmlns='http://www.w3.org/2000/svg'><rect").starts_with("the text is not SVG")
    );
}

#[test]
fn a_drawing_without_width_needs_a_scale() {
    let text = svg(r#"<line x1="5" y1="0" x2="5" y2="50" stroke="black"/>"#);
    let error = read_svg(&text, &Placement::default(), &SvgOptions::default()).unwrap_err();
    assert!(matches!(error, SvgError::ZeroWidth { .. }));
    assert!(
        error.to_string().contains("give 'scale_m_per_unit'"),
        "{error}"
    );
    let placement = Placement {
        scale_m_per_unit: Some(1e-3),
        width_m: None,
        ..Placement::default()
    };
    let drawing = read_and_check(&text, &placement, &SvgOptions::default());
    assert_eq!(drawing.size_m(), [0.0, 0.05]);
}

#[test]
fn bad_placements_and_options_are_refused_naming_the_field() {
    let text = icon("heart");
    let refused = |placement: Placement, options: SvgOptions| {
        read_svg(&text, &placement, &options)
            .unwrap_err()
            .to_string()
    };
    let base = Placement::default;
    let options = SvgOptions::default;
    let cases = [
        (
            Placement {
                normal: [0.0; 3],
                ..base()
            },
            "placement field 'normal' is a zero vector",
        ),
        (
            Placement {
                x_axis: [0.0, 0.0, 2.0],
                ..base()
            },
            "placement field 'x_axis' [0.0, 0.0, 2.0] is parallel to 'normal'",
        ),
        (
            Placement {
                origin_m: [f64::NAN, 0.0, 0.0],
                ..base()
            },
            "placement field 'origin_m' is not finite",
        ),
        (
            Placement {
                width_m: Some(0.0),
                ..base()
            },
            "placement field 'width_m' is 0; it must be a positive length",
        ),
        (
            Placement {
                width_m: Some(-0.1),
                ..base()
            },
            "placement field 'width_m' is -0.1",
        ),
        (
            Placement {
                scale_m_per_unit: Some(0.01),
                ..base()
            },
            "give one of them",
        ),
        (
            Placement {
                width_m: None,
                ..base()
            },
            "give 'width_m' or 'scale_m_per_unit'",
        ),
        (
            Placement {
                width_m: None,
                scale_m_per_unit: Some(f64::INFINITY),
                ..base()
            },
            "placement field 'scale_m_per_unit' is inf",
        ),
    ];
    for (placement, expected) in cases {
        let message = refused(placement, options());
        assert!(
            message.starts_with("placement field '") && message.contains(expected),
            "{message}"
        );
    }
    let message = refused(
        base(),
        SvgOptions {
            curve_tolerance_m: 0.0,
            ..options()
        },
    );
    assert!(
        message.starts_with("SVG option 'curve_tolerance_m' is 0; it must be at least 0.000001 m"),
        "{message}"
    );
    let message = refused(
        base(),
        SvgOptions {
            min_stroke_m: f64::NAN,
            ..options()
        },
    );
    assert!(
        message.starts_with("SVG option 'min_stroke_m' is NaN"),
        "{message}"
    );
    let message = refused(
        base(),
        SvgOptions {
            smooth_join_deg: 60.0,
            ..options()
        },
    );
    assert_eq!(
        message,
        "SVG option 'smooth_join_deg' is 60; it must be within [0, 45] degrees"
    );
}

#[test]
fn placements_and_options_read_from_json() {
    let placement: Placement = serde_json::from_str(
        r#"{"origin_m": [0.5, 0, 0.2], "normal": [0, 0, -1], "x_axis": [1, 0, 0],
            "scale_m_per_unit": 0.001}"#,
    )
    .unwrap();
    assert_eq!(placement.scale_m_per_unit, Some(0.001));
    assert_eq!(placement.width_m, None);
    let back: Placement =
        serde_json::from_str(&serde_json::to_string(&placement).unwrap()).unwrap();
    assert_eq!(back, placement);
    let unknown = serde_json::from_str::<Placement>(
        r#"{"origin_m": [0, 0, 0], "normal": [0, 0, 1], "x_axis": [1, 0, 0], "width": 1}"#,
    )
    .unwrap_err();
    assert!(
        unknown.to_string().contains("unknown field `width`"),
        "{unknown}"
    );
    let options: SvgOptions = serde_json::from_str(r#"{"curve_tolerance_m": 1e-5}"#).unwrap();
    assert_eq!(options.min_stroke_m, SvgOptions::default().min_stroke_m);
    assert_eq!(options.curve_tolerance_m, 1e-5);
}

#[test]
fn files_are_named_in_errors() {
    let drawing = read_svg_file(
        &icon_path("anchor"),
        &Placement::default(),
        &SvgOptions::default(),
    )
    .unwrap();
    // The shaft, the arc with its barbs, the crossbar, the ring.
    assert_eq!(drawing.strokes.len(), 4);
    let missing = icon_path("no-such-icon");
    let error = read_svg_file(&missing, &Placement::default(), &SvgOptions::default()).unwrap_err();
    assert!(matches!(error, SvgFileError::Io { .. }));
    assert!(error.to_string().contains("no-such-icon.svg"), "{error}");
    let readme = icon_path("x").with_file_name("README.md");
    let error = read_svg_file(&readme, &Placement::default(), &SvgOptions::default()).unwrap_err();
    let message = error.to_string();
    assert!(
        message.starts_with("SVG file ") && message.contains("README.md: the text is not SVG"),
        "{message}"
    );
}

#[test]
fn no_input_panics() {
    let placement = Placement::default();
    let options = SvgOptions::default();
    let texts = [
        String::new(),
        "<".into(),
        svg(""),
        svg(r#"<path d="M 1 1"/>"#),
        svg(r#"<path d="M 1 1 Z"/>"#),
        svg(r#"<path d="M 1 1 L 1 1 L 1 1 Z"/>"#),
        svg(r#"<path d="M 0 0 C 0 0 0 0 0 0"/>"#),
        svg(r#"<path d="M 0 0 C 10 10 0 10 10 0 M 5 5 C 5 5 5 5 6 5" stroke="black"/>"#),
        svg(r#"<path d="M 0 0 L 1e30 1e30" stroke="black"/>"#),
        svg(r#"<circle r="1e-20"/>"#),
        svg(r#"<path d="M 0 0 L NaN 5" stroke="black"/>"#),
        svg(r#"<g transform="scale(0)"><rect width="10" height="10"/></g>"#),
        svg(r#"<g transform="matrix(1 0 0 0 0 0)"><rect width="10" height="10"/></g>"#),
        svg(r#"<text x="0" y="10">hi</text>"#),
        svg(r##"<use href="#a"/><g id="a"><use href="#a"/></g>"##),
    ];
    for text in &texts {
        for placement in [
            placement.clone(),
            Placement {
                scale_m_per_unit: Some(1e300),
                width_m: None,
                ..placement.clone()
            },
        ] {
            if let Ok(drawing) = read_svg(text, &placement, &options) {
                for spec in &drawing.strokes {
                    Path::new(spec.clone()).unwrap();
                }
            }
        }
    }
}
