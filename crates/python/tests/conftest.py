"""Fixtures shared by the module's tests: the shipped FR3 planner and the evaluation tasks."""

from pathlib import Path

import pytest

import extreme_line_motion as elm

EVAL_TASKS = Path(__file__).resolve().parents[3] / "data" / "tasks" / "eval-v1.tasks"


@pytest.fixture(scope="session")
def planner():
    return elm.Planner("fr3")


@pytest.fixture(scope="session")
def tasks():
    return elm.load_tasks(EVAL_TASKS)
