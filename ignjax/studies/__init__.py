"""Offline studies over evaluation outputs (outcome tables, question traces,
trajectories, episode difficulty factors).

* :mod:`~ignjax.studies.cost_derivation`: the paper's per-type costs rebuilt
  from cue statistics (and lambda fitted to the locked costs).
* :mod:`~ignjax.studies.cost_sensitivity`: WSR re-weighted under up to
  millions of alternative question-cost vectors, agent rankings and where
  they flip relative to the locked costs (its figures:
  :mod:`~ignjax.studies.cost_figures`; the arithmetic runs without matplotlib).
* :mod:`~ignjax.studies.difficulty_ablation`: episode difficulty under a grid
  of alpha coefficients and bin thresholds; whether per-bin success is
  ordered easy >= medium >= hard; alpha calibrated against failures on a
  held-out split.
* :mod:`~ignjax.studies.interaction`: when questions are asked, where Type-3
  questions arise on the navigation grid, questions per difficulty, and the
  explored-area proxy Delta-U of Type-3 answers.

Every study is a set of pure functions returning plain dicts of numpy arrays
(ready for tables); each has ``plot_*`` helpers that write a PNG atomically.
"""
