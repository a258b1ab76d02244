"""Benchmark construction and episode files.

* :mod:`~ignjax.episodes.inventory`: instances and target candidates of a scene.
* :mod:`~ignjax.episodes.describe`: target descriptions and the Type-1/Type-2 facts.
* :mod:`~ignjax.episodes.difficulty`: difficulty factors, D and bins (array programs).
* :mod:`~ignjax.episodes.construct`: scenes -> candidate episodes -> balanced subset.
* :mod:`~ignjax.episodes.schema`: versioned episode records, validation, reading, writing.
* :mod:`~ignjax.episodes.dataset`: an episode file -> :class:`EpisodeSet` (bank, goal fields, specs).
* :mod:`~ignjax.episodes.stats`: summaries and the statistics figure.

Imports :mod:`ignjax.scenes` and the simulator's episode type
(:class:`ignjax.sim.types.EpisodeSpec`); nothing above.
"""
