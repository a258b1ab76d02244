"""File suffixes of the scene sources: which reader takes which file.

One definition shared by the folder loader (:mod:`ignjax.scenes.io.sources`)
and the readers themselves (:mod:`ignjax.scenes.io.usd`,
:mod:`ignjax.scenes.io.meshes`).
"""

from __future__ import annotations

USD_SUFFIXES: tuple[str, ...] = (".usd", ".usda", ".usdc", ".usdz")
MESH_SUFFIXES: tuple[str, ...] = (".gltf", ".glb", ".obj")
JSON_SUFFIXES: tuple[str, ...] = (".json", ".jsonl", ".jsonl.gz", ".json.gz")
SIDECAR_SUFFIX = ".ignjax.json"
"""Mesh-scene sidecars (see :mod:`ignjax.scenes.io.meshes`); never scenes themselves."""
