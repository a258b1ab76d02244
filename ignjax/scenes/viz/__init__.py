"""Pictures of scenes: top-down maps (:mod:`~ignjax.scenes.viz.mapplot`),
first-person views (:mod:`~ignjax.scenes.viz.render`) and the catalogue
gallery (:mod:`~ignjax.scenes.viz.gallery`).

MuJoCo picks its OpenGL backend from ``MUJOCO_GL`` when ``mujoco`` is first
imported, so the library never sets it behind the user's back: programs call
:func:`headless_gl` before anything imports ``mujoco`` (the command lines
do), or set ``MUJOCO_GL=egl`` themselves.
"""

from __future__ import annotations

import ctypes.util
import os
import sys


def headless_gl() -> str | None:
    """Default MuJoCo to headless EGL rendering (``MUJOCO_GL=egl``,
    ``PYOPENGL_PLATFORM=egl``) on Linux when the EGL library is installed;
    a ``MUJOCO_GL`` the user set is kept (``osmesa`` keeps its own
    platform). Every command that renders calls it first thing
    (``sweep``, ``evaluate``, ``bench``, ``build``, ``view``), so rendering
    needs no environment variable on a machine without a display. Effective
    only before ``mujoco`` is imported.

    Returns:
        The ``MUJOCO_GL`` now in effect (None: unset, MuJoCo's own default).
    """
    if not os.environ.get("MUJOCO_GL") and sys.platform.startswith("linux") and ctypes.util.find_library("EGL"):
        os.environ["MUJOCO_GL"] = "egl"
    gl = os.environ.get("MUJOCO_GL") or None
    if gl in ("egl", "osmesa"):
        os.environ.setdefault("PYOPENGL_PLATFORM", gl)
    return gl


__all__ = ["headless_gl"]
