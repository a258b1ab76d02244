"""ignjax: a JAX-vectorized batched simulator and benchmark for interactive
Instance Goal Navigation (IGN) with cost-aware questions.

Sub-packages follow the data flow: ``scenes`` (scene model, importers,
procedural houses, compilation to MuJoCo/MJX, navigation grids), ``episodes``
(benchmark construction), ``sim`` (batched simulator and oracle), ``agents``,
``studies``; command lines are ``python -m ignjax.build``,
``ignjax.evaluate``, ``ignjax.sweep`` and ``ignjax.bench``.
"""

__version__ = "0.1.0"
