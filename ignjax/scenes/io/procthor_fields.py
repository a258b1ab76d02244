"""Typed reads of a ProcTHOR house's JSON fields (numbers, objects, lists,
points, ids) for the importer (:mod:`ignjax.scenes.io.procthor`): a wrong
or missing field raises :class:`SceneError` naming the file, the house
(``line 7, `` in a JSONL file) and the field.
"""

from __future__ import annotations

import math

from ignjax.errors import SceneError

__all__ = ["ReadContext"]


class ReadContext:
    """Where errors point: the file and a prefix (``line 7, `` for JSONL),
    and the typed reads that raise there."""

    def __init__(self, source: str, prefix: str = ""):
        self.source = source
        self.prefix = prefix

    def err(self, where: str, reason: str) -> SceneError:
        return SceneError(self.source, f"{self.prefix}{where}" if where else (self.prefix.rstrip(", .") or None), reason)

    def num(self, value, where: str) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.err(where, f"expected a number, got {value!r}")
        v = float(value)
        if not math.isfinite(v):
            raise self.err(where, f"expected a finite number, got {value!r}")
        return v

    def obj(self, value, where: str) -> dict:
        if not isinstance(value, dict):
            raise self.err(where, f"expected a JSON object, got {type(value).__name__}")
        return value

    def lst(self, value, where: str) -> list:
        if not isinstance(value, list):
            raise self.err(where, f"expected a list, got {type(value).__name__}")
        return value

    def xyz(self, value, where: str, keys: str = "xyz", default: float | None = None) -> tuple[float, ...]:
        d = self.obj(value, where)
        out = []
        for k in keys:
            if k not in d:
                if default is None:
                    raise self.err(f"{where}.{k}", "missing")
                out.append(default)
            else:
                out.append(self.num(d[k], f"{where}.{k}"))
        return tuple(out)

    def ident(self, value, where: str) -> str:
        if isinstance(value, bool) or not isinstance(value, (str, int)) or value == "":
            raise self.err(where, f"expected a non-empty string id, got {value!r}")
        return str(value)
