//! Drawings of the corpus generated here, from fixed seeds: jagged coastlines (closed outlines of
//! thousands of vertices) and maps of regions sharing jagged borders (each region a closed
//! outline, so every inner border is drawn twice, as a published map of states draws it), and
//! lines of Hershey text laid out as SVG polylines.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::fetch::FontLines;

/// Vertices of a generated coastline.
pub const COASTLINE_VERTICES: usize = 1536;

/// The SVG of one polyline per point list (closed as a polygon where `closed`).
fn svg_of(width: f64, height: f64, outlines: &[(Vec<[f64; 2]>, bool)]) -> String {
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {width:.3} {height:.3}\">\n"
    );
    for (points, closed) in outlines {
        let list: Vec<String> = points
            .iter()
            .map(|p| format!("{:.3},{:.3}", p[0], p[1]))
            .collect();
        let element = if *closed { "polygon" } else { "polyline" };
        svg += &format!(
            "<{element} fill=\"none\" stroke=\"black\" points=\"{}\"/>\n",
            list.join(" ")
        );
    }
    svg + "</svg>\n"
}

/// A closed jagged outline of about radius 40 round (50, 50): midpoint displacement of a
/// square's corners on the radius, halved in amplitude each level, to [`COASTLINE_VERTICES`].
fn coastline(rng: &mut ChaCha8Rng) -> Vec<[f64; 2]> {
    let mut radii: Vec<f64> = (0..4).map(|_| 40.0 + rng.random_range(-4.0..4.0)).collect();
    let mut amplitude = 6.0;
    while radii.len() < COASTLINE_VERTICES {
        let n = radii.len();
        let mut finer = Vec::with_capacity(2 * n);
        for i in 0..n {
            finer.push(radii[i]);
            let middle = 0.5 * (radii[i] + radii[(i + 1) % n]);
            finer.push(middle + rng.random_range(-amplitude..amplitude));
        }
        radii = finer;
        amplitude *= 0.55;
    }
    let n = radii.len();
    radii
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let a = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
            [50.0 + r * libm::cos(a), 50.0 + r * libm::sin(a)]
        })
        .collect()
}

/// A jagged border from `a` to `b`: midpoint displacement across it, 64 pieces.
fn border(a: [f64; 2], b: [f64; 2], rng: &mut ChaCha8Rng) -> Vec<[f64; 2]> {
    let mut points = vec![a, b];
    let length = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    let mut amplitude = 0.08 * length;
    while points.len() < 65 {
        let mut finer = Vec::with_capacity(2 * points.len());
        for pair in points.windows(2) {
            let (p, q) = (pair[0], pair[1]);
            let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
            let norm = (dx * dx + dy * dy).sqrt().max(1e-9);
            let shift = rng.random_range(-amplitude..amplitude);
            finer.push(p);
            finer.push([
                0.5 * (p[0] + q[0]) - dy / norm * shift,
                0.5 * (p[1] + q[1]) + dx / norm * shift,
            ]);
        }
        finer.push(*points.last().expect("a border has points"));
        points = finer;
        amplitude *= 0.5;
    }
    points
}

/// A map of `columns × rows` regions on a jittered grid, each a closed outline of its four
/// jagged borders (shared with its neighbours).
fn map(columns: usize, rows: usize, rng: &mut ChaCha8Rng) -> Vec<(Vec<[f64; 2]>, bool)> {
    let cell = 100.0 / columns.max(rows) as f64;
    let corners: Vec<Vec<[f64; 2]>> = (0..=rows)
        .map(|j| {
            (0..=columns)
                .map(|i| {
                    let inner = i > 0 && i < columns && j > 0 && j < rows;
                    let jitter = if inner { 0.25 * cell } else { 0.0 };
                    [
                        i as f64 * cell + rng.random_range(-jitter..=jitter),
                        j as f64 * cell + rng.random_range(-jitter..=jitter),
                    ]
                })
                .collect()
        })
        .collect();
    let across: Vec<Vec<Vec<[f64; 2]>>> = (0..=rows)
        .map(|j| {
            (0..columns)
                .map(|i| border(corners[j][i], corners[j][i + 1], rng))
                .collect()
        })
        .collect();
    let down: Vec<Vec<Vec<[f64; 2]>>> = (0..rows)
        .map(|j| {
            (0..=columns)
                .map(|i| border(corners[j][i], corners[j + 1][i], rng))
                .collect()
        })
        .collect();
    let mut regions = Vec::new();
    for j in 0..rows {
        for i in 0..columns {
            let mut outline = across[j][i].clone();
            outline.extend(down[j][i + 1].iter().skip(1));
            outline.extend(across[j + 1][i].iter().rev().skip(1));
            outline.extend(down[j][i].iter().rev().skip(1).take(63));
            regions.push((outline, true));
        }
    }
    regions
}

/// The generated outlines: `(name, SVG)` for five coastlines and three maps, from fixed seeds.
pub fn outlines() -> Vec<(String, String)> {
    let mut drawings = Vec::new();
    for seed in 0..5u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(7800 + seed);
        let outline = coastline(&mut rng);
        drawings.push((
            format!("coastline-{seed}"),
            svg_of(100.0, 100.0, &[(outline, true)]),
        ));
    }
    for (seed, (columns, rows)) in [(3usize, 3usize), (4, 3), (5, 4)].into_iter().enumerate() {
        let mut rng = ChaCha8Rng::seed_from_u64(7900 + seed as u64);
        drawings.push((
            format!("map-{columns}x{rows}"),
            svg_of(100.0, 100.0, &map(columns, rows, &mut rng)),
        ));
    }
    drawings
}

/// Each line of each font as a drawing: `(font: line, SVG)`, its strokes as polylines (y
/// turned downward, as SVG draws it).
pub fn text(fonts: &[(String, FontLines)], lines: &[&str]) -> Vec<(String, String)> {
    let mut drawings = Vec::new();
    for (font, rendered) in fonts {
        for (line, strokes) in lines.iter().zip(rendered) {
            let outlines: Vec<(Vec<[f64; 2]>, bool)> = strokes
                .iter()
                .filter(|stroke| stroke.len() >= 2)
                .map(|stroke| (stroke.iter().map(|p| [p[0], -p[1]]).collect(), false))
                .collect();
            let points = outlines.iter().flat_map(|(points, _)| points);
            let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for p in points {
                for k in 0..2 {
                    low[k] = low[k].min(p[k]);
                    high[k] = high[k].max(p[k]);
                }
            }
            if outlines.is_empty() {
                continue;
            }
            let moved: Vec<(Vec<[f64; 2]>, bool)> = outlines
                .into_iter()
                .map(|(points, closed)| {
                    let points = points
                        .into_iter()
                        .map(|p| [p[0] - low[0] + 1.0, p[1] - low[1] + 1.0])
                        .collect();
                    (points, closed)
                })
                .collect();
            drawings.push((
                format!("{font}: {line}"),
                svg_of(high[0] - low[0] + 2.0, high[1] - low[1] + 2.0, &moved),
            ));
        }
    }
    drawings
}
