"""ignjax: a JAX-vectorized batched simulator and benchmark for interactive
Instance Goal Navigation (IGN) with cost-aware questions.

Sub-packages follow the data flow: ``scenes`` (scene model, importers,
procedural houses, compilation to MuJoCo/MJX, navigation grids), ``episodes``
(benchmark construction), ``sim`` (batched simulator and oracle), ``agents``,
``studies``; command lines are ``python -m ignjax.build``,
``ignjax.evaluate.cli``, ``ignjax.sweep.cli`` and ``ignjax.bench.runner``.
"""

import os as _os

# Headless rendering by default: MuJoCo reads MUJOCO_GL when it is first
# imported, so it is set here, before any ignjax module imports mujoco. A
# value the user set (glfw, osmesa, egl) is kept.
_os.environ.setdefault("MUJOCO_GL", "egl")
_os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa" if _os.environ["MUJOCO_GL"] == "osmesa" else "egl")

__version__ = "0.1.0"
