//! `Robot`: a robot file's kinematic chain, for forward kinematics and Jacobians.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use emg_kinematics::JointVector;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use emg_io::RobotRef;
use emg_planner::ShippedRobot;

use crate::data::{data_dir, robot_file};
use crate::errors::{InputError, input_error, message};

/// A serial arm of six or seven revolute joints from a robot file: `Robot("fr3")`,
/// `Robot("iiwa14")`, `Robot("ur5e")` or `Robot(path)` (the chain from the file's root link to
/// its only leaf link).
#[pyclass(frozen, module = "extreme_line_motion")]
pub struct Robot {
    pub(crate) inner: Arc<emg_kinematics::Robot>,
    pub(crate) file: PathBuf,
    /// How written files name it ([`RobotRef`]'s text).
    pub(crate) reference: String,
    /// A shipped arm's home (rad, one value per joint, [`ShippedRobot::home`]); `None` for
    /// another robot file.
    pub(crate) home: Option<&'static [f64]>,
}

impl Robot {
    /// Loads the robot `robot` selects (shipped name or path).
    pub(crate) fn load(robot: &Path) -> PyResult<Self> {
        let file = robot_file(robot)?;
        let inner = emg_kinematics::Robot::from_chain_file(&file)
            .map_err(|e| input_error(format!("robot {}", file.display()), &e))?;
        let shipped = ShippedRobot::by_path(&file, &data_dir()?);
        let reference = match shipped {
            Some(shipped) => RobotRef::shipped(shipped.name, &file),
            None => RobotRef::file(&file),
        }
        .map_err(|e| input_error(format!("robot {}", file.display()), &e))?;
        Ok(Self {
            inner: Arc::new(inner),
            file,
            reference: reference.to_string(),
            home: shipped.map(|shipped| shipped.home),
        })
    }

    /// Loads the robot that the `robot` field of `file` names (see [`RobotRef::resolve`]), or
    /// `given` (a shipped robot's name or a robot file) when there is one.
    pub(crate) fn named(field: &str, file: &Path, given: Option<&Path>) -> PyResult<Self> {
        if let Some(given) = given {
            return Self::load(given);
        }
        let reference = RobotRef::parse(field).map_err(|e| input_error(file.display(), &e))?;
        let data = data_dir()?;
        let shipped = |name: &str| ShippedRobot::by_name(name).map(|robot| robot.path(&data));
        let path = reference
            .resolve(shipped, file)
            .map_err(|e| InputError::new_err(message(&e)))?;
        Self::load(&path)
    }
}

/// The configuration of `robot` from `q`, one angle (rad) per joint; `field` names the argument
/// in the error when the count is not the arm's.
pub(crate) fn joint_vector(
    robot: &emg_kinematics::Robot,
    q: &[f64],
    field: &str,
) -> PyResult<JointVector> {
    if q.len() != robot.dof() {
        return Err(InputError::new_err(format!(
            "{field}: give {} joint angles (rad), one per joint of the arm; got {}",
            robot.dof(),
            q.len()
        )));
    }
    Ok(robot.joint_vector(q))
}

/// The arm's `n` entries of `q` as an array, shape (n,).
pub(crate) fn joint_array<'py>(
    py: Python<'py>,
    robot: &emg_kinematics::Robot,
    q: &JointVector,
) -> Bound<'py, PyArray1<f64>> {
    array1(py, robot.joints_of(q).iter().copied())
}

/// Rows of the arm's `joints` entries of each vector, shape (len, joints).
pub(crate) fn joint_rows<'py, 'q>(
    py: Python<'py>,
    joints: usize,
    rows: impl ExactSizeIterator<Item = &'q JointVector>,
) -> Bound<'py, PyArray2<f64>> {
    let count = rows.len();
    let flat: Vec<f64> = rows.flat_map(|q| q.as_slice()[..joints].to_vec()).collect();
    Array2::from_shape_vec((count, joints), flat)
        .expect("rows of the arm's joints")
        .into_pyarray(py)
}

/// `values` as an array, shape (len,).
pub(crate) fn array1<'py>(
    py: Python<'py>,
    values: impl IntoIterator<Item = f64>,
) -> Bound<'py, PyArray1<f64>> {
    values.into_iter().collect::<Vec<_>>().into_pyarray(py)
}

#[pymethods]
impl Robot {
    #[new]
    #[pyo3(signature = (robot = PathBuf::from("fr3")), text_signature = "(robot='fr3')")]
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

    /// Names of the arm's `n` joints (6 or 7), base to tip (the order of every `q`).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joint_names().to_vec()
    }

    /// Number of joints `n` (6 or 7).
    #[getter]
    fn dof(&self) -> usize {
        self.inner.dof()
    }

    /// Lower joint limits (rad), shape (n,).
    #[getter]
    fn lower_limits<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        joint_array(py, &self.inner, &self.inner.limits().lower)
    }

    /// Upper joint limits (rad), shape (n,).
    #[getter]
    fn upper_limits<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        joint_array(py, &self.inner, &self.inner.limits().upper)
    }

    /// Joint velocity limits (rad/s), shape (n,).
    #[getter]
    fn velocity_limits<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        joint_array(py, &self.inner, &self.inner.limits().velocity)
    }

    /// A shipped arm's home (rad), shape (n,): its vendor's home or ready pose, where a job's
    /// program starts and ends unless given another (docs/jobs.md#home); `None` for another
    /// robot file.
    #[getter]
    fn home<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.home.map(|home| array1(py, home.iter().copied()))
    }

    /// The tool-centre-point pose at `q` (n joint angles, rad) as a 4×4 homogeneous transform in
    /// the base frame (rotation columns: the TCP frame's axes; the tool axis is the third).
    fn fk<'py>(&self, py: Python<'py>, q: Vec<f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let kinematics = self.inner.forward(&joint_vector(&self.inner, &q, "q")?);
        let (rotation, tcp) = (kinematics.tcp_rotation(), kinematics.tcp());
        let mut pose = Array2::<f64>::eye(4);
        for row in 0..3 {
            for column in 0..3 {
                pose[[row, column]] = rotation[(row, column)];
            }
            pose[[row, 3]] = tcp[row];
        }
        Ok(pose.into_pyarray(py))
    }

    /// The position Jacobian `∂tcp/∂q` at `q` (n joint angles, rad), shape (3, n).
    fn jacobian<'py>(&self, py: Python<'py>, q: Vec<f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let kinematics = self.inner.forward(&joint_vector(&self.inner, &q, "q")?);
        let jacobian = kinematics.jacobian();
        Ok(
            Array2::from_shape_fn((3, self.inner.dof()), |(row, column)| {
                jacobian[(row, column)]
            })
            .into_pyarray(py),
        )
    }

    fn __repr__(&self) -> String {
        format!("Robot({:?})", self.file.display().to_string())
    }
}
