"""Scene readers and writers: :mod:`.sources` (read any source, by file type),
:mod:`.usd` (USD import and export), :mod:`.procthor` (ProcTHOR houses) with
:mod:`.procthor_assets` (its asset table), :mod:`.meshes` (glTF/GLB/OBJ),
:mod:`.manifest` (scene-folder manifests); shared pieces: :mod:`.formats`
(file suffixes), :mod:`.footprint` (2-D hulls and boxes) and :mod:`.names`
(categories and room labels from names)."""
