"""ignjax: a JAX-vectorized batched simulator and benchmark for interactive
Instance Goal Navigation (IGN) with cost-aware questions.

Sub-packages follow the data flow: ``scenes`` (scene model, importers,
procedural houses, compilation to MuJoCo/MJX, navigation grids), ``episodes``
(benchmark construction), ``sim`` (batched simulator and oracle), ``agents``,
``studies``; command lines are ``python -m ignjax.build``,
``ignjax.evaluate``, ``ignjax.sweep`` and ``ignjax.bench``.
"""

import os as _os

# Headless rendering by default: MuJoCo reads MUJOCO_GL when it is first
# imported, so it is set here, before any ignjax module imports mujoco. A
# value the user set (glfw, osmesa, egl) is kept.
_os.environ.setdefault("MUJOCO_GL", "egl")
_os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa" if _os.environ["MUJOCO_GL"] == "osmesa" else "egl")

# XLA:CPU compiles loop bodies (the rollout's scan over planner steps and the
# masked batch maps inside it) several times slower with its MLIR fusion
# emitters than with the classic ones: the simulator's gather-heavy ray
# marches ran 3-4x slower inside a while loop than the same code at top
# level (measured with jax/jaxlib 0.10.2 on a 2-core CPU). The classic
# emitters bring loop bodies back to top-level speed; rollouts run about 1.7x
# faster. XLA reads XLA_FLAGS when JAX first initialises its backend, so this
# takes effect when ignjax is imported before any JAX computation runs. A
# choice the user made in XLA_FLAGS is kept; IGNJAX_XLA_DEFAULTS=0 leaves
# XLA_FLAGS untouched. The flag concerns the CPU backend only.
_CPU_FLAG = "--xla_cpu_use_fusion_emitters"
if _os.environ.get("IGNJAX_XLA_DEFAULTS", "1") != "0" and _CPU_FLAG not in _os.environ.get("XLA_FLAGS", ""):
    _os.environ["XLA_FLAGS"] = (_os.environ.get("XLA_FLAGS", "") + f" {_CPU_FLAG}=false").strip()

__version__ = "0.1.0"
