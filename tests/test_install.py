"""The package as an installed library: one version (ignjax.__version__,
shown by ``python -m ignjax --version`` and read by pyproject.toml), SPDX
license metadata, and optional parts (extras) that fail with one line naming
their ``pip install`` when missing. The wheel itself is built, installed in a
fresh virtual environment and run from an empty folder by ``.ci/wheel-check``."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import ignjax
from ignjax.errors import IgnjaxError
from ignjax.errors.extras import EXTRAS, MissingExtra, optional_module, require_extra

ROOT = Path(__file__).resolve().parents[1]


def test_the_version_lives_in_one_place_and_the_metadata_is_spdx():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    project = meta["project"]
    assert "version" not in project and project["dynamic"] == ["version"]
    assert meta["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "ignjax.__version__"}
    assert project["license"] == "Apache-2.0" and all((ROOT / f).is_file() for f in project["license-files"])
    assert set(EXTRAS) <= set(project["optional-dependencies"])
    proc = subprocess.run([sys.executable, "-m", "ignjax", "--version"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0 and proc.stdout.strip() == f"ignjax {ignjax.__version__}"


def test_a_missing_optional_package_is_one_error_naming_its_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "aiohttp", None)  # what `import aiohttp` meets without the llm extra
    absent = optional_module("aiohttp", "llm")
    with pytest.raises(MissingExtra) as e:
        absent.ClientSession
    assert isinstance(e.value, IgnjaxError) and 'pip install "ignjax[llm]"' in str(e.value)
    with pytest.raises(MissingExtra, match=r"'aiohttp' package is not installed"):
        require_extra("aiohttp", "llm")
    require_extra("json", "llm")  # an importable package passes


WITHOUT_AIOHTTP = """
import sys
sys.modules["aiohttp"] = None  # the core install: no llm extra
import ignjax.agents.llm  # still imports
from ignjax.evaluate.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_an_mllm_agent_without_the_llm_extra_stops_before_any_work(tmp_path):
    out = tmp_path / "run"
    proc = subprocess.run([sys.executable, "-c", WITHOUT_AIOHTTP, "--agent", "vlm", "--llm-endpoint",
                           "http://127.0.0.1:9/v1", "--llm-model", "m", "--out", str(out)],
                          capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().splitlines() == [
        "error: the 'aiohttp' package is not installed; it comes with the 'llm' extra "
        f"({EXTRAS['llm']}): pip install \"ignjax[llm]\""]
    assert not out.exists()
