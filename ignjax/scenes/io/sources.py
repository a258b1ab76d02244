"""Read any supported scene source: one entry point, dispatch by file type.

=====================================  =========================================
source                                 reader
=====================================  =========================================
directory with ``manifest.json``       every scene the manifest lists
directory without a manifest           every supported file in it (sorted)
``.usd`` ``.usda`` ``.usdc`` ``.usdz``   :func:`ignjax.scenes.io.usd.load_usd`
``.json`` (ignjax scene document)      :func:`ignjax.scenes.model.scenejson.scene_from_dict`
``.json`` (ProcTHOR house)             :func:`ignjax.scenes.io.procthor.load_procthor`
``.jsonl`` ``.jsonl.gz``               one ProcTHOR house per line
``.gltf`` ``.glb`` ``.obj``            :func:`ignjax.scenes.io.meshes.load_mesh_scene`
=====================================  =========================================
"""

from __future__ import annotations

import gzip
import importlib.metadata
import json
import os
from pathlib import Path
from types import MappingProxyType

from ignjax.errors import SceneError, call_recording_warnings, warn_again
from ignjax.scenes.io.formats import MESH_SUFFIXES, SIDECAR_SUFFIX, USD_SUFFIXES
from ignjax.scenes.io.manifest import read_manifest
from ignjax.scenes.io.remembered import read_remembered
from ignjax.scenes.model import Scene
from ignjax.scenes.model.scenejson import scene_from_dict

_USD_VERSION = importlib.metadata.version("usd-core")


def _suffix(path: Path) -> str:
    name = path.name.lower()
    for s in (".jsonl.gz", ".json.gz"):
        if name.endswith(s):
            return s
    return path.suffix.lower()


def is_scene_file(path: str | os.PathLike) -> bool:
    """True when ``path`` has a suffix one of the :data:`READERS` reads."""
    return _suffix(Path(path)) in READERS


def load_scenes(path: str | os.PathLike) -> list[Scene]:
    """Read every scene in ``path`` (a file or a folder).

    Raises:
        SceneError: the path does not exist, is of an unsupported type, or
            its content is invalid (the message names file, place and reason).
    """
    p = Path(path)
    if not p.exists():
        raise SceneError(p, None, "no such file or directory")
    if p.is_dir():
        manifest = p / "manifest.json"
        if manifest.exists():
            return [s for entry in read_manifest(manifest) for s in load_scenes(p / entry["file"])]
        files = sorted(f for f in p.iterdir() if f.is_file() and is_scene_file(f) and not f.name.endswith(SIDECAR_SUFFIX))
        if not files:
            raise SceneError(p, None, "the directory holds no USD, JSON or mesh scene files")
        return [s for f in files for s in load_scenes(f)]
    reader = READERS.get(_suffix(p))
    if reader is None:
        raise SceneError(p, None, f"unsupported file type {_suffix(p) or '(none)'!r}: expected USD "
                                  "(.usd/.usda/.usdc/.usdz), JSON (.json/.jsonl/.jsonl.gz: ProcTHOR houses or ignjax "
                                  "scenes) or a mesh (.gltf/.glb/.obj)")
    return reader(p)


def load_scene(path: str | os.PathLike) -> Scene:
    """Read exactly one scene; error when the source holds several."""
    scenes = load_scenes(path)
    if len(scenes) != 1:
        raise SceneError(path, None, f"expected one scene, found {len(scenes)}")
    return scenes[0]


def _json_document(p: Path):
    opener = gzip.open if p.name.lower().endswith(".gz") else open
    try:
        with opener(p, "rt", encoding="utf-8") as f:
            return json.load(f)
    except UnicodeDecodeError as e:
        raise SceneError(p, None, f"not a text JSON file ({e.reason})") from e
    except json.JSONDecodeError as e:
        raise SceneError(p, f"line {e.lineno}, column {e.colno}", f"invalid JSON: {e.msg}") from e
    except OSError as e:
        raise SceneError(p, None, f"cannot read: {e}") from e


def _load_recorded(path: Path) -> tuple[list[Scene], list]:
    """:func:`load_scenes` plus its warnings (:func:`~ignjax.errors.call_recording_warnings`):
    the unit of work of :func:`scene_sources` in another process."""
    return call_recording_warnings(load_scenes, path)


def _source_files(raw) -> list[Path]:
    """The scene files of one source given to :func:`scene_sources`."""
    p = Path(raw)
    if not p.exists():
        raise SceneError(p, None, "no such file or directory")
    if p.is_dir():
        manifest = p / "manifest.json"
        files = [p / e["file"] for e in read_manifest(manifest)] if manifest.exists() else sorted(
            f for f in p.iterdir() if f.is_file() and is_scene_file(f) and not f.name.endswith(SIDECAR_SUFFIX))
        if not files:
            raise SceneError(p, None, "the directory holds no scene files")
        return files
    return [p]


def scene_sources(paths, map_=map) -> list[tuple[object, Path]]:
    """(scene, file) pairs for every scene in the given sources.

    ``map_`` reads the files (``map_(load_scenes, files)``, results in file
    order): the built-in :func:`map` reads them one by one here, a process
    pool's map (:func:`ignjax.build.pool.ordered_map`) in parallel. Either way
    the error raised is the one reading the sources in order meets first.
    """
    files: list[Path] = []
    error: BaseException | None = None
    for raw in paths:
        try:
            files += _source_files(raw)
        except Exception as e:  # raised once the files of the sources before it are read, as reading in order would
            error = e
            break
    out = []
    if map_ is map:
        for f, scenes in zip(files, map(load_scenes, files)):
            out += [(s, f) for s in scenes]
    else:
        for f, (scenes, caught) in zip(files, map_(_load_recorded, files)):
            warn_again(caught)  # raised here, in file order, as if read here
            out += [(s, f) for s in scenes]
    if error is not None:
        raise error
    return out


# Readers, one per kind of source. Each imports its library when a file of its
# kind is read: importing pxr and trimesh takes seconds (measured ~0.6 s and
# ~1-3 s here), and most callers read one kind only.


def _read_usd(p: Path) -> list[Scene]:
    def read():  # USD's libraries (about 0.3 s to load) only when the file is read, not when it is remembered
        from ignjax.scenes.io.usd.load import read_usd

        return read_usd(p)

    return [read_remembered(p, "usd", read, _USD_VERSION)]


def _read_mesh(p: Path) -> list[Scene]:
    from ignjax.scenes.io.meshes import load_mesh_scene

    return [load_mesh_scene(p)]


def _read_procthor(p: Path) -> list[Scene]:
    from ignjax.scenes.io.procthor import load_procthor

    return load_procthor(p)


def _read_json(p: Path) -> list[Scene]:
    doc = _json_document(p)
    if isinstance(doc, dict) and doc.get("format") == "ignjax-scene":
        return [scene_from_dict(doc, str(p))]
    return _read_procthor(p)


READERS = MappingProxyType({
    **{s: _read_usd for s in USD_SUFFIXES},
    **{s: _read_mesh for s in MESH_SUFFIXES},
    ".jsonl": _read_procthor, ".jsonl.gz": _read_procthor,
    ".json": _read_json, ".json.gz": _read_json,
})
"""File suffix -> reader (path -> scenes). A new importer is one module in
:mod:`ignjax.scenes.io` plus its suffixes here (and in
:mod:`~ignjax.scenes.io.formats`)."""
