"""The README's Library example runs as written."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _library_example() -> str:
    text = (ROOT / "README.md").read_text()
    section = text.split("## Library", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert len(blocks) == 1, "the Library section holds one python block"
    return blocks[0]


def test_library_example_runs(tmp_path):
    code = _library_example()
    assert len([line for line in code.splitlines() if line.strip()]) <= 14
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    lines = proc.stdout.splitlines()
    assert lines[0].split()[:2] == ["Agent", "Easy"] and lines[1].split()[0] == "eig"
    lo, hi = re.search(r"WSR@1.5 over 1,000 cost vectors: ([0-9.]+) to ([0-9.]+)", proc.stdout).groups()
    assert 0.0 <= float(lo) <= float(hi) <= 1.0
    assert (tmp_path / "bench" / "episodes.jsonl").is_file() and (tmp_path / "bench" / "house.usda").is_file()
