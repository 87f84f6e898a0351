"""Jobs from Python: `Planner.plan_job` plans the same program as `emg job`, its segments as
numpy arrays, the written file passes `emg check`, and a malformed job is refused naming the
field.

EMG_CLI names the `emg` binary to compare with (default: target/debug/emg of this checkout).
"""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import extreme_line_motion as elm

ROOT = Path(__file__).resolve().parents[3]
CLI = Path(os.environ.get("EMG_CLI", ROOT / "target" / "debug" / "emg"))
SEAMS = ROOT / "examples" / "seams.json"


def run_cli(*args):
    assert CLI.is_file(), f"{CLI} is missing: build it with `cargo build -p emg-cli` or set EMG_CLI"
    done = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


@pytest.fixture(scope="module")
def job_plan():
    return elm.Planner("fr3").plan_job(SEAMS)


def test_a_job_is_planned_whole_and_its_segments_are_arrays(job_plan):
    summary = job_plan.summary
    assert summary["complete"] + summary["resumed"] == 3
    assert summary["drawn_m"] == pytest.approx(summary["total_m"], abs=1e-3)
    assert summary["travel_m"] < summary["travel_given_m"]
    segments = job_plan.segments
    kinds = [s["kind"] for s in segments]
    assert kinds.count("stroke") >= 3 and "travel" in kinds
    for before, after in zip(segments, segments[1:]):
        assert before["end_s"] == after["start_s"]
    joints = job_plan.q.shape[1]
    assert joints == 7 and job_plan.q.shape[0] == job_plan.time_s.shape[0]
    for segment in segments:
        assert segment["q"].shape == (segment["time_s"].shape[0], joints)
        # Every segment runs from rest to rest.
        first = np.searchsorted(job_plan.time_s, segment["time_s"][0])
        last = np.searchsorted(job_plan.time_s, segment["time_s"][-1])
        assert np.all(job_plan.qd[first] == 0.0) and np.all(job_plan.qd[last] == 0.0)
    assert np.all(np.diff(job_plan.time_s) > 0)
    # By default it starts and ends at the shipped arm's home, as `emg job` plans it.
    home = elm.Robot("fr3").home
    np.testing.assert_array_equal(job_plan.q[0], home)
    np.testing.assert_array_equal(job_plan.q[-1], home)
    assert summary["ends_at_home"]


def test_the_program_is_the_clis_and_passes_the_checker(tmp_path, job_plan):
    ours = tmp_path / "python.job.json"
    job_plan.write(ours)
    run_cli("job", SEAMS, "--out", tmp_path / "cli.job.json")
    python_file = json.loads(ours.read_text())
    cli_file = json.loads((tmp_path / "cli.job.json").read_text())
    # The same program, the robot named alike (by name and digest); only the planning time
    # differs.
    assert python_file["robot"].startswith("shipped:fr3@sha256:")
    for file in (python_file, cli_file):
        del file["summary"]["planning_s"]
    assert python_file == cli_file
    assert "OK" in run_cli("check", ours).stdout


# A home of the FR3 other than its ready pose, within its limits: the arm turned and lowered.
OTHER_HOME = [0.5, -0.3, 0.2, -2.0, 0.1, 1.9, 0.3]


def test_a_job_given_a_home_starts_and_ends_there_and_passes_the_checker(tmp_path):
    job = elm.Planner("fr3").plan_job(SEAMS, home=OTHER_HOME)
    assert job.summary["ends_at_home"]
    np.testing.assert_array_equal(job.q[0], OTHER_HOME)
    np.testing.assert_array_equal(job.q[-1], OTHER_HOME)
    assert not np.allclose(job.q[0], elm.Robot("fr3").home)
    program = tmp_path / "home.job.json"
    job.write(program)
    written = json.loads(program.read_text())
    assert written["home"] == OTHER_HOME
    assert written["segments"][0]["vertices"][0] == OTHER_HOME
    assert written["segments"][-1]["vertices"][-1] == OTHER_HOME
    assert "OK" in run_cli("check", program).stdout


def test_a_home_that_does_not_fit_the_arm_is_refused_naming_home():
    planner = elm.Planner("fr3")
    with pytest.raises(elm.InputError, match=r"^home: has 6 values; .* has 7 joints"):
        planner.plan_job(SEAMS, home=OTHER_HOME[:6])
    with pytest.raises(elm.InputError, match=r"^home: joint 4 \(0.5 rad\) is outside its limits"):
        planner.plan_job(SEAMS, home=OTHER_HOME[:3] + [0.5] + OTHER_HOME[4:])
    with pytest.raises(elm.InputError, match=r"^home: .* is not finite"):
        planner.plan_job(SEAMS, home=[float("nan")] * 7)
    with pytest.raises(elm.InputError, match=r"^home: give 7 joint angles"):
        planner.plan_job(SEAMS, home="0,0,0,0,0,0,0")
    with pytest.raises(elm.InputError, match=r"^home: has 8 values"):
        planner.place_job(SEAMS, {"x_m": [0, 0], "y_m": [0, 0], "rotation_deg": [0, 0]}, home=[0.0] * 8)


def test_only_a_shipped_robot_has_a_home(tmp_path):
    assert elm.Robot("ur5e").home.tolist() == pytest.approx([0, -np.pi / 2, 0, -np.pi / 2, 0, 0])
    robot_file = tmp_path / "arm.urdf"
    robot_file.write_bytes((ROOT / "data" / "robots" / "fr3_pen.urdf").read_bytes())
    assert elm.Robot(robot_file).home is None


def test_check_reads_a_program_as_the_cli_does_from_any_directory(tmp_path, job_plan, monkeypatch):
    program = tmp_path / "copied" / "seams.job.json"
    program.parent.mkdir()
    job_plan.write(program)
    monkeypatch.chdir(tmp_path)
    report = elm.check(program)
    assert isinstance(report, elm.JobCheckReport)
    assert report.layout == json.loads(program.read_text())["format"]
    assert report.stroke_parts >= 3 and report.moves >= 2 and report.points > 100
    assert "OK" in run_cli("check", program).stdout
    # A program whose stroke motion is moved off its path is refused, as by the CLI.
    file = json.loads(program.read_text())
    stroke = next(s for s in file["segments"] if s["kind"] == "stroke")
    values = stroke["motion"]["stretches"][0]["values"]
    values[len(values) // 2][0] += 0.05
    tampered = tmp_path / "tampered.job.json"
    tampered.write_text(json.dumps(file))
    with pytest.raises(elm.CheckFailed, match="tampered.job.json does not hold up"):
        elm.check(tampered)


def test_a_program_whose_robot_changed_is_refused_naming_both_digests(tmp_path, job_plan):
    program = tmp_path / "seams.job.json"
    job_plan.write(program)
    file = json.loads(program.read_text())
    recorded = file["robot"].rsplit("@sha256:", 1)[1]
    other = "0" * 64
    file["robot"] = f"shipped:fr3@sha256:{other}"
    program.write_text(json.dumps(file))
    with pytest.raises(elm.InputError, match=f"field 'robot'.*{other}.*{recorded}"):
        elm.check(program)
    # The robot given overrides the file's.
    assert elm.check(program, robot="fr3").stroke_parts >= 3


def test_every_default_shows_its_value_in_help():
    import inspect

    callables = [elm.Planner, elm.Robot, elm.load_tasks, elm.check, elm.export]
    callables += [getattr(elm.Planner, name) for name in ("plan", "plan_path", "plan_job", "place_job", "plan_many")]
    callables += [getattr(elm.Plan, name) for name in ("timed", "save")]
    for function in callables:
        signature = inspect.signature(function)
        for parameter in signature.parameters.values():
            assert parameter.default is not Ellipsis, f"{function.__qualname__}: {parameter.name}"
    assert inspect.signature(elm.Planner.plan_job).parameters["tolerance_mm"].default == 0.5
    for method in (elm.Planner.plan_job, elm.Planner.place_job):
        assert inspect.signature(method).parameters["home"].default is None
    assert inspect.signature(elm.Planner).parameters["robot"].default == "fr3"
    assert inspect.signature(elm.Plan.save).parameters["rate_hz"].default == 1000.0
    # The job default is `emg job`'s.
    assert "[default: 0.5]" in run_cli("job", "--help").stdout


def test_a_malformed_job_is_refused_naming_the_field():
    planner = elm.Planner("fr3")
    with pytest.raises(elm.InputError, match="'strokes' is empty"):
        planner.plan_job({"version": 1, "strokes": []})
    with pytest.raises(elm.InputError, match="tolerance_mm"):
        planner.plan_job(SEAMS, tolerance_mm=-1)
    with pytest.raises(elm.InputError, match="placement"):
        planner.plan_job(SEAMS, placement={"width_m": 0.1})
