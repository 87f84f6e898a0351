//! A generated drawing for measuring jobs at scale: many short strokes scattered evenly.

/// A drawing of `strokes` short strokes (3 to 12 units long, one `<path>` each) scattered over a
/// 200-unit square (a 224-unit view box with a margin), deterministic: the start of stroke `k`
/// and its direction from low-discrepancy steps (golden-ratio and plastic-number fractions), its
/// length `3 + k mod 10` units. At the default width (0.2 m) the strokes are 3–12 mm long in a
/// 0.2 m square: the plotter drawings, hatched fills and seam patterns of jobs at production
/// scale (docs/jobs.md, docs/results/jobs.md).
pub fn scattered_strokes_svg(strokes: usize) -> String {
    let mut paths = String::new();
    for k in 0..strokes {
        let x = (k as f64 * 0.618_033_988_749_895).fract() * 200.0;
        let y = (k as f64 * 0.754_877_666_246_693).fract() * 200.0;
        let (u, v) = (
            (k as f64 * 0.381_966).fract() - 0.5,
            (k as f64 * 0.569_840).fract() - 0.45,
        );
        let length = (3.0 + (k % 10) as f64) / (u * u + v * v).sqrt().max(0.05);
        paths.push_str(&format!(
            "<path d=\"M{x:.3},{y:.3} L{:.3},{:.3}\"/>",
            x + length * u,
            y + length * v
        ));
    }
    format!("<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"-12 -12 224 224\">{paths}</svg>")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::svg::{Placement, SvgOptions, read_svg};

    #[test]
    fn the_drawing_holds_short_strokes_in_a_square_of_the_default_width() {
        let drawing = read_svg(
            &scattered_strokes_svg(200),
            &Placement::default(),
            &SvgOptions::default(),
        )
        .expect("the drawing reads");
        // Stroke 0 has no length and is dropped as tiny.
        assert_eq!(drawing.strokes.len() + drawing.dropped_tiny, 200);
        for stroke in &drawing.strokes {
            let length = emg_control::Path::new(stroke.clone())
                .expect("a path")
                .length_m();
            assert!((0.0029..=0.0121).contains(&length), "{length}");
        }
        assert_eq!(scattered_strokes_svg(200), scattered_strokes_svg(200));
    }
}
