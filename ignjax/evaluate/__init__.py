"""Evaluation: agents over a benchmark, outcome tables and metrics.

* :mod:`~ignjax.evaluate.runner`: :func:`make_world`, :func:`run_agent` (fixed-size
  batches, per-episode keys).
* :mod:`~ignjax.evaluate.outcomes`: one row per (agent, episode) as Parquet and CSV.
* :mod:`~ignjax.evaluate.metrics`: SR, OSR, NE, TL, Q_t, |Q|, WSR as array
  programs over :class:`ignjax.sim.types.OutcomeRow`; Table 1.
* :mod:`~ignjax.evaluate.cli`: ``python -m ignjax.evaluate``.
"""
