"""The shipped benchmark: 12 procedural houses (seed 0) and the 500-episode
file built from them (seed 0), package data under ``ignjax/data/benchmark/``.

It travels inside the wheel (about 1.5 MB compressed, 16 MB installed), so
that every command defaulting to it works from any folder after
``pip install ignjax``: regenerating it on first use would cost every new
machine minutes of building (the USD houses, navigation grids and geodesic
fields) where the archive costs a megabyte. The repository's top-level
``scenes/`` is a link to this folder, so the two can never drift apart.

Every file is checked against ``benchmark.sha256`` (``sha256sum`` format)
before a command uses the default: a missing, truncated or foreign file is
one :class:`~ignjax.errors.InputError` naming it and the command that
rebuilds the benchmark byte for byte (:data:`REBUILD`).
"""

from __future__ import annotations

import functools
import gzip
import json
import math
from pathlib import Path

from ignjax.errors import InputError
from ignjax.fileio import file_sha256

FOLDER = Path(__file__).resolve().parent / "benchmark"
"""The shipped benchmark's folder (the houses, their manifest and the episode files)."""

EPISODES = FOLDER / "benchmark.jsonl.gz"
"""The shipped episode file: 500 episodes, 150/200/150 easy/medium/hard."""

HASHES = Path(__file__).resolve().parent / "benchmark.sha256"
"""Recorded SHA-256 of every file in :data:`FOLDER`, one ``<hex>  <name>`` line each."""

SCENE_COUNT, SCENE_SEED, SUBSET, EPISODE_SEED = 12, 0, 500, 0
"""How the shipped benchmark is built (``python -m ignjax.build default``)."""

REBUILD = "python -m ignjax.build default --out DIR"
"""The command that writes the shipped benchmark again, byte for byte, into ``DIR``."""

LABEL = "the shipped benchmark (package data)"


def recorded_hashes() -> dict[str, str]:
    """``{file name: sha256 hex}`` of the shipped benchmark's files."""
    if not HASHES.is_file():
        raise _damaged(HASHES, "the list of recorded hashes is missing")
    out = {}
    for i, line in enumerate(HASHES.read_text().splitlines(), 1):
        digest, _, name = line.partition("  ")
        if len(digest) != 64 or not name:
            raise _damaged(HASHES, f"line {i} is not '<sha256>  <file name>'")
        out[name] = digest
    return out


def mismatches(folder: Path, hashes: dict[str, str]) -> list[str]:
    """Files of ``hashes`` that are missing from ``folder`` or differ, each
    as ``"<name>: <why>"``."""
    out = []
    for name, digest in sorted(hashes.items()):
        p = folder / name
        if not p.is_file():
            out.append(f"{name}: missing")
        elif file_sha256(p) != digest:
            out.append(f"{name}: its bytes differ from the recorded ones (truncated, edited or from another version)")
    return out


def _differences(a, b, where: str, rel: float) -> list[str]:
    """Where two JSON values differ, floats compared within ``rel`` (relative)."""
    if isinstance(a, float) or isinstance(b, float):
        ok = isinstance(a, (int, float)) and isinstance(b, (int, float)) and math.isclose(a, b, rel_tol=rel, abs_tol=rel)
        return [] if ok else [f"{where}: {a!r} vs {b!r}"]
    if isinstance(a, dict) and isinstance(b, dict):
        return [d for k in sorted(set(a) | set(b)) for d in _differences(a.get(k), b.get(k), f"{where}.{k}", rel)]
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [d for i, (u, v) in enumerate(zip(a, b)) for d in _differences(u, v, f"{where}[{i}]", rel)]
    return [] if a == b else [f"{where}: {a!r} vs {b!r}"]


def episode_differences(path: Path, rel: float = 1e-9) -> tuple[list[str], int]:
    """``(differences, rounded)``: how the episode file at ``path`` differs from
    the shipped one beyond floating-point rounding (each ``"<episode
    field>: <ours> vs <shipped>"``), and how many numbers differ only in their
    last digits (what another numpy build or CPU gives)."""
    def load(p):
        with gzip.open(p, "rt") as f:
            return [json.loads(line) for line in f if line.strip()]

    ours, recorded = load(path), load(EPISODES)
    if len(ours) != len(recorded):
        return [f"{len(ours)} episodes vs {len(recorded)}"], 0
    diffs = [d for i, (u, v) in enumerate(zip(ours, recorded)) for d in _differences(u, v, f"episode {i}", rel)]
    exact = [d for i, (u, v) in enumerate(zip(ours, recorded)) for d in _differences(u, v, f"episode {i}", 0.0)]
    return diffs, len(exact) - len(diffs)


def _damaged(path: Path, reason: str) -> InputError:
    return InputError(f"{LABEL}, {path}", None,
                      f"{reason}; reinstall ignjax (pip install --force-reinstall ignjax), or rebuild it with "
                      f"`{REBUILD}` and pass --set benchmark.episodes=DIR/benchmark.jsonl.gz")


@functools.lru_cache(maxsize=1)
def _checked() -> Path:
    bad = mismatches(FOLDER, recorded_hashes())
    if bad:
        name = bad[0].partition(":")[0]
        more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
        raise _damaged(FOLDER / name, bad[0].partition(": ")[2] + more)
    return EPISODES


def describe(path) -> str:
    """``path`` as a user reads it: the shipped benchmark is named as such, with where it is installed."""
    p = Path(path)
    return f"{LABEL} {p}" if p.resolve() == EPISODES else str(p)


def shipped_episodes() -> Path:
    """The shipped episode file, after checking every file of the shipped
    benchmark against its recorded hash (once per process).

    Raises:
        InputError: a file is missing or differs; the message names it and
            :data:`REBUILD`.
    """
    return _checked()


__all__ = ["EPISODES", "EPISODE_SEED", "FOLDER", "HASHES", "LABEL", "REBUILD", "SCENE_COUNT", "SCENE_SEED", "SUBSET",
           "describe", "episode_differences", "mismatches", "recorded_hashes", "shipped_episodes"]
