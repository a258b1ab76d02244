"""Fixtures of the episode viewer's tests: a small evaluation run folder of
two JAX agents on the shared small benchmark (``python -m ignjax.evaluate``,
the command a user runs), and copies of it that a test may add images and
transcripts to."""

from __future__ import annotations

import shutil

import pytest

from ignjax.evaluate.cli import main as evaluate

AGENTS = ("eig", "random")


@pytest.fixture(scope="session")
def eval_run(small_benchmark, tmp_path_factory):
    """The run folder of ``python -m ignjax.evaluate`` with eig and random on the 40 small episodes."""
    out = tmp_path_factory.mktemp("view_run") / "run"
    argv = ["--episodes", str(small_benchmark["path"]), "--out", str(out), "--batch", "40", "--quiet"]
    for a in AGENTS:
        argv += ["--agent", a]
    assert evaluate(argv) == 0
    return out


@pytest.fixture(scope="session")
def run_agents():
    """The agents of :func:`eval_run`, in its order."""
    return AGENTS


@pytest.fixture
def run_copy(eval_run, tmp_path):
    """A copy of :func:`eval_run` that a test may change."""
    dst = tmp_path / "run"
    shutil.copytree(eval_run, dst)
    return dst
