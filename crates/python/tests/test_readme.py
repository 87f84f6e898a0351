"""The README's examples, run as written: its Python example and its `emg plan --p0 …` command
plan the same task with their defaults and write the same files, byte for byte."""

import json
import os
import re
import shlex
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
CLI = Path(os.environ.get("EMG_CLI", ROOT / "target" / "debug" / "emg"))


def blocks(language):
    text = (ROOT / "README.md").read_text()
    return re.findall(rf"```{language}\n(.*?)```", text, flags=re.DOTALL)


def test_the_readmes_python_and_cli_examples_plan_the_same_task_to_the_same_length(
    tmp_path, monkeypatch, capsys
):
    example = next(block for block in blocks("python") if "elm.Planner" in block)
    (tmp_path / "python").mkdir()
    monkeypatch.chdir(tmp_path / "python")
    namespace = {}
    exec(compile(example, "README.md", "exec"), namespace)
    printed = capsys.readouterr().out
    plan = namespace["plan"]
    assert f"{plan.path_length_m:.3f} m" in printed
    assert all((tmp_path / "python" / f"line{s}").is_file()
               for s in (".json", ".csv", ".joint_trajectory.json"))

    command = next(
        line for block in blocks("sh") for line in block.splitlines()
        if line.startswith("emg plan --p0")
    )
    words = shlex.split(command.split("#")[0])
    assert words[:2] == ["emg", "plan"]
    (tmp_path / "cli").mkdir()
    done = subprocess.run([str(CLI), *words[1:]], cwd=tmp_path / "cli", capture_output=True,
                          text=True)
    assert done.returncode == 0, done.stderr
    record = json.loads((tmp_path / "cli" / "line.json").read_text())
    assert record["path_length_m"] == plan.path_length_m, done.stdout
    assert record["path_length_m"] > 0.9, done.stdout
    for suffix in (".json", ".csv", ".joint_trajectory.json"):
        python = (tmp_path / "python" / f"line{suffix}").read_bytes()
        assert python == (tmp_path / "cli" / f"line{suffix}").read_bytes(), suffix
