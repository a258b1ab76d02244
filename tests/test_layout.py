"""The package layout of docs/architecture.md: no import cycle, no import
from a higher layer, at most five top-level modules, no module over 1,000
lines. Read from the source (ast), nothing is imported."""

from __future__ import annotations

import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "ignjax"
LAYER = {"__main__": 6, "protocol": 0, "arrays": 0, "cache": 0, "errors": 0, "fileio": 0, "data": 0, "devices": 0, "settings": 0, "scenes": 1, "episodes": 2, "sim": 2,
         "agents": 3, "evaluate": 4, "studies": 5, "rl": 5, "config": 6, "sweep": 6, "bench": 6, "build": 6, "view": 6}
FORBIDDEN = {("sim", "episodes")}  # episodes uses the simulator's EpisodeSpec; sim uses nothing of episodes


def _modules() -> dict[str, Path]:
    mods = {}
    for p in sorted(PKG.rglob("*.py")):
        name = ".".join(("ignjax",) + p.relative_to(PKG).with_suffix("").parts)
        mods[name.removesuffix(".__init__")] = p
    return mods


def _imports(mods: dict[str, Path]) -> dict[str, set[str]]:
    edges = {}
    for name, p in mods.items():
        out = set()
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, ast.ImportFrom):
                base = name if p.name == "__init__.py" else name.rpartition(".")[0]
                for _ in range(max(node.level - 1, 0)):
                    base = base.rpartition(".")[0]
                stem = (f"{base}.{node.module}" if node.module else base) if node.level else (node.module or "")
                targets = [stem] + [f"{stem}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                continue
            for t in targets:
                while t and t not in mods:
                    t = t.rpartition(".")[0]
                if t and t != name and t != "ignjax" and not name.startswith(t + "."):
                    out.add(t)
        edges[name] = out
    return edges


def test_every_package_has_a_layer():
    tops = {p.name.removesuffix(".py") for p in PKG.iterdir() if p.name != "__init__.py"
            and (p.suffix == ".py" or (p / "__init__.py").is_file())}
    assert tops == set(LAYER), f"add new top-level packages to LAYER and docs/architecture.md: {tops ^ set(LAYER)}"


def test_no_import_from_a_higher_layer():
    bad = []
    for src, targets in _imports(_modules()).items():
        a = src.split(".")[1] if src.count(".") else None
        for t in targets:
            b = t.split(".")[1]
            if a and (LAYER[b] > LAYER[a] or (a, b) in FORBIDDEN):
                bad.append(f"{src} -> {t}")
    assert not bad, "upward imports:\n" + "\n".join(bad)


def test_no_import_cycle():
    edges = _imports(_modules())
    state: dict[str, int] = {}

    def visit(v, path):
        state[v] = 1
        for w in edges[v]:
            if state.get(w) == 1:
                raise AssertionError("import cycle: " + " -> ".join(path[path.index(w):] + [w]))
            if w not in state:
                visit(w, path + [w])
        state[v] = 2

    for v in edges:
        if v not in state:
            visit(v, [v])


def test_module_sizes_and_top_level_modules():
    mods = _modules()
    top = [p for p in PKG.glob("*.py") if p.name != "__init__.py"]
    assert len(top) <= 5, sorted(p.name for p in top)
    big = {n: len(p.read_text().splitlines()) for n, p in mods.items() if len(p.read_text().splitlines()) > 1000}
    assert not big, big
