#![allow(dead_code)]

use emg_control::{Path, PathSpec};
use emg_io::{Drawing, Placement, SvgOptions, parse_path, read_svg};
use emg_kinematics::Vec3;
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
        .map(|p| (path.locate(p, 0.0, path.length_m()).point - p).norm())
        .fold(0.0, f64::max);
    let back = path_points(path, 2e-4)
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

#[test]
fn all_icons() {
    let configs: Vec<(f64, f64)> = std::env::var("CONFIGS")
        .unwrap()
        .split(';')
        .map(|c| {
            let v: Vec<f64> = c.split(',').map(|x| x.parse().unwrap()).collect();
            (v[0], v[1])
        })
        .collect();
    for (tol, width) in configs {
        let mut worst = (0.0, String::new());
        let (mut corners, mut strokes, mut dropped, mut segs, mut failed) = (0, 0, 0, 0, 0);
        for entry in std::fs::read_dir("/tmp/lucide/package/icons").unwrap() {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap();
            let placement = Placement {
                width_m: Some(width),
                ..Placement::default()
            };
            let options = SvgOptions {
                curve_tolerance_m: tol,
                ..SvgOptions::default()
            };
            let d = match read_svg(&text, &placement, &options) {
                Ok(d) => d,
                Err(_) => {
                    failed += 1;
                    continue;
                }
            };
            dropped += d.dropped_tiny;
            if d.dropped_tiny > 0 {
                continue;
            }
            let originals = original_strokes(&text, &d, &placement);
            assert_eq!(originals.len(), d.strokes.len(), "{path:?}");
            for (spec, original) in d.strokes.iter().zip(&originals) {
                let p = validated(spec);
                strokes += 1;
                segs += spec.segments.len();
                corners += p.corners_m().count();
                let (a, b) = deviations(&p, original);
                let e = a.max(b) / tol;
                if e > worst.0 {
                    worst = (e, format!("{path:?} {a:.3e} {b:.3e}"));
                }
                if e > 1.03 {
                    println!("{path:?}: {a:.3e} {b:.3e}");
                }
            }
        }
        println!(
            "tol {tol} width {width}: failed {failed} strokes {strokes} segments {segs} corners {corners} dropped {dropped} worst {worst:?}"
        );
    }
}
