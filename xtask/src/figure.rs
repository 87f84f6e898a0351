//! The drawing style the figures share.

use plotters::coord::CoordTranslate;
use plotters::prelude::*;

/// Draws the legend of `chart`'s labelled series at `position`, on translucent white inside a
/// black border.
pub fn draw_legend<'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, CT>,
    position: SeriesLabelPosition,
) -> anyhow::Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}
