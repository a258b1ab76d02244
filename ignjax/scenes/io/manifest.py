"""The manifest of a scene folder (``manifest.json``).

::

    {"format": "ignjax-scenes", "version": 1,
     "generator": {"seed": 0, "count": 12, "params": {...}},
     "scenes": [{"id": "house_0_000", "file": "house_0_000.usda", "rooms": 5,
                 "instances": 61, "categories": 34, "room_labels": [...],
                 "sha256": "..."}, ...]}

``file`` is relative to the folder. :func:`read_manifest` validates the
document and that every listed file exists; :func:`write_manifest` writes
atomically.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from ignjax.errors import SceneError
from ignjax.fileio import file_sha256
from ignjax.scenes.model import Scene

MANIFEST_FORMAT = "ignjax-scenes"
MANIFEST_VERSION = 1


def manifest_entry(scene: Scene, file: Path) -> dict:
    """The manifest entry of a scene written to ``file``."""
    return {
        "id": scene.id,
        "file": file.name,
        "rooms": len(scene.rooms),
        "instances": len(scene.objects),
        "categories": len(scene.categories()),
        "room_labels": [r.label for r in scene.rooms],
        "sha256": file_sha256(file),
    }


def write_manifest(folder: str | os.PathLike, entries: list[dict], generator: dict | None = None) -> Path:
    """Write ``folder/manifest.json`` atomically."""
    folder = Path(folder)
    doc = {"format": MANIFEST_FORMAT, "version": MANIFEST_VERSION, "generator": generator or {}, "scenes": entries}
    out = folder / "manifest.json"
    tmp = folder / f".manifest.json.tmp-{os.getpid()}"
    tmp.write_text(json.dumps(doc, indent=2, sort_keys=True) + "\n")
    os.replace(tmp, out)
    return out


def read_manifest(path: str | os.PathLike) -> list[dict]:
    """The scene entries of a manifest, validated.

    Raises:
        SceneError: naming the manifest, the entry and the problem.
    """
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except json.JSONDecodeError as e:
        raise SceneError(p, f"line {e.lineno}", f"invalid JSON: {e.msg}") from e
    except OSError as e:
        raise SceneError(p, None, f"cannot read: {e}") from e
    if not isinstance(doc, dict) or doc.get("format") != MANIFEST_FORMAT:
        raise SceneError(p, "format", f"not an ignjax scene manifest (expected format {MANIFEST_FORMAT!r})")
    if doc.get("version") != MANIFEST_VERSION:
        raise SceneError(p, "version", f"unsupported manifest version {doc.get('version')!r}")
    scenes = doc.get("scenes")
    if not isinstance(scenes, list) or not scenes:
        raise SceneError(p, "scenes", "must be a non-empty list")
    for i, e in enumerate(scenes):
        if not isinstance(e, dict) or not isinstance(e.get("file"), str) or not isinstance(e.get("id"), str):
            raise SceneError(p, f"scenes[{i}]", "each entry needs string fields 'id' and 'file'")
        if not (p.parent / e["file"]).exists():
            raise SceneError(p, f"scenes[{i}].file", f"listed file {e['file']!r} does not exist")
    return scenes
