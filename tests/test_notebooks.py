"""The example notebooks: stored without outputs, and they run from top to
bottom (small sizes, ``IGNJAX_NOTEBOOK_SMALL=1``) with figures shown
inline and nothing left in their working folder."""

from __future__ import annotations

from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"
NAMES = ("difficulty_ablation.ipynb", "cost_sensitivity.ipynb")
MIN_FIGURES = {"difficulty_ablation.ipynb": 5, "cost_sensitivity.ipynb": 4}


def _read(name: str):
    nb = nbformat.read(NOTEBOOKS / name, as_version=4)
    nbformat.validate(nb)
    return nb


@pytest.mark.parametrize("name", NAMES)
def test_notebook_is_stored_without_outputs(name):
    nb = _read(name)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert code and any(c.cell_type == "markdown" for c in nb.cells)
    for i, cell in enumerate(code):
        assert cell.outputs == [], f"{name}: code cell {i} has stored outputs"
        assert cell.execution_count is None, f"{name}: code cell {i} has an execution count"


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n == "difficulty_ablation.ipynb" else n
                                  for n in NAMES])  # the difficulty notebook takes 80 s: run with -m slow
def test_notebook_runs_and_shows_figures(name, tmp_path, monkeypatch):
    monkeypatch.setenv("IGNJAX_NOTEBOOK_SMALL", "1")  # the kernel inherits the environment
    nb = _read(name)
    client = NotebookClient(nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}})
    client.execute()  # raises CellExecutionError (with the cell and traceback) on any error
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    figures = [o for o in outputs if o.output_type in ("display_data", "execute_result") and "image/png" in o.data]
    assert len(figures) >= MIN_FIGURES[name], f"{name}: {len(figures)} figures shown"
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "small run: True" in text and "notebook finished" in text
    assert list(tmp_path.iterdir()) == [], "the notebook left files in its working folder"
