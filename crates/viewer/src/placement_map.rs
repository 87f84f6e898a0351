//! The placement map: a heat map over the region of part places, each position coloured by its
//! best score over the turns tried (the turn written in the cell), the best places marked and
//! ranked; an SVG drawn with plotters.

use plotters::prelude::*;

/// One position of the map: its shift (m), its best score in [0, 1] and the turn that gave it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapCell {
    /// Shift along the part frame's x axis (m).
    pub x_m: f64,
    /// Shift along its y axis (m).
    pub y_m: f64,
    /// The best score at this position.
    pub score: f64,
    /// The turn of the best score (degrees).
    pub rotation_deg: f64,
}

/// A position marked on the map with the ranks of its places (1 is the chosen place).
#[derive(Clone, Debug, PartialEq)]
pub struct MapMark {
    /// Shift along x (m).
    pub x_m: f64,
    /// Shift along y (m).
    pub y_m: f64,
    /// The ranks, as written beside the mark ("1", "2, 4").
    pub ranks: String,
}

/// The colour of `score`: dark blue at 0 through green to yellow at 1.
fn colour(score: f64) -> RGBColor {
    let stops = [
        (0.0, (38, 24, 96)),
        (0.5, (33, 145, 140)),
        (1.0, (253, 231, 37)),
    ];
    let t = score.clamp(0.0, 1.0);
    let (low, high) = if t <= 0.5 {
        (stops[0], stops[1])
    } else {
        (stops[1], stops[2])
    };
    let f = (t - low.0) / (high.0 - low.0);
    let mix = |a: u8, b: u8| (f64::from(a) + (f64::from(b) - f64::from(a)) * f).round() as u8;
    RGBColor(
        mix(low.1.0, high.1.0),
        mix(low.1.1, high.1.1),
        mix(low.1.2, high.1.2),
    )
}

/// The map's SVG: `cells` on their grid (spaced evenly; one position makes a 1 cm cell), the
/// `marks` ringed and numbered, `title` above.
pub fn placement_map_svg(cells: &[MapCell], marks: &[MapMark], title: &str) -> String {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (760, 700)).into_drawing_area();
        // Drawing into a string cannot fail; a failure would only leave the picture short.
        let _ = draw(&root, cells, marks, title);
    }
    text
}

/// Distinct sorted values of `values`.
fn levels(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut levels: Vec<f64> = values.collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    levels
}

/// Half the spacing of `levels` (0.005 m for one level).
fn half_step(levels: &[f64]) -> f64 {
    match levels {
        [a, b, ..] => 0.5 * (b - a),
        _ => 0.005,
    }
}

fn draw(
    root: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    cells: &[MapCell],
    marks: &[MapMark],
    title: &str,
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    root.fill(&WHITE)?;
    let xs = levels(cells.iter().map(|c| c.x_m));
    let ys = levels(cells.iter().map(|c| c.y_m));
    let (hx, hy) = (half_step(&xs), half_step(&ys));
    let (x0, x1) = (xs[0] - hx, xs[xs.len() - 1] + hx);
    let (y0, y1) = (ys[0] - hy, ys[ys.len() - 1] + hy);
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("shift along the part's x axis (m)")
        .y_desc("shift along the part's y axis (m)")
        .draw()?;
    chart.draw_series(cells.iter().map(|c| {
        Rectangle::new(
            [(c.x_m - hx, c.y_m - hy), (c.x_m + hx, c.y_m + hy)],
            colour(c.score).filled(),
        )
    }))?;
    chart.draw_series(cells.iter().map(|c| {
        let ink = if c.score > 0.6 { BLACK } else { WHITE };
        Text::new(
            format!("{:.0}%", 100.0 * c.score),
            (c.x_m - 0.6 * hx, c.y_m + 0.35 * hy),
            ("sans-serif", 11).into_font().color(&ink),
        )
    }))?;
    chart.draw_series(cells.iter().map(|c| {
        let ink = if c.score > 0.6 { BLACK } else { WHITE };
        Text::new(
            format!("{:+.0}°", c.rotation_deg),
            (c.x_m - 0.6 * hx, c.y_m - 0.15 * hy),
            ("sans-serif", 10).into_font().color(&ink),
        )
    }))?;
    chart.draw_series(
        marks
            .iter()
            .map(|m| Circle::new((m.x_m, m.y_m), 13, ShapeStyle::from(&RED).stroke_width(3))),
    )?;
    chart.draw_series(marks.iter().map(|m| {
        Text::new(
            m.ranks.clone(),
            (m.x_m + 0.45 * hx, m.y_m - 0.45 * hy),
            ("sans-serif", 15).into_font().color(&RED),
        )
    }))?;
    root.present()?;
    Ok(())
}
