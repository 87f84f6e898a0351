//! `Robot`: a robot file's kinematic chain, for forward kinematics and Jacobians.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use emg_kinematics::JointVector;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::{input_error, robot_file};

/// A 7-DoF serial arm from a robot file: `Robot("fr3")`, `Robot("iiwa14")` or `Robot(path)`
/// (the chain from the file's root link to its only leaf link).
#[pyclass(frozen, module = "extreme_line_motion")]
pub struct Robot {
    pub(crate) inner: Arc<emg_kinematics::Robot>,
    pub(crate) file: PathBuf,
}

impl Robot {
    /// Loads the robot `robot` selects (shipped name or path).
    pub(crate) fn load(robot: &Path) -> PyResult<Self> {
        let file = robot_file(robot)?;
        let inner = emg_kinematics::Robot::from_chain_file(&file)
            .map_err(|e| input_error(format!("robot {}", file.display()), &e))?;
        Ok(Self {
            inner: Arc::new(inner),
            file,
        })
    }
}

/// A joint configuration from a sequence of 7 floats (rad).
pub(crate) fn joint_vector(q: [f64; 7]) -> JointVector {
    JointVector::from(q)
}

fn vector<'py>(
    py: Python<'py>,
    values: impl IntoIterator<Item = f64>,
) -> Bound<'py, PyArray1<f64>> {
    values.into_iter().collect::<Vec<_>>().into_pyarray(py)
}

#[pymethods]
impl Robot {
    #[new]
    #[pyo3(signature = (robot = PathBuf::from("fr3")))]
    fn new(robot: PathBuf) -> PyResult<Self> {
        Self::load(&robot)
    }

    /// The robot file (a shipped robot's file, or the path as given).
    #[getter]
    fn file(&self) -> PathBuf {
        self.file.clone()
    }

    /// The robot's name in its file.
    #[getter]
    fn name(&self) -> &str {
        self.inner.name()
    }

    /// Names of the seven joints, base to tip (the order of every `q`).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joint_names().to_vec()
    }

    /// Lower joint limits (rad), shape (7,).
    #[getter]
    fn lower_limits<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.inner.limits().lower.iter().copied())
    }

    /// Upper joint limits (rad), shape (7,).
    #[getter]
    fn upper_limits<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.inner.limits().upper.iter().copied())
    }

    /// Joint velocity limits (rad/s), shape (7,).
    #[getter]
    fn velocity_limits<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.inner.limits().velocity.iter().copied())
    }

    /// The tool-centre-point pose at `q` (7 joint angles, rad) as a 4×4 homogeneous transform in
    /// the base frame (rotation columns: the TCP frame's axes; the tool axis is the third).
    fn fk<'py>(&self, py: Python<'py>, q: [f64; 7]) -> Bound<'py, PyArray2<f64>> {
        let kinematics = self.inner.forward(&joint_vector(q));
        let (rotation, tcp) = (kinematics.tcp_rotation(), kinematics.tcp());
        let mut pose = Array2::<f64>::eye(4);
        for row in 0..3 {
            for column in 0..3 {
                pose[[row, column]] = rotation[(row, column)];
            }
            pose[[row, 3]] = tcp[row];
        }
        pose.into_pyarray(py)
    }

    /// The position Jacobian `∂tcp/∂q` at `q` (7 joint angles, rad), shape (3, 7).
    fn jacobian<'py>(&self, py: Python<'py>, q: [f64; 7]) -> Bound<'py, PyArray2<f64>> {
        let kinematics = self.inner.forward(&joint_vector(q));
        let jacobian = kinematics.jacobian();
        Array2::from_shape_fn((3, 7), |(row, column)| jacobian[(row, column)]).into_pyarray(py)
    }

    fn __repr__(&self) -> String {
        format!("Robot({:?})", self.file.display().to_string())
    }
}
