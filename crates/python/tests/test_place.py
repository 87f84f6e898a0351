"""Placement from Python: `Planner.place_job` moves lucide's pencil from the edge of the FR3's
reach to where the arm draws it whole, the same place as `emg place`, its program passing
`emg check`; or the robot's base to where it draws it; a bad region is refused naming the
field.

EMG_CLI names the `emg` binary to compare with (default: target/debug/emg of this checkout).
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

import extreme_line_motion as elm

ROOT = Path(__file__).resolve().parents[3]
CLI = Path(os.environ.get("EMG_CLI", ROOT / "target" / "debug" / "emg"))
PENCIL = ROOT / "examples" / "pencil.svg"
FAR = {"origin_m": [0.78, 0.0, 0.25], "width_m": 0.3}
REGION = {"x_m": [-0.3, 0.0], "y_m": [-0.1, 0.1], "rotation_deg": [-45.0, 45.0]}


def run_cli(*args):
    assert CLI.is_file(), f"{CLI} is missing: build it with `cargo build -p emg-cli` or set EMG_CLI"
    done = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def test_the_pencil_is_moved_where_it_is_drawn_whole_as_emg_place_moves_it(tmp_path):
    placement = elm.Planner("fr3").place_job(
        PENCIL, REGION, placement=FAR, positions=3, rotations=2, certify=2
    )
    assert len(placement.screened) == 54  # 3 × 3 positions, 3 heights, 2 turns
    best = placement.certified[0]
    assert best["drawn_m"] == pytest.approx(best["total_m"], abs=1e-3)
    summary = placement.program.summary
    assert summary["drawn_m"] == best["drawn_m"]
    # Its program starts and ends at the arm's home, as `emg place` plans it.
    home = elm.Robot("fr3").home.tolist()
    assert placement.program.q[0].tolist() == home and placement.program.q[-1].tolist() == home
    assert placement.map_svg().startswith("<svg")
    exported = tmp_path / "cli-job.json"
    run_cli(
        "place", PENCIL, "--origin", "0.78,0,0.25", "--width", "0.3",
        "--x=-0.3,0", "--y=-0.1,0.1", "--rotation=-45,45",
        "--positions", "3", "--rotations", "2", "--certify", "2",
        "--out", tmp_path / "cli.json", "--job-out", exported,
    )
    cli = json.loads(exported.read_text())["transform"]
    for key in ("translation_m", "rpy"):
        assert cli[key] == pytest.approx(placement.transform[key], abs=1e-12)
    ours = tmp_path / "python.json"
    placement.program.write(ours)
    run_cli("check", ours)


def test_the_base_moves_instead_of_the_part():
    placement = elm.Planner("fr3").place_job(
        PENCIL,
        {"moving": "base", "x_m": [0.0, 0.3], "y_m": [-0.1, 0.1], "rotation_deg": [-30, 30]},
        placement=FAR, positions=3, rotations=2, certify=2,
    )
    best = placement.certified[0]
    assert best["drawn_m"] == pytest.approx(best["total_m"], abs=1e-3)
    pose = placement.base_pose
    assert pose["translation_m"][0] == pytest.approx(best["scored"]["place"]["x_m"])
    # The job moves back as the base moves forward.
    assert placement.transform["rpy"][2] == pytest.approx(-pose["rpy"][2])


def test_a_bad_region_is_refused_naming_the_field():
    planner = elm.Planner("fr3")
    with pytest.raises(elm.InputError, match="region field 'y_m'"):
        planner.place_job(PENCIL, {**REGION, "y_m": [0.1, -0.1]}, placement=FAR)
    with pytest.raises(elm.InputError, match="region"):
        planner.place_job(PENCIL, {**REGION, "w_m": [0, 1]}, placement=FAR)
    with pytest.raises(elm.InputError, match="region field 'z_m'"):
        planner.place_job(PENCIL, {**REGION, "z_m": [0.1, -0.1]}, placement=FAR)
