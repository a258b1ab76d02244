"""ignjax: a JAX-vectorized batched simulator and benchmark for interactive
Instance Goal Navigation (IGN) with cost-aware questions.

One package per stage of the data flow (``docs/architecture.md`` is the map)::

    scenes -> episodes -> sim (world, rollout) -> agents -> evaluate -> studies -> sweep / bench / build

The names below are what a library user needs; each lives in its package
and is loaded on first use (``import ignjax`` stays cheap, so the command
lines answer ``--help`` at once instead of importing JAX and MuJoCo first):

* scenes: :func:`load_scenes`, :func:`generate_house`, :class:`HouseParams`,
  :func:`save_usd`, :class:`Scene`;
* a benchmark: :func:`build_benchmark`, :class:`BuildConfig`,
  :func:`write_records`, :func:`load_benchmark`, :class:`EpisodeSet`;
* the simulator: :func:`make_world`, :class:`SimConfig`, :func:`reset`,
  :func:`step`, :func:`observe`, :func:`outcome`;
* agents and rollouts: :func:`get_agent`, :data:`AGENTS`, :func:`run_agent`,
  :func:`rollout`, :func:`rollout_sweep`, :func:`episode_keys`;
* metrics and outcome tables: :func:`summarize`, :func:`metric_row`,
  :func:`episode_success`, :func:`table1`, :func:`outcome_rows`,
  :func:`metric_rows`, :func:`write_outcomes`, :func:`read_outcomes`;
* studies: :func:`cost_samples`, :func:`offline_wsr`, :mod:`ignjax.studies`;
  the whole main job: :func:`resolve` (a :class:`SweepConfig`) and
  :func:`run_sweep`.

Command lines: ``python -m ignjax.sweep`` (the main job), ``python -m
ignjax.evaluate``, ``python -m ignjax.build`` and ``python -m ignjax.bench``.
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

_EXPORTS = {
    "load_scenes": "ignjax.scenes.io.sources",
    "generate_house": "ignjax.scenes.procgen",
    "generate_houses": "ignjax.scenes.procgen",
    "HouseParams": "ignjax.scenes.procgen",
    "save_usd": "ignjax.scenes.io.usd",
    "Scene": "ignjax.scenes.model",
    "build_benchmark": "ignjax.episodes.construct",
    "BuildConfig": "ignjax.episodes.construct",
    "write_records": "ignjax.episodes.schema",
    "load_benchmark": "ignjax.episodes.dataset",
    "EpisodeSet": "ignjax.episodes.dataset",
    "make_world": "ignjax.evaluate.runner",
    "SimConfig": "ignjax.sim.simconfig",
    "reset": "ignjax.sim.env",
    "step": "ignjax.sim.env",
    "observe": "ignjax.sim.env",
    "outcome": "ignjax.sim.env",
    "get_agent": "ignjax.agents",
    "AGENTS": "ignjax.agents",
    "run_agent": "ignjax.evaluate.runner",
    "rollout": "ignjax.sim.rollout",
    "rollout_sweep": "ignjax.sim.rollout",
    "episode_keys": "ignjax.sim.rollout",
    "summarize": "ignjax.evaluate.metrics",
    "metric_row": "ignjax.evaluate.metrics",
    "episode_success": "ignjax.evaluate.metrics",
    "table1": "ignjax.evaluate.metrics",
    "outcome_rows": "ignjax.evaluate.outcomes",
    "metric_rows": "ignjax.evaluate.outcomes",
    "write_outcomes": "ignjax.evaluate.outcomes",
    "read_outcomes": "ignjax.evaluate.outcomes",
    "cost_samples": "ignjax.studies.cost_sensitivity",
    "offline_wsr": "ignjax.studies.cost_sensitivity",
    "SweepConfig": "ignjax.config",
    "resolve": "ignjax.config",
    "run_sweep": "ignjax.sweep.stages",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'ignjax' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
