"""``python -m ignjax.build``: scenes (procedural houses as USD), ``inspect``,
``render`` (top-down map and first-person panel) and ``episodes`` (build or
check a benchmark). :mod:`~ignjax.build.cli` holds the commands,
:mod:`~ignjax.build.episodes` the benchmark command."""
