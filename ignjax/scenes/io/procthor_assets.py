"""The ProcTHOR asset table: ``assetId`` -> object type and bounding-box size.

:func:`derive_asset_table` derives it from ProcTHOR's ``asset-database.json``
(the shipped :data:`DEFAULT_ASSET_TABLE` was made so); :func:`load_asset_table`
reads a derived table or a raw database (cached per path). The ProcTHOR
importer (:mod:`ignjax.scenes.io.procthor`) looks objects up in it.

Command line (regenerates ``ignjax/data/procthor_assets.json.gz``)::

    python -m ignjax.scenes.io.procthor_assets derive-assets asset-database.json [--out FILE]
"""

from __future__ import annotations

import argparse
import gzip
import hashlib
import io
import json
import math
import os
import sys
import zlib
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping, Sequence

from ignjax.errors import SceneError

__all__ = [
    "AssetInfo",
    "ASSET_TABLE_FORMAT",
    "ASSET_TABLE_VERSION",
    "DEFAULT_ASSET_TABLE",
    "derive_asset_table",
    "load_asset_table",
    "resolve_assets",
    "main",
]

ASSET_TABLE_FORMAT = "ignjax-procthor-assets"
ASSET_TABLE_VERSION = 1
DEFAULT_ASSET_TABLE = Path(__file__).resolve().parents[2] / "data" / "procthor_assets.json.gz"
"""The asset table shipped with ignjax (derived from ProcTHOR's
``asset-database.json``, Apache-2.0, allenai/procthor)."""


@dataclass(frozen=True)
class AssetInfo:
    """What the importer needs to know about one ProcTHOR asset.

    Attributes:
        object_type: AI2-THOR object type (``"Fridge"``, ``"HousePlant"``).
        size: (3,) bounding-box size along the asset's Unity x, y (height)
            and z (depth, the asset's forward axis), metres.
    """

    object_type: str
    size: tuple[float, float, float]


def _bad(path, where: str, reason: str) -> SceneError:
    return SceneError(path, where, reason)


def _finite_number(value, path, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _bad(path, where, f"expected a number, got {type(value).__name__} {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise _bad(path, where, f"expected a finite number, got {value!r}")
    return v


def _round(v: float) -> float:
    return round(float(v), 5)


def derive_asset_table(asset_database_path: str | os.PathLike, out_path: str | os.PathLike | None = None) -> dict[str, Any]:
    """Derive the compact asset table from ProcTHOR's ``asset-database.json``.

    The table maps ``assetId`` -> ``[objectType, size_x, size_y, size_z]``
    (bounding-box size in metres, rounded to 10 micrometres), with the
    source file's SHA-256 for provenance. The gzipped file is byte-for-byte
    reproducible (sorted keys, no timestamp).

    Args:
        asset_database_path: ProcTHOR's ``asset-database.json`` (a mapping
            object type -> list of assets with ``assetId``, ``objectType``
            and ``boundingBox``).
        out_path: where to write the gzipped JSON table; nothing is written
            when None.

    Returns:
        The table document (what the file holds).

    Raises:
        SceneError: the database is missing, not JSON, or an asset lacks an
            id, a type or a finite positive bounding box.
    """
    src = Path(asset_database_path)
    try:
        raw = src.read_bytes()
    except OSError as e:
        raise SceneError(src, None, f"cannot read the asset database: {e.strerror or e}") from e
    try:
        db = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as e:
        raise SceneError(src, None, f"not a text JSON file ({e.reason})") from e
    except json.JSONDecodeError as e:
        raise SceneError(src, f"line {e.lineno}, column {e.colno}", f"invalid JSON: {e.msg}") from e
    if not isinstance(db, dict):
        raise SceneError(src, None, "expected a JSON object mapping object types to lists of assets")
    assets: dict[str, list] = {}
    for group, items in db.items():
        if not isinstance(items, list):
            raise SceneError(src, group, "expected a list of assets")
        for i, a in enumerate(items):
            where = f"{group}[{i}]"
            if not isinstance(a, dict):
                raise SceneError(src, where, "expected an asset object")
            aid, otype, bb = a.get("assetId"), a.get("objectType", group), a.get("boundingBox")
            if not isinstance(aid, str) or not aid:
                raise SceneError(src, f"{where}.assetId", "missing or not a string")
            if not isinstance(otype, str) or not otype:
                raise SceneError(src, f"{where}.objectType", "missing or not a string")
            if not isinstance(bb, dict):
                raise SceneError(src, f"{where}.boundingBox", "missing or not an object with x, y, z")
            size = []
            for k in "xyz":
                v = _finite_number(bb.get(k), src, f"{where}.boundingBox.{k}")
                if v <= 0:
                    raise SceneError(src, f"{where}.boundingBox.{k}", f"size must be positive, got {v}")
                size.append(_round(v))
            if aid in assets:
                raise SceneError(src, f"{where}.assetId", f"duplicate assetId {aid!r}")
            assets[aid] = [otype] + size
    doc = {
        "format": ASSET_TABLE_FORMAT,
        "version": ASSET_TABLE_VERSION,
        "source": "ProcTHOR asset-database.json (allenai/procthor, Apache-2.0)",
        "source_sha256": hashlib.sha256(raw).hexdigest(),
        "fields": ["objectType", "size_x", "size_y", "size_z"],
        "units": "metres; size_x/size_z horizontal (z = the asset's forward axis), size_y height",
        "assets": dict(sorted(assets.items())),
    }
    if out_path is not None:
        out = Path(out_path)
        out.parent.mkdir(parents=True, exist_ok=True)
        text = json.dumps(doc, sort_keys=True, separators=(",", ":")).encode("utf-8")
        buf = io.BytesIO()
        with gzip.GzipFile(filename="", mode="wb", fileobj=buf, compresslevel=9, mtime=0) as gz:
            gz.write(text)
        out.write_bytes(buf.getvalue())
    return doc


def _table_from_doc(doc: Any, path) -> dict[str, AssetInfo]:
    if not isinstance(doc, dict):
        raise SceneError(path, None, "not an asset table or asset database (expected a JSON object)")
    if doc.get("format") == ASSET_TABLE_FORMAT:
        if doc.get("version") != ASSET_TABLE_VERSION:
            raise SceneError(path, "version", f"unsupported asset table version {doc.get('version')!r}")
        out = {}
        for aid, row in doc.get("assets", {}).items():
            if not (isinstance(row, list) and len(row) == 4 and isinstance(row[0], str)):
                raise SceneError(path, f"assets.{aid}", "expected [objectType, size_x, size_y, size_z]")
            size = tuple(_finite_number(v, path, f"assets.{aid}") for v in row[1:])
            out[aid] = AssetInfo(row[0], size)  # type: ignore[arg-type]
        return out
    # A raw ProcTHOR asset-database.json.
    tmp = {}
    for group, items in doc.items():
        if not isinstance(items, list):
            raise SceneError(path, group, "expected a list of assets (is this an asset database?)")
        for i, a in enumerate(items):
            if not isinstance(a, dict) or not isinstance(a.get("assetId"), str) or not isinstance(a.get("boundingBox"), dict):
                raise SceneError(path, f"{group}[{i}]", "expected an asset with assetId and boundingBox")
            bb = a["boundingBox"]
            size = tuple(_finite_number(bb.get(k), path, f"{group}[{i}].boundingBox.{k}") for k in "xyz")
            tmp[a["assetId"]] = AssetInfo(str(a.get("objectType", group)), size)  # type: ignore[arg-type]
    return tmp


@lru_cache(maxsize=8)
def _load_table_cached(path: str) -> Mapping[str, AssetInfo]:
    p = Path(path)
    try:
        with (gzip.open(p, "rt", encoding="utf-8") if p.name.endswith(".gz") else open(p, encoding="utf-8")) as f:
            doc = json.load(f)
    except FileNotFoundError as e:
        raise SceneError(p, None, "asset table not found") from e
    except (OSError, UnicodeDecodeError, EOFError, zlib.error) as e:
        raise SceneError(p, None, f"cannot read the asset table: {e}") from e
    except json.JSONDecodeError as e:
        raise SceneError(p, f"line {e.lineno}, column {e.colno}", f"invalid JSON: {e.msg}") from e
    return MappingProxyType(_table_from_doc(doc, p))


def load_asset_table(path: str | os.PathLike | None = None) -> Mapping[str, AssetInfo]:
    """Read an asset table: assetId -> :class:`AssetInfo`.

    Args:
        path: a table written by :func:`derive_asset_table` (``.json`` or
            ``.json.gz``) or a raw ProcTHOR ``asset-database.json``; the
            shipped table when None.

    Returns:
        A read-only mapping (cached per path).
    """
    return _load_table_cached(str(Path(path if path is not None else DEFAULT_ASSET_TABLE).resolve()))


def resolve_assets(assets) -> Mapping[str, AssetInfo]:
    """An asset table given as a mapping, a path, or None (the shipped table)."""
    if assets is None or isinstance(assets, (str, os.PathLike)):
        return load_asset_table(assets)
    return assets


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: ``python -m ignjax.scenes.io.procthor_assets derive-assets PATH [--out FILE]``."""
    parser = argparse.ArgumentParser(prog="python -m ignjax.scenes.io.procthor_assets",
                                     description="ProcTHOR asset table.")
    sub = parser.add_subparsers(dest="command", required=True)
    d = sub.add_parser("derive-assets", help="derive the compact asset table from ProcTHOR's asset-database.json",
                       description="Derive ignjax's asset table (assetId -> object type and bounding-box size) "
                                   "from ProcTHOR's asset-database.json.")
    d.add_argument("path", help="ProcTHOR asset-database.json")
    d.add_argument("--out", default=str(DEFAULT_ASSET_TABLE),
                   help=f"output .json.gz file (default: the shipped table, {DEFAULT_ASSET_TABLE})")
    args = parser.parse_args(argv)
    try:
        doc = derive_asset_table(args.path, args.out)
    except SceneError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    _load_table_cached.cache_clear()
    types = {row[0] for row in doc["assets"].values()}
    size = Path(args.out).stat().st_size
    print(f"wrote {len(doc['assets'])} assets of {len(types)} object types to {args.out} ({size} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
