//! `Motion`: a plan timed rest to rest within joint limits, as numpy arrays.

use emg_kinematics::JointVector;
use emg_planner::MotionTiming;
use emg_timing::{TimedMotion, TimedSample};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::robot::{array1, joint_rows};

/// A plan timed rest to rest: a C² path through the planned steps, time-optimal within the
/// joint velocity and acceleration limits and the tool-speed cap, jerk-limited, sampled at a
/// fixed rate. Arrays have one row per sample.
#[pyclass(frozen, module = "extreme_line_motion")]
pub struct Motion {
    pub(crate) motion: TimedMotion,
    pub(crate) timing: MotionTiming,
}

impl Motion {
    /// The knots and waypoints of every stretch one after another (each stretch's parameters
    /// after the previous one's end, the knot two stretches share once), and the indices of
    /// the shared knots (the rests).
    fn joined(&self) -> (Vec<(f64, JointVector)>, Vec<usize>) {
        let mut knots: Vec<(f64, JointVector)> = Vec::new();
        let mut rests = Vec::new();
        for path in &self.motion.paths {
            let Some(spline) = path.spline() else {
                continue;
            };
            let (offset, skip) = match knots.last() {
                Some(&(s, _)) => {
                    rests.push(knots.len() - 1);
                    (s, 1)
                }
                None => (0.0, 0),
            };
            knots.extend(
                spline
                    .knots()
                    .iter()
                    .zip(spline.values())
                    .skip(skip)
                    .map(|(s, q)| (s + offset, *q)),
            );
        }
        (knots, rests)
    }

    /// One joint vector of every sample, picked by `value`, shape (N, n).
    fn sample_rows<'py>(
        &self,
        py: Python<'py>,
        value: impl Fn(&TimedSample) -> &JointVector,
    ) -> Bound<'py, PyArray2<f64>> {
        joint_rows(
            py,
            self.timing.joints(),
            self.motion.samples.iter().map(value),
        )
    }
}

#[pymethods]
impl Motion {
    /// Sample times (s), shape (N,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.motion.samples.iter().map(|s| s.time_s()))
    }

    /// Joint positions (rad), shape (N, n).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.sample_rows(py, |s| &s.q)
    }

    /// Joint velocities (rad/s), shape (N, n).
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.sample_rows(py, |s| &s.qd)
    }

    /// Joint accelerations (rad/s²), shape (N, n).
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.sample_rows(py, |s| &s.qdd)
    }

    /// Time from rest to rest (s).
    #[getter]
    fn duration_s(&self) -> f64 {
        self.motion.report.duration_s
    }

    /// Time of the fastest motion along the same path within the velocity, acceleration and
    /// tool-speed limits, without jerk limits (TOPP-RA on `grid`) (s).
    #[getter]
    fn time_optimal_s(&self) -> f64 {
        self.motion.report.time_optimal_s
    }

    /// Share of the duration with the tool at ≥ 99 % of the requested speed.
    #[getter]
    fn tool_speed_share(&self) -> f64 {
        self.motion.report.tool_speed_share
    }

    /// The path's knots: its parameter (m of TCP travel) at each waypoint, shape (K,); the
    /// stretches between rests ([`rest_knots`]) one after another.
    #[getter]
    fn knots<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.joined().0.into_iter().map(|(s, _)| s))
    }

    /// The waypoints the path passes through at its knots (rad), shape (K, n): between two
    /// rests (`rest_knots`, and the ends) the path is the natural cubic spline through them
    /// (`scipy.interpolate.CubicSpline(knots[a:b+1], waypoints[a:b+1], bc_type="natural")`).
    #[getter]
    fn waypoints<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let waypoints: Vec<JointVector> = self.joined().0.into_iter().map(|(_, q)| q).collect();
        joint_rows(py, self.timing.joints(), waypoints.iter())
    }

    /// Indices of the knots at which the motion rests inside the path (the corners a path task
    /// does not blend), shape (R,); empty on a line.
    #[getter]
    fn rest_knots<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<usize>> {
        PyArray1::from_vec(py, self.joined().1)
    }

    /// Path parameters of the TOPP-RA grid, shape (M,).
    #[getter]
    fn grid<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.motion.grid_s.iter().copied())
    }

    /// The joint limits the samples hold (after scaling, at most the robot file's velocity
    /// limits): `{"velocity": (n,), "acceleration": (n,), "jerk": (n,)}`.
    #[getter]
    fn limits<'py>(
        &self,
        py: Python<'py>,
    ) -> std::collections::BTreeMap<&'static str, Bound<'py, PyArray1<f64>>> {
        let limits = &self.timing.request().limits;
        let joints = |values: &JointVector| {
            array1(
                py,
                values.as_slice()[..self.timing.joints()].iter().copied(),
            )
        };
        [
            ("velocity", joints(&limits.velocity)),
            ("acceleration", joints(&limits.acceleration)),
            ("jerk", joints(&limits.jerk)),
        ]
        .into()
    }

    /// Largest tool speed asked for (m/s).
    #[getter]
    fn tool_speed(&self) -> f64 {
        self.timing.request().tool_speed_m_per_s
    }

    fn __repr__(&self) -> String {
        format!(
            "Motion(duration_s={:.3}, samples={}, time_optimal_s={:.3})",
            self.motion.report.duration_s,
            self.motion.samples.len(),
            self.motion.report.time_optimal_s
        )
    }
}
