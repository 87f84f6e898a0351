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


def test_the_program_is_the_clis_and_passes_the_checker(tmp_path, job_plan):
    ours = tmp_path / "python.job.json"
    job_plan.write(ours)
    run_cli("job", SEAMS, "--out", tmp_path / "cli.job.json")
    python_file = json.loads(ours.read_text())
    cli_file = json.loads((tmp_path / "cli.job.json").read_text())
    # The same program; only the planning time and the robot file's spelling differ.
    for file in (python_file, cli_file):
        del file["summary"]["planning_s"]
        del file["robot"]
    assert python_file == cli_file
    assert "OK" in run_cli("check", ours, "--robot", "fr3").stdout


def test_a_malformed_job_is_refused_naming_the_field():
    planner = elm.Planner("fr3")
    with pytest.raises(elm.InputError, match="'strokes' is empty"):
        planner.plan_job({"version": 1, "strokes": []})
    with pytest.raises(elm.InputError, match="tolerance_mm"):
        planner.plan_job(SEAMS, tolerance_mm=-1)
    with pytest.raises(elm.InputError, match="placement"):
        planner.plan_job(SEAMS, placement={"width_m": 0.1})
