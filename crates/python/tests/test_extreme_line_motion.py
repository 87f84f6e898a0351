"""Tests of the extreme_line_motion module against the `emg` CLI and the library's own checks.

EMG_CLI names the `emg` binary to compare with (default: target/debug/emg of this checkout).
"""

import json
import math
import os
import shutil
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import extreme_line_motion as elm

ROOT = Path(__file__).resolve().parents[3]
CLI = Path(os.environ.get("EMG_CLI", ROOT / "target" / "debug" / "emg"))
EVAL_TASKS = ROOT / "data" / "tasks" / "eval-v1.tasks"
FILES = (".json", ".csv", ".joint_trajectory.json")


def vector(values):
    return ",".join(repr(float(v)) for v in values)


def run_cli(*args):
    assert CLI.is_file(), f"{CLI} is missing: build it with `cargo build -p emg-cli` or set EMG_CLI"
    done = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def assert_same_files(python_stem, cli_stem):
    for suffix in FILES:
        ours = Path(f"{python_stem}{suffix}").read_bytes()
        theirs = Path(f"{cli_stem}{suffix}").read_bytes()
        assert ours == theirs, f"{python_stem}{suffix} differs from the CLI's {cli_stem}{suffix}"


@pytest.mark.parametrize(
    "options",
    [
        {"seed": "dp", "controller": "hybrid", "planner": "controller", "reach": True},
        {"seed": "home", "controller": "classical", "planner": "controller", "reach": False},
        {"seed": "dp", "controller": "rl", "planner": "search", "reach": True},
    ],
)
def test_plan_and_save_equal_the_cli_byte_for_byte(tmp_path, planner, tasks, options):
    task = tasks[3]
    plan = planner.plan(task.p0, task.d, task.n, **options)
    written = plan.save(tmp_path / "python")
    assert [Path(p).name for p in written] == [f"python{s}" for s in FILES]
    run_cli(
        "plan", "--p0", vector(task.p0), "--d", vector(task.d), "--n", vector(task.n),
        "--seed", options["seed"], "--controller", options["controller"],
        "--planner", options["planner"], "--reach", "on" if options["reach"] else "off",
        "--surface", "off", "--out", tmp_path / "cli",
    )
    assert_same_files(tmp_path / "python", tmp_path / "cli")
    record = json.loads((tmp_path / "python.json").read_text())
    assert record["path_length_m"] == plan.path_length_m
    assert ("reachable_m" in record) == options["reach"]


def test_plan_many_equals_the_cli_on_a_task_file(tmp_path, planner, tasks):
    chosen = tasks[:4]
    task_file = tmp_path / "tasks.json"
    task_file.write_text(json.dumps([
        {"p0": t.p0.tolist(), "d": t.d.tolist(), "n": t.n.tolist(), "q0_seed": t.q0_seed.tolist()}
        for t in chosen
    ]))
    plans = planner.plan_many(chosen, controller="hybrid", planner="controller", reach=False)
    run_cli("plan", "--task-file", task_file, "--controller", "hybrid", "--planner", "controller",
            "--reach", "off", "--surface", "off", "--out", tmp_path / "cli")
    for index, plan in enumerate(plans):
        plan.save(tmp_path / f"python-{index:05}")
        assert_same_files(tmp_path / f"python-{index:05}", tmp_path / f"cli-{index:05}")


def test_the_work_surface_and_a_scene_plan_as_the_cli_plans_them(tmp_path, planner, tasks):
    task = tasks[3]
    free = planner.plan(task.p0, task.d, task.n, seed="dp", controller="hybrid",
                        planner="controller")
    assert len(free.t) > 12, free.termination
    scene = {"obstacles": [{
        "name": "ball", "clearance_m": 0.005,
        "sphere": {"centre": free.tcp[10].tolist(), "radius": 0.015},
    }]}
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    cell = elm.Planner("fr3", config={
        "rollout": {"constraints": {"work_surface": True, "scene": scene}},
    })
    plan = cell.plan(task.p0, task.d, task.n, seed="dp", controller="hybrid",
                     planner="controller", reach=False)
    assert len(plan.t) <= 10
    assert "ball" in plan.termination or "work surface" in plan.termination, plan.termination
    plan.save(tmp_path / "python")
    run_cli(
        "plan", "--p0", vector(task.p0), "--d", vector(task.d), "--n", vector(task.n),
        "--seed", "dp", "--controller", "hybrid", "--planner", "controller", "--reach", "off",
        "--surface", "half-space", "--scene", tmp_path / "scene.json", "--out", tmp_path / "cli",
    )
    assert_same_files(tmp_path / "python", tmp_path / "cli")
    assert elm.check(tmp_path / "python.joint_trajectory.json").points > 0


def test_a_cells_tolerance_and_cone_plan_as_the_cli_plans_them(tmp_path, tasks):
    task = tasks[5]
    fine = elm.Planner("fr3", surface="off", tolerance_mm=0.5, cone_deg=20)
    plan = fine.plan(task.p0, task.d, task.n, seed="dp", controller="hybrid",
                     planner="controller", reach=False)
    assert np.all(plan.tool_angle_deg <= 20.0)
    plan.save(tmp_path / "python")
    run_cli(
        "plan", "--p0", vector(task.p0), "--d", vector(task.d), "--n", vector(task.n),
        "--seed", "dp", "--controller", "hybrid", "--planner", "controller", "--reach", "off",
        "--surface", "off", "--tolerance", "0.5", "--cone", "20", "--out", tmp_path / "cli",
    )
    assert_same_files(tmp_path / "python", tmp_path / "cli")
    with pytest.raises(elm.InputError, match="tolerance_mm"):
        elm.Planner("fr3", tolerance_mm=0)


def test_plan_arrays_describe_the_motion(planner, tasks):
    task = tasks[0]
    plan = planner.plan(task.p0, task.d, task.n, reach=True)
    steps = plan.q.shape[0]
    assert plan.q.shape == (steps, 7) and plan.tcp.shape == (steps, 3)
    assert plan.t.shape == plan.tool_angle_deg.shape == plan.rho.shape == (steps,)
    assert len(plan.controllers) == steps and steps > 1
    assert np.all(np.diff(plan.t) > 0)
    assert plan.path_length_m == pytest.approx(float((plan.tcp[-1] - task.p0) @ task.d), abs=1e-9)
    assert 0 < plan.path_length_m <= plan.reachable_m + 0.02
    assert (plan.below_bound is None) == (plan.path_length_m >= 0.9 * plan.reachable_m)
    np.testing.assert_array_equal(plan.q[0], plan.seed)
    # The search starts from whichever of its candidates goes furthest, never less far than
    # the paper's pipeline (one DP seed, one rollout).
    search_sources = ("dp", "generating", "q_mu", "q_jl", "ik", "scan-chain", "far-end", "scan")
    assert plan.seed_source in search_sources
    pipeline = planner.plan(task.p0, task.d, task.n, planner="controller")
    assert pipeline.seed_source == "dp"
    assert plan.path_length_m >= pipeline.path_length_m
    assert plan.termination
    np.testing.assert_array_equal(plan.task.p0, task.p0)


def test_robot_kinematics_agree_with_the_plan_and_finite_differences(planner, tasks):
    robot = planner.robot
    plan = planner.plan(tasks[1].p0, tasks[1].d, tasks[1].n, controller="classical")
    for q, tcp in zip(plan.q[::10], plan.tcp[::10]):
        pose = robot.fk(q)
        assert pose.shape == (4, 4)
        np.testing.assert_allclose(pose[:3, 3], tcp, atol=1e-12)
        np.testing.assert_allclose(pose[:3, :3] @ pose[:3, :3].T, np.eye(3), atol=1e-12)
        jacobian = robot.jacobian(q)
        assert jacobian.shape == (3, 7)
        h = 1e-6
        for joint in range(7):
            step = np.zeros(7)
            step[joint] = h
            numeric = (robot.fk(q + step)[:3, 3] - robot.fk(q - step)[:3, 3]) / (2 * h)
            np.testing.assert_allclose(jacobian[:, joint], numeric, atol=1e-8)
    assert len(robot.joint_names) == 7
    assert np.all(robot.lower_limits < robot.upper_limits)


def test_check_reports_a_saved_plan_and_refuses_a_tampered_one(tmp_path, planner, tasks):
    plan = planner.plan(tasks[2].p0, tasks[2].d, tasks[2].n)
    plan.save(tmp_path / "line")
    report = elm.check(tmp_path / "line.json")
    assert report.points == plan.q.shape[0]
    assert report.path_length_m == pytest.approx(plan.path_length_m, abs=1e-9)
    assert report.max_line_deviation_m <= 0.02 and report.recorded_end_verified
    joint = elm.check(tmp_path / "line.joint_trajectory.json")
    assert joint.layout == "emg-joint-trajectory/2" and not joint.recorded_end_verified

    tampered = json.loads((tmp_path / "line.joint_trajectory.json").read_text())
    point = len(tampered["points"]) // 2
    tampered["points"][point]["positions"][1] += 0.5
    (tmp_path / "bad.joint_trajectory.json").write_text(json.dumps(tampered))
    with pytest.raises(elm.CheckFailed, match=f"point {point} of"):
        elm.check(tmp_path / "bad.joint_trajectory.json")
    # The CSV takes its task from the JSON beside it; alone, it carries none.
    assert elm.check(tmp_path / "line.csv").points == plan.q.shape[0]
    shutil.copy(tmp_path / "line.csv", tmp_path / "alone.csv")
    with pytest.raises(elm.InputError, match="carries no task"):
        elm.check(tmp_path / "alone.csv")
    with pytest.raises(OSError):
        elm.check(tmp_path / "missing.json")


def test_bad_input_raises_with_the_librarys_message(tmp_path, planner):
    p0, d, n = [0.4, 0.0, 0.3], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]
    with pytest.raises(elm.InputError, match="controller"):
        planner.plan(p0, d, n, controller="fast")
    with pytest.raises(elm.InputError, match="planner"):
        planner.plan(p0, d, n, planner="beam")
    with pytest.raises(elm.InputError, match="seed"):
        planner.plan(p0, d, n, seed="best")
    with pytest.raises(elm.InputError, match="seed"):
        planner.plan(p0, d, n, seed=[0.0, 1.0])
    with pytest.raises(elm.InputError, match="task"):
        planner.plan(p0, [0.0, 0.0, 0.0], n)
    with pytest.raises(elm.InputError, match="task"):
        planner.plan(p0, [0.0, 0.0, 1.0], n)
    with pytest.raises((TypeError, ValueError), match="'n'"):
        planner.plan(p0, d, [0.0, 0.0])
    with pytest.raises(elm.InputError, match="no_such_robot.urdf"):
        elm.Planner(tmp_path / "no_such_robot.urdf")
    with pytest.raises(elm.InputError, match="models"):
        elm.Planner("fr3", models=tmp_path / "none")
    with pytest.raises(elm.InputError, match="lateral_gain"):
        elm.Planner("fr3", config={"rollout": {"lateral_gain_per_s": -1.0}})
    with pytest.raises(elm.InputError, match="config"):
        elm.Planner("fr3", config={"rollout": {"no_such_field": 1}})
    with pytest.raises(elm.InputError, match=r"tasks\[1\]"):
        planner.plan_many([(p0, d, n), (p0, d, d)])
    with pytest.raises(elm.InputError, match="task file"):
        elm.load_tasks(tmp_path / "none.tasks")
    assert issubclass(elm.InputError, elm.Error) and issubclass(elm.CheckFailed, elm.Error)


def test_a_robot_file_without_models_plans_classically_and_refuses_learned_controllers(tmp_path):
    robot_file = tmp_path / "arm.urdf"
    shutil.copy(ROOT / "data" / "robots" / "iiwa14_pen.urdf", robot_file)
    planner = elm.Planner(robot_file)
    assert planner.models == {"diffusion": False, "policy": False}
    task = elm.load_tasks(ROOT / "data" / "iiwa14" / "tasks" / "eval-v1.tasks", robot_file)[0]
    p0, d, n = task.p0, task.d, task.n
    # The defaults plan it: the classical controller, the search.
    plan = planner.plan(p0, d, n)
    assert plan.path_length_m > 0
    pipeline = planner.plan(p0, d, n, controller="classical", planner="controller")
    assert pipeline.seed_source == "home" and plan.path_length_m >= pipeline.path_length_m
    with pytest.raises(elm.InputError, match="ppo-v1.weights"):
        planner.plan(p0, d, n, controller="hybrid")
    with pytest.raises(elm.InputError, match=r"tasks\[0\]: controller \"rl\""):
        planner.plan_many([task, task], controller="rl")
    with pytest.raises(elm.PlanningError, match="dp"):
        planner.plan(p0, d, n, seed="dp", controller="classical")


def test_a_six_joint_arm_takes_and_gives_one_value_per_joint(tmp_path):
    planner = elm.Planner("ur5e")
    robot = planner.robot
    assert robot.dof == 6 and len(robot.joint_names) == 6
    assert robot.lower_limits.shape == robot.velocity_limits.shape == (6,)
    task = elm.load_tasks(ROOT / "data" / "ur5e" / "tasks" / "eval-v1.tasks", "ur5e")[0]
    assert task.q0_seed.shape == (6,)
    plan = planner.plan(
        task.p0, task.d, task.n, seed=list(task.q0_seed), controller="classical", planner="controller"
    )
    assert plan.q.shape == (len(plan.t), 6) and plan.seed.shape == (6,)
    np.testing.assert_array_equal(plan.seed, task.q0_seed)
    np.testing.assert_allclose(robot.fk(plan.q[-1])[:3, 3], plan.tcp[-1], atol=1e-12)
    assert robot.jacobian(plan.q[0]).shape == (3, 6)
    motion = plan.timed()
    assert motion.q.shape[1] == motion.qd.shape[1] == 6
    assert motion.limits["jerk"].shape == (6,)
    plan.save(tmp_path / "six")
    assert elm.check(tmp_path / "six.joint_trajectory.json").points == motion.q.shape[0]
    with pytest.raises(elm.InputError, match="give 6 joint angles"):
        robot.fk([0.0] * 7)
    with pytest.raises(elm.InputError, match="seed: give 6 joint angles"):
        planner.plan(task.p0, task.d, task.n, seed=[0.0] * 7)


def test_plan_many_releases_the_gil_and_matches_plan(planner, tasks):
    chosen = tasks[:1000]
    result = {}

    def work():
        result["started"] = time.perf_counter()
        result["plans"] = planner.plan_many(chosen)
        result["ended"] = time.perf_counter()

    worker = threading.Thread(target=work)
    ticks = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    worker.join()
    plans = result["plans"]
    assert len(plans) == 1000
    # The main thread ran Python code while the batch was being planned: had plan_many held the
    # GIL, no tick could fall inside it.
    started, ended = result["started"], result["ended"]
    middle = [t for t in ticks if started + 0.25 * (ended - started) < t < ended - 0.25 * (ended - started)]
    assert len(middle) >= 10, f"{len(middle)} ticks in the middle half of {ended - started:.2f} s of plan_many"
    for index in (0, 499, 999):
        alone = planner.plan_many([chosen[index]])[0]
        np.testing.assert_array_equal(alone.q, plans[index].q)
    assert all(math.isfinite(p.path_length_m) for p in plans)


def documented_path():
    """The JSON example of docs/paths.md."""
    doc = (ROOT / "docs" / "paths.md").read_text()
    start = doc.index("```json\n") + len("```json\n")
    return json.loads(doc[start:doc.index("```", start)])


def test_plan_path_follows_the_documented_slot_as_the_cli_does(tmp_path, planner):
    path = documented_path()
    plan = planner.plan_path(path)
    assert plan.termination == "reached the end of the path"
    assert plan.task.path_length_m == pytest.approx(0.6 + math.pi * 0.1)
    assert plan.path_length_m == pytest.approx(plan.task.path_length_m, abs=2e-4)
    motion = plan.timed()
    assert len(motion.rest_knots) == 0, "the slot's segments meet tangentially"
    plan.save(tmp_path / "python")
    file = tmp_path / "slot.json"
    file.write_text(json.dumps(path))
    assert planner.plan_path(file).path_length_m == plan.path_length_m
    run_cli("plan", "--path", file, "--surface", "off", "--out", tmp_path / "cli")
    assert_same_files(tmp_path / "python", tmp_path / "cli")


def test_plan_path_refuses_a_malformed_path_naming_the_field(planner):
    path = documented_path()
    path["segments"][1]["arc"]["sweep_deg"] = 400
    with pytest.raises(elm.InputError, match=r"segments\[1\]\.arc\.sweep_deg"):
        planner.plan_path(path)
    with pytest.raises(elm.InputError, match="cannot read path file"):
        planner.plan_path("/nonexistent/path.json")
