"""``python -m ignjax.bench``: speed figures, each a ratio against a reference
run in the same process (:mod:`~ignjax.bench.runner`, the command line;
:mod:`~ignjax.bench.rays`, ray paths and their agreement with MuJoCo;
:mod:`~ignjax.bench.rollouts`, decision steps/s and the studies;
:mod:`~ignjax.bench.timing`)."""
