"""Pictures of scenes: top-down maps (:mod:`~ignjax.scenes.viz.mapplot`),
first-person views (:mod:`~ignjax.scenes.viz.render`) and the catalogue
gallery (:mod:`~ignjax.scenes.viz.gallery`).

MuJoCo picks its OpenGL backend from ``MUJOCO_GL`` when ``mujoco`` is first
imported, so the library never sets it behind the user's back: programs call
:func:`headless_gl` before anything imports ``mujoco`` (the command lines
do), or set ``MUJOCO_GL=egl`` themselves.
"""

from __future__ import annotations

import os


def headless_gl() -> None:
    """Default MuJoCo to headless EGL rendering (``MUJOCO_GL=egl``,
    ``PYOPENGL_PLATFORM=egl``; ``osmesa`` keeps its own platform); a value
    the user set is kept. Effective only before ``mujoco`` is imported."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa" if os.environ["MUJOCO_GL"] == "osmesa" else "egl")


__all__ = ["headless_gl"]
