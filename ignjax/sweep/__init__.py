"""``python -m ignjax.sweep``: the main job.

Runs the studies on a benchmark and writes ``<run.out>/<run.name>/``:

* ``report.md`` - the paper's Table-1 columns for every agent (overall and
  per difficulty) and every study's results with its figures;
* ``outcomes.parquet`` / ``outcomes.csv`` - one row per (agent, episode);
  ``metrics.csv`` - the metric table (both recomputable from the outcomes);
* ``costs_*.csv``, ``difficulty_*.csv``, ``derive_costs.csv``,
  ``analysis_*.csv`` - the studies' tables; ``figures/*.png``;
* ``run.json`` - the resolved configuration and its fingerprint;
  ``checkpoints/`` - the rollouts' partial results (orbax), for ``--resume``.

Studies (``--study``, repeatable or comma-separated; default all):
``eval`` agents x episodes; ``costs`` offline re-weighting of the stored
outcomes over sampled cost vectors plus the cost-aware agent re-run in the
loop under K cost vectors in one vmapped call; ``difficulty`` alpha and
threshold ablation and calibration on the stored factors; ``derive-costs``
the paper's cost construction; ``analysis`` the interaction analyses from
question traces and trajectories. ``costs``, ``difficulty`` and
``analysis`` use the ``eval`` rollouts (run as needed).

Every rollout is checkpointed as it finishes; a run interrupted (even by
SIGKILL) and continued with ``--resume`` writes the same bytes as an
uninterrupted one. Timings go to stderr only, never into the run folder.

``--processes N`` (or one process per host, :mod:`ignjax.devices.processes`)
splits every rollout stage's batches over processes; each writes its
finished batches to ``parts/`` and process 0 merges, checkpoints and
writes the report: the same bytes as one process.

Benchmark: ``benchmark.episodes`` when set; else the shipped
``scenes/benchmark.jsonl.gz`` (500 episodes, 150/200/150, seed 0) when the
benchmark settings are the defaults; else one built from
``benchmark.scenes`` into ``<run.out>/_benchmarks/`` and reused.
``benchmark.limit`` keeps N episodes spread evenly over the file (quick runs).

Modules, lowest first: :mod:`~ignjax.sweep.report` (the studies' tables
and figures), :mod:`~ignjax.sweep.sections` (the text of ``report.md``), :mod:`~ignjax.sweep.checkpoints` (the run
folder and its orbax checkpoints), :mod:`~ignjax.sweep.stages` (benchmark,
rollout stages, :func:`~ignjax.sweep.stages.run_sweep`) and
:mod:`~ignjax.sweep.cli` (the command line). The configuration is
:class:`ignjax.config.SweepConfig`.
"""
