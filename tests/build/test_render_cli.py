"""``python -m ignjax.build render`` run as a user runs it (a subprocess) on a
small scene written to a temporary folder: it writes the top-down map, the
front view (``--size`` pixels square), the Planner panel (3 x 3 views) and
the Grounder image, and none of them is blank.

Rendering needs headless OpenGL: the test uses the first of
``$MUJOCO_GL`` (default ``egl``) and ``osmesa`` that can open a MuJoCo
renderer here, and is skipped, naming each backend's error, when none can.
"""

from __future__ import annotations

import os
import subprocess
import sys

import matplotlib.image as mpimg
import numpy as np
import pytest

from ignjax.scenes.io.usd import save_usd

SIZE = 64
pytestmark = pytest.mark.render

_PROBE = ("import mujoco\n"
          "m = mujoco.MjModel.from_xml_string(\"<mujoco><worldbody><geom size='1 1 .1' type='plane'/></worldbody></mujoco>\")\n"
          "r = mujoco.Renderer(m, 16, 16)\n"
          "r.close()\n")


def _gl_env(backend: str) -> dict:
    env = dict(os.environ, MUJOCO_GL=backend)
    env["PYOPENGL_PLATFORM"] = "osmesa" if backend == "osmesa" else "egl"
    return env


@pytest.fixture(scope="module")
def gl_env() -> dict:
    """The environment of the first headless OpenGL backend that renders here (or a skip naming why none does)."""
    errors = []
    for backend in dict.fromkeys((os.environ.get("MUJOCO_GL", "egl"), "egl", "osmesa")):
        env = _gl_env(backend)
        proc = subprocess.run([sys.executable, "-c", _PROBE], env=env, capture_output=True, text=True, timeout=120)
        if proc.returncode == 0:
            return env
        last = (proc.stderr.strip().splitlines() or ["no error output"])[-1]
        errors.append(f"MUJOCO_GL={backend}: {last}")
    pytest.skip("no headless OpenGL backend can render here (" + "; ".join(errors) + ")")


@pytest.fixture(scope="module")
def rendered(two_room_scene, gl_env, tmp_path_factory):
    root = tmp_path_factory.mktemp("render")
    src = root / "two_rooms.usda"
    save_usd(two_room_scene, src)
    out = root / "out"
    env = gl_env
    if env["MUJOCO_GL"] == "egl":  # the command selects headless EGL itself: no variable set, no display
        env = {k: v for k, v in env.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM", "DISPLAY", "WAYLAND_DISPLAY")}
    proc = subprocess.run([sys.executable, "-m", "ignjax.build", "render", str(src), "--out", str(out), "--size", str(SIZE)],
                          env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return out, two_room_scene.id, proc.stdout


def test_commands_select_headless_egl_themselves():
    """``headless_gl`` (called first by every command that renders): EGL where its library is installed and
    ``MUJOCO_GL`` is unset; a value the user set is kept."""
    code = "from ignjax.scenes.viz import headless_gl; import os; print(headless_gl(), os.environ.get('PYOPENGL_PLATFORM'))"
    bare = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM", "DISPLAY")}
    import ctypes.util

    got = subprocess.run([sys.executable, "-c", code], env=bare, capture_output=True, text=True, timeout=60)
    want = "egl egl" if sys.platform.startswith("linux") and ctypes.util.find_library("EGL") else "None None"
    assert got.stdout.split() == want.split(), got.stderr
    kept = subprocess.run([sys.executable, "-c", code], env=dict(bare, MUJOCO_GL="osmesa"), capture_output=True,
                          text=True, timeout=60)
    assert kept.stdout.split() == ["osmesa", "osmesa"], kept.stderr


def _image(path) -> np.ndarray:
    img = mpimg.imread(path)
    assert img.ndim == 3 and img.shape[2] in (3, 4)
    return img[..., :3].astype(np.float64)


def test_render_writes_the_promised_images(rendered):
    out, sid, stdout = rendered
    names = {f"{sid}_map.png", f"{sid}_front.png", f"{sid}_panorama.png", f"{sid}_grounder.png"}
    assert {p.name for p in out.iterdir()} == names  # nothing else (no temporary files left behind)
    for name in names:
        assert name in stdout
    assert _image(out / f"{sid}_front.png").shape == (SIZE, SIZE, 3)
    assert _image(out / f"{sid}_panorama.png").shape == (3 * SIZE, 3 * SIZE, 3)
    assert _image(out / f"{sid}_grounder.png").shape == (SIZE, SIZE, 3)
    assert min(_image(out / f"{sid}_map.png").shape[:2]) >= 100


def test_rendered_images_are_not_blank(rendered):
    out, sid, _ = rendered
    for name in ("map", "front", "panorama", "grounder"):
        img = _image(out / f"{sid}_{name}.png")
        assert img.var() > 1e-4, name
    # every cell of the panel shows something: eight views around the orientation cell
    panel = _image(out / f"{sid}_panorama.png")
    tiles = {(i, j): panel[i * SIZE:(i + 1) * SIZE, j * SIZE:(j + 1) * SIZE] for i in range(3) for j in range(3)}
    for (i, j), tile in tiles.items():
        assert tile.var() > 1e-4, (i, j)
    # the front view is the panel's top-middle tile, under its label and grid lines
    same = np.all(np.abs(tiles[(0, 1)] - _image(out / f"{sid}_front.png")) <= 1 / 255, axis=-1)
    assert same.mean() > 0.6
