"""The module planned from wherever it is copied: the shipped robots and models are compiled in
and written to the user's cache on first use, so neither the checkout nor `EMG_DATA` is needed."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import extreme_line_motion as elm

SCRIPT = """
import extreme_line_motion as elm
for robot in ("fr3", "iiwa14", "ur5e"):
    assert elm.Planner(robot).models == {"diffusion": True, "policy": True}, robot
plan = elm.Planner("fr3").plan(p0=[0.45, -0.2, 0.25], d=[0, 1, 0], n=[0, 0, -1])
print(repr(plan.path_length_m))
"""


def test_a_copied_module_plans_without_the_checkout(tmp_path):
    module = Path(elm.__file__)
    (tmp_path / "site").mkdir()
    shutil.copy(module, tmp_path / "site" / module.name)
    env = {key: value for key, value in os.environ.items() if key != "EMG_DATA"}
    env.update(PYTHONPATH=str(tmp_path / "site"), XDG_CACHE_HOME=str(tmp_path / "cache"))
    done = subprocess.run([sys.executable, "-c", SCRIPT], cwd=tmp_path, env=env,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    copied = float(done.stdout.strip())
    here = elm.Planner("fr3").plan(p0=[0.45, -0.2, 0.25], d=[0, 1, 0], n=[0, 0, -1])
    assert copied == here.path_length_m > 0.9
    cached = list((tmp_path / "cache" / "extreme-line-motion").iterdir())
    assert len(cached) == 1 and (cached[0] / "robots" / "fr3_pen.urdf").is_file()
