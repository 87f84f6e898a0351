//! What a timed motion's samples are computed from: its paths in joint space and the
//! jerk-limited speed profile along each ([`ProfileGrid`]). Sampling a [`MotionDefinition`] at
//! the rate it was timed for gives the samples the timing gave, sample for sample, so a program
//! can keep the definition (which grows with the path) instead of its samples (which grow with
//! the motion's duration).

use emg_kinematics::JointVector;

use crate::blended_path::BlendedPath;
use crate::dynamics::TimedSample;
use crate::profile::{SmoothedProfile, SpeedProfile};
use crate::sampling::{at_rest, push_samples, sample};
use crate::spline::JointSpline;

/// Most samples one motion may have: a rate or tool speed that would give more is refused
/// (ten million samples are almost three hours at 1 kHz).
pub const MAX_SAMPLES: f64 = 1e7;

/// A rest-to-rest speed profile along a path as the timing chose it: the path speeds
/// `x_i = ṡ²` at the grid points `s_i` (TOPP-RA's, `s̈` constant between them:
/// [`SpeedProfile`]) averaged over `window` seconds ([`SmoothedProfile`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileGrid {
    /// The grid's path parameters, increasing strictly.
    pub s: Vec<f64>,
    /// `ṡ²` at each grid point: 0 at both ends, not negative between, and never 0 at two
    /// neighbouring points (a stroke may touch rest at a grid point, as TOPP-RA's profile does
    /// where a limit stops it there).
    pub x: Vec<f64>,
    /// The averaging window (s), positive.
    pub window_s: f64,
}

impl ProfileGrid {
    /// The profile in time.
    pub fn smoothed(&self) -> SmoothedProfile {
        SmoothedProfile::new(SpeedProfile::new(&self.s, &self.x), self.window_s)
    }

    /// Why this profile cannot be sampled at `rate_hz` (naming the field), if it cannot: fewer
    /// than three grid points, parameters that do not increase strictly, speeds that are not 0 at
    /// the ends, negative between or 0 at two neighbouring points, a window that is not
    /// positive, or more than [`MAX_SAMPLES`] samples.
    pub fn check(&self, rate_hz: f64) -> Result<(), String> {
        if self.s.len() < 3 || !self.s.iter().all(|s| s.is_finite()) {
            return Err("s must hold at least three finite numbers".to_string());
        }
        if !self.s.windows(2).all(|pair| pair[1] > pair[0]) {
            return Err("s must increase strictly".to_string());
        }
        if self.x.len() != self.s.len() {
            return Err(format!(
                "x must hold one speed per grid point ({}), not {}",
                self.s.len(),
                self.x.len()
            ));
        }
        let last = self.x.len() - 1;
        if self.x[0] != 0.0 || self.x[last] != 0.0 {
            return Err("x must be 0 at both ends (rest to rest)".to_string());
        }
        if !self.x[1..last].iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err("x must be finite and not negative between the ends".to_string());
        }
        if self
            .x
            .windows(2)
            .any(|pair| pair[0] == 0.0 && pair[1] == 0.0)
        {
            return Err(
                "x must not be 0 at two neighbouring grid points (the motion would never pass \
                 between them)"
                    .to_string(),
            );
        }
        if !(self.window_s.is_finite() && self.window_s > 0.0) {
            return Err(format!("window_s must be positive, got {}", self.window_s));
        }
        let samples = self.smoothed().duration() * rate_hz;
        if !samples.is_finite() || samples > MAX_SAMPLES {
            return Err(format!(
                "the profile takes {samples:.0} samples, more than {MAX_SAMPLES:.0}"
            ));
        }
        Ok(())
    }
}

/// One stretch of a path task's motion: from rest to rest along a natural cubic spline.
#[derive(Clone, Debug, PartialEq)]
pub struct SplineStretch {
    /// The path.
    pub spline: JointSpline,
    /// The speed along it.
    pub profile: ProfileGrid,
}

/// A rest-to-rest motion as what defines its samples.
#[derive(Clone, Debug, PartialEq)]
pub enum MotionDefinition {
    /// A path task's motion ([`crate::time_motion`]): at rest at `start`, then along each
    /// stretch in turn, at rest between them; no stretch where the path has no length.
    Splines {
        /// Where the motion starts.
        start: JointVector,
        /// The stretches between rests.
        stretches: Vec<SplineStretch>,
    },
    /// A move keeping to a joint polyline ([`crate::time_free_move`]): along each edge in turn,
    /// at rest at every vertex; one profile per edge of at least 1e-9 rad, along the edge's
    /// joint-space length.
    Polyline {
        /// The polyline's vertices.
        vertices: Vec<JointVector>,
        /// The speed along each edge.
        edges: Vec<ProfileGrid>,
    },
    /// A move through a joint polyline with its corners rounded ([`crate::time_blended_move`]),
    /// at rest only at its ends; the profile along the rounded path's joint-space length.
    Blended {
        /// The polyline's vertices.
        vertices: Vec<JointVector>,
        /// How far before its vertex each corner's arc starts, as a share of the shorter of
        /// its edges.
        share: f64,
        /// The speed along the rounded path.
        profile: ProfileGrid,
    },
}

impl MotionDefinition {
    /// The motion's samples at `k / rate_hz` (rounded to whole nanoseconds) from rest to rest:
    /// the samples its timing gave.
    pub fn samples(&self, rate_hz: f64) -> Vec<TimedSample> {
        match self {
            Self::Splines { start, stretches } => spline_samples(start, stretches, rate_hz),
            Self::Polyline { vertices, edges } => polyline_samples(vertices, edges, rate_hz),
            Self::Blended {
                vertices,
                share,
                profile,
            } => BlendedPath::new(vertices, *share).map_or_else(
                || vec![at_rest(vertices[0])],
                |path| path.samples(&profile.smoothed(), rate_hz),
            ),
        }
    }

    /// An upper bound on the motion's duration (s) sampled at `rate_hz`: each profile's
    /// duration and one sampling period.
    pub fn duration_bound_s(&self, rate_hz: f64) -> f64 {
        let profiles: Vec<&ProfileGrid> = match self {
            Self::Splines { stretches, .. } => stretches.iter().map(|s| &s.profile).collect(),
            Self::Polyline { edges, .. } => edges.iter().collect(),
            Self::Blended { profile, .. } => vec![profile],
        };
        profiles
            .iter()
            .map(|profile| profile.smoothed().duration() + 1.0 / rate_hz)
            .sum()
    }

    /// Why this definition cannot be sampled at `rate_hz` (naming the field), if it cannot:
    /// a profile [`ProfileGrid::check`] refuses, a polyline without a vertex or with another
    /// number of profiles than edges, or a blended move whose corners cannot be rounded.
    pub fn check(&self, rate_hz: f64) -> Result<(), String> {
        let profile = |field: String, profile: &ProfileGrid| {
            profile
                .check(rate_hz)
                .map_err(|why| format!("{field}: {why}"))
        };
        match self {
            Self::Splines { stretches, .. } => {
                for (k, stretch) in stretches.iter().enumerate() {
                    profile(format!("stretches[{k}].profile"), &stretch.profile)?;
                }
            }
            Self::Polyline { vertices, edges } => {
                if vertices.is_empty() {
                    return Err("vertices must hold a vertex".to_string());
                }
                let moving = moving_edges(vertices).count();
                if edges.len() != moving {
                    return Err(format!(
                        "edges must hold one profile per edge of at least 1e-9 rad ({moving}), \
                         not {}",
                        edges.len()
                    ));
                }
                for (k, edge) in edges.iter().enumerate() {
                    profile(format!("edges[{k}]"), edge)?;
                }
            }
            Self::Blended {
                vertices,
                share,
                profile: grid,
            } => {
                if !(0.0..=0.5).contains(share) {
                    return Err(format!("share must be within [0, 0.5], got {share}"));
                }
                if BlendedPath::new(vertices, *share).is_none() {
                    return Err(
                        "the corners of its vertices cannot be rounded (one turns back)"
                            .to_string(),
                    );
                }
                profile("profile".to_string(), grid)?;
            }
        }
        Ok(())
    }
}

/// The edges of `vertices` at least 1e-9 rad long: their ends, unit direction and length.
pub(crate) fn moving_edges(
    vertices: &[JointVector],
) -> impl Iterator<Item = (JointVector, JointVector, JointVector, f64)> + '_ {
    vertices.windows(2).filter_map(|edge| {
        let chord = edge[1] - edge[0];
        let length = chord.norm();
        (length >= 1e-9).then(|| (edge[0], edge[1], chord / length, length))
    })
}

/// The samples of the motion along the polyline `vertices`, along each edge of at least 1e-9
/// rad by its profile in `edges` ([`MotionDefinition::Polyline`]).
pub(crate) fn polyline_samples(
    vertices: &[JointVector],
    edges: &[ProfileGrid],
    rate_hz: f64,
) -> Vec<TimedSample> {
    let mut samples = vec![at_rest(vertices[0])];
    // Every sample lies on the grid `k / rate`; an edge's last sample, on the first grid time at
    // or after its end, holds its end vertex at rest.
    let mut elapsed = 0u64;
    for ((from, to, direction, _), profile) in moving_edges(vertices).zip(edges) {
        elapsed = push_samples(
            &profile.smoothed(),
            rate_hz,
            elapsed,
            &to,
            &mut samples,
            |s| (from + direction * s, direction, JointVector::zeros()),
        );
    }
    samples
}

/// The samples of a path task's motion at `rate_hz` ([`MotionDefinition::Splines`]): at rest at
/// `start`, then each stretch's samples after its first, on one grid of `k / rate_hz` (rounded
/// to whole nanoseconds), as [`crate::time_motion`] joins its stretches.
pub(crate) fn spline_samples(
    start: &JointVector,
    stretches: &[SplineStretch],
    rate_hz: f64,
) -> Vec<TimedSample> {
    let mut samples = vec![at_rest(*start)];
    for stretch in stretches {
        let offset = samples.len() as u64 - 1;
        let (part, _) = sample(&stretch.spline, &stretch.profile.smoothed(), rate_hz);
        samples.extend(
            part.iter()
                .enumerate()
                .skip(1)
                .map(|(k, sample)| TimedSample {
                    time_ns: ((offset + k as u64) as f64 * 1e9 / rate_hz).round() as u64,
                    ..*sample
                }),
        );
    }
    samples
}
