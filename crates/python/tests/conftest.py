"""Fixtures shared by the module's tests: the shipped FR3 planner and the evaluation tasks."""

from pathlib import Path

import pytest

import extreme_line_motion as elm

EVAL_TASKS = Path(__file__).resolve().parents[3] / "data" / "tasks" / "eval-v1.tasks"


@pytest.fixture(scope="session")
def planner():
    """The FR3 under the paper's protocol (no work surface), as `emg plan --surface off`."""
    return elm.Planner("fr3", surface="off")


@pytest.fixture(scope="session")
def tasks():
    return elm.load_tasks(EVAL_TASKS)
