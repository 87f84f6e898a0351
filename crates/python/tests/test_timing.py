"""Timed motions from Python: `Plan.timed` against the files `emg plan` writes, and the
time-optimal part (TOPP-RA without jerk limits) against `toppra` from PyPI on the same path,
grid and limits.
"""

import json
from pathlib import Path

import numpy as np
import pytest

import extreme_line_motion as elm

import toppra
import toppra.algorithm
import toppra.constraint



def test_timed_motion_rests_at_both_ends_and_matches_the_saved_file(planner, tasks, tmp_path):
    task = tasks[3]
    plan = planner.plan(task.p0, task.d, task.n, controller="classical", planner="controller")
    motion = plan.timed(acceleration_scaling=0.5, rate_hz=200)
    assert motion.q.shape == (len(motion.t), 7) and motion.qdd.shape == motion.q.shape
    np.testing.assert_allclose(np.diff(motion.t), 0.005, atol=1e-12)
    assert np.array_equal(motion.q[0], plan.q[0]) and np.array_equal(motion.q[-1], plan.q[-1])
    for end in (0, -1):
        assert not motion.qd[end].any() and not motion.qdd[end].any()
    limits = motion.limits
    assert np.all(np.abs(motion.qd) <= limits["velocity"])
    assert np.all(np.abs(motion.qdd) <= limits["acceleration"])
    assert np.all(np.abs(np.diff(motion.qdd, axis=0)) / 0.005 <= limits["jerk"])
    assert limits["acceleration"][0] == 5.0
    assert motion.duration_s >= motion.time_optimal_s > 0

    stem = tmp_path / "timed"
    plan.save(stem, acceleration_scaling=0.5, rate_hz=200)
    doc = json.loads(Path(f"{stem}.joint_trajectory.json").read_text())
    assert doc["format"] == "emg-joint-trajectory/2"
    positions = np.array([p["positions"] for p in doc["points"]])
    assert np.array_equal(positions, motion.q)
    accelerations = np.array([p["accelerations"] for p in doc["points"]])
    assert np.array_equal(accelerations, motion.qdd)
    assert elm.check(f"{stem}.joint_trajectory.json").points == len(motion.t)

    with pytest.raises(elm.InputError, match="velocity_scaling"):
        plan.timed(velocity_scaling=1.5)
    with pytest.raises(elm.InputError, match="rate_hz"):
        plan.timed(rate_hz=0)
    with pytest.raises(elm.InputError, match="nowhere.yaml"):
        plan.timed(limits=tmp_path / "nowhere.yaml")


class ToolSpeed(toppra.constraint.LinearConstraint):
    """|p'(s)| ṡ ≤ v: a bound on x = ṡ² alone, with p'(s) = J(q(s)) q'(s)."""

    def __init__(self, robot, speed):
        super().__init__()
        self.robot, self.speed = robot, speed

    def compute_constraint_params(self, path, gridpoints, *args, **kwargs):
        bound = np.zeros((len(gridpoints), 2))
        for i, s in enumerate(gridpoints):
            gain = np.linalg.norm(self.robot.jacobian(path(s)) @ path(s, 1))
            bound[i, 1] = (self.speed / gain) ** 2
        return None, None, None, None, None, None, bound


def toppra_duration(robot, motion):
    """toppra's time-optimal duration on the motion's own path, grid and limits."""
    path = toppra.SplineInterpolator(motion.knots, motion.waypoints, bc_type="natural")
    limits = motion.limits
    constraints = [
        toppra.constraint.JointVelocityConstraint(limits["velocity"]),
        toppra.constraint.JointAccelerationConstraint(
            limits["acceleration"],
            discretization_scheme=toppra.constraint.DiscretizationType.Collocation,
        ),
        ToolSpeed(robot, motion.tool_speed),
    ]
    instance = toppra.algorithm.TOPPRA(constraints, path, gridpoints=motion.grid)
    _, sd, _ = instance.compute_parameterization(0, 0)
    assert sd is not None, "toppra found no parametrization"
    return float(np.sum(2 * np.diff(motion.grid) / (sd[:-1] + sd[1:])))


def test_the_time_optimal_duration_is_toppras(planner, tasks):
    """Without jerk limits the duration is within 1 % of toppra's on the same path and grid."""
    ratios, overheads = [], []
    for task in tasks[:12]:
        plan = planner.plan(task.p0, task.d, task.n, planner="controller")
        motion = plan.timed()
        if motion.time_optimal_s == 0:
            continue
        ratios.append(motion.time_optimal_s / toppra_duration(planner.robot, motion))
        overheads.append(motion.duration_s / motion.time_optimal_s - 1)
    print(f"ours / toppra: {np.round(ratios, 5)}; jerk-limited overhead: {np.round(overheads, 3)}")
    assert len(ratios) >= 10
    assert all(abs(r - 1) <= 0.01 for r in ratios), ratios
