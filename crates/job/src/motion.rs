//! A segment's motion as the program file holds it (`emg-job/3`): what its samples are computed
//! from ([`emg_timing::MotionDefinition`]: its paths in joint space and the speed profile along
//! each), the arm's joints only. It grows with the path, not with the motion's duration; its
//! samples are evaluated where they are read ([`crate::JobFile::points`]).

use emg_kinematics::JointVector;
use emg_timing::{JointSpline, MotionDefinition, ProfileGrid, SplineStretch};
use serde::{Deserialize, Serialize};

/// A rest-to-rest speed profile along a path ([`ProfileGrid`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    /// The grid's path parameters, increasing strictly.
    pub s: Vec<f64>,
    /// The path speed squared `ṡ²` at each grid point: 0 at both ends, not negative between
    /// and never 0 at two neighbours; `s̈` is constant between grid points.
    pub x: Vec<f64>,
    /// The moving average's window (s) over which the profile's `s(t)` is averaged.
    pub window_s: f64,
}

/// A stretch of a stroke part's motion between rests: a natural cubic spline through `values`
/// at `knots` (`q'' = 0` at both ends), and the speed along it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stretch {
    /// The spline's knots (its path parameter at each value), increasing strictly.
    pub knots: Vec<f64>,
    /// The configuration at each knot (rad, one value per joint).
    pub values: Vec<Vec<f64>>,
    /// The speed along the spline.
    pub profile: Profile,
}

/// What a segment's samples are computed from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "path", rename_all = "snake_case")]
pub enum Motion {
    /// A stroke part's motion: at rest at `start`, then along each stretch in turn, at rest
    /// between them (none where the part does not move).
    Splines {
        /// Where the motion starts (rad, one value per joint).
        start: Vec<f64>,
        /// The stretches between rests.
        stretches: Vec<Stretch>,
    },
    /// A move keeping to the segment's `vertices`, at rest at each: along each edge of at least
    /// 1e-9 rad in turn, by its profile along its joint-space length.
    Polyline {
        /// The speed along each such edge.
        edges: Vec<Profile>,
    },
    /// A move through the segment's `vertices` with every corner rounded by a quintic blend
    /// starting `share` of the shorter of its edges before its vertex, at rest only at its ends;
    /// the profile along the rounded path's joint-space length.
    Blended {
        /// How far before its vertex each corner's blend starts, as a share of the shorter edge.
        share: f64,
        /// The speed along the rounded path.
        profile: Profile,
    },
}

impl Motion {
    /// `definition` as the file holds it: the arm's `dof` joints.
    pub fn of(definition: &MotionDefinition, dof: usize) -> Self {
        let joints = |q: &JointVector| q.as_slice()[..dof].to_vec();
        match definition {
            MotionDefinition::Splines { start, stretches } => Self::Splines {
                start: joints(start),
                stretches: stretches
                    .iter()
                    .map(|stretch| Stretch {
                        knots: stretch.spline.knots().to_vec(),
                        values: stretch.spline.values().iter().map(joints).collect(),
                        profile: Profile::of(&stretch.profile),
                    })
                    .collect(),
            },
            MotionDefinition::Polyline { edges, .. } => Self::Polyline {
                edges: edges.iter().map(Profile::of).collect(),
            },
            MotionDefinition::Blended { share, profile, .. } => Self::Blended {
                share: *share,
                profile: Profile::of(profile),
            },
        }
    }

    /// The definition of the motion through `vertices` (the segment's; a move's polyline) for
    /// an arm of `dof` joints, checked for sampling at `rate_hz`; or why it cannot be sampled,
    /// naming the field.
    pub fn definition(
        &self,
        vertices: &[Vec<f64>],
        dof: usize,
        rate_hz: f64,
    ) -> Result<MotionDefinition, String> {
        let polyline = || {
            vertices
                .iter()
                .enumerate()
                .map(|(k, q)| joint_vector(q, dof).map_err(|why| format!("vertices[{k}]: {why}")))
                .collect::<Result<Vec<_>, _>>()
        };
        let definition = match self {
            Self::Splines { start, stretches } => MotionDefinition::Splines {
                start: joint_vector(start, dof).map_err(|why| format!("motion.start: {why}"))?,
                stretches: stretches
                    .iter()
                    .enumerate()
                    .map(|(k, stretch)| {
                        stretch
                            .definition(dof)
                            .map_err(|why| format!("motion.stretches[{k}].{why}"))
                    })
                    .collect::<Result<_, _>>()?,
            },
            Self::Polyline { edges } => MotionDefinition::Polyline {
                vertices: polyline()?,
                edges: edges.iter().map(Profile::grid).collect(),
            },
            Self::Blended { share, profile } => MotionDefinition::Blended {
                vertices: polyline()?,
                share: *share,
                profile: profile.grid(),
            },
        };
        definition
            .check(rate_hz)
            .map_err(|why| format!("motion.{why}"))?;
        Ok(definition)
    }
}

impl Profile {
    /// `grid` as the file holds it.
    fn of(grid: &ProfileGrid) -> Self {
        Self {
            s: grid.s.clone(),
            x: grid.x.clone(),
            window_s: grid.window_s,
        }
    }

    /// The profile as the timing samples it.
    fn grid(&self) -> ProfileGrid {
        ProfileGrid {
            s: self.s.clone(),
            x: self.x.clone(),
            window_s: self.window_s,
        }
    }
}

impl Stretch {
    /// The stretch as the timing samples it, or why it cannot be (naming the field).
    fn definition(&self, dof: usize) -> Result<SplineStretch, String> {
        if self.knots.len() < 2 || !self.knots.iter().all(|s| s.is_finite()) {
            return Err("knots: must hold at least two finite numbers".to_string());
        }
        if !self.knots.windows(2).all(|pair| pair[1] > pair[0]) {
            return Err("knots: must increase strictly".to_string());
        }
        if self.values.len() != self.knots.len() {
            return Err(format!(
                "values: must hold one configuration per knot ({}), not {}",
                self.knots.len(),
                self.values.len()
            ));
        }
        let values = self
            .values
            .iter()
            .enumerate()
            .map(|(k, q)| joint_vector(q, dof).map_err(|why| format!("values[{k}]: {why}")))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(SplineStretch {
            spline: JointSpline::natural(self.knots.clone(), values),
            profile: self.profile.grid(),
        })
    }
}

/// `values` as a joint vector, or why it is not one: `dof` finite numbers.
fn joint_vector(values: &[f64], dof: usize) -> Result<JointVector, String> {
    if values.len() != dof || dof > emg_kinematics::MAX_DOF {
        return Err(format!(
            "must hold one value per joint ({dof}), not {}",
            values.len()
        ));
    }
    if !values.iter().all(|v| v.is_finite()) {
        return Err("must hold finite numbers".to_string());
    }
    Ok(JointVector::from_fn(|i, _| {
        values.get(i).copied().unwrap_or(0.0)
    }))
}
