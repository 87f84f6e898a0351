//! A drawing's line tolerance, shared between rounding its corners and following its strokes
//! (docs/jobs.md, "Corner rounding").
//!
//! A job drawn from an SVG drawing holds its pen within the line tolerance `e` of the drawing
//! as the user made it. Its corners are rounded within the corner tolerance `c ≤ e`, and the
//! planner follows the rounded strokes within the rest, `e − c`, so that no pen-down sample
//! is farther than `e` from the drawing, corner or not. A job file's strokes are followed as
//! they are, within `e`.

use emg_io::{Drawing, SvgOptions};
use emg_kinematics::Robot;
use emg_planner::Planner;

use crate::spec::{Job, JobError};

/// How a drawing's line tolerance is spent: on rounding its corners and on following them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrawingTolerance {
    /// The line tolerance (m): how far the pen may leave the drawing.
    pub line_m: f64,
    /// The corner tolerance (m): how far the rounding of a corner may leave it (0 keeps every
    /// corner, passed at rest).
    pub corner_m: f64,
}

impl DrawingTolerance {
    /// The tolerance of a drawing at line tolerance `line_m` with its corners rounded within
    /// `corner_m` (m); refused unless `0 ≤ corner_m < line_m`.
    pub fn new(line_m: f64, corner_m: f64) -> Result<Self, JobError> {
        if !(corner_m.is_finite() && (0.0..line_m).contains(&corner_m)) {
            return Err(JobError::CornerTolerance { corner_m, line_m });
        }
        Ok(Self { line_m, corner_m })
    }

    /// The job of `drawing`, read with [`DrawingTolerance::svg_options`]: its strokes, its
    /// settings recording the corner tolerance they were rounded within
    /// ([`crate::JobSettings::corner_tolerance_m`]).
    pub fn job(&self, drawing: Drawing, robot: &Robot) -> Result<Job, JobError> {
        let mut job = Job::from_strokes(drawing.strokes, robot)?;
        job.settings.corner_tolerance_m = self.corner_m;
        Ok(job)
    }

    /// The SVG reader's options that round the drawing's corners within the corner tolerance.
    pub fn svg_options(&self) -> SvgOptions {
        SvgOptions {
            corner_tolerance_m: self.corner_m,
            ..SvgOptions::default()
        }
    }
}

/// `planner` following strokes within its line tolerance less `corner_tolerance_m`, what the
/// rounding of their corners spent of it; `None` where that is 0 (`planner` as it is). Refused
/// unless the corner tolerance is less than the line tolerance.
pub(crate) fn following(
    planner: &Planner,
    corner_tolerance_m: f64,
) -> Result<Option<Planner>, JobError> {
    if corner_tolerance_m == 0.0 {
        return Ok(None);
    }
    let mut config = planner.config().clone();
    let line_m = config.rollout.constraints.line_tolerance_m;
    let shared = DrawingTolerance::new(line_m, corner_tolerance_m)?;
    config.rollout.constraints.line_tolerance_m = shared.line_m - shared.corner_m;
    let planner = planner
        .with_config(config)
        .expect("a configuration with a smaller positive line tolerance is valid");
    Ok(Some(planner))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_corner_tolerance_is_a_part_of_the_line_tolerance_below_it() {
        let tolerance = DrawingTolerance::new(5e-4, 1.25e-4).unwrap();
        assert_eq!(tolerance.svg_options().corner_tolerance_m, 1.25e-4);
        let sharp = DrawingTolerance::new(5e-4, 0.0).unwrap();
        assert_eq!(sharp.svg_options(), emg_io::SvgOptions::default());
        for corner in [5e-4, 1e-3, -1e-6, f64::NAN] {
            let message = DrawingTolerance::new(5e-4, corner).unwrap_err().to_string();
            assert!(message.contains("corner tolerance"), "{message}");
        }
    }
}
