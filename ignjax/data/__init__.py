"""Data files shipped with the package: the ProcTHOR asset table, the
paper's published cue statistics (read with :mod:`importlib.resources`), the
shipped benchmark (``benchmark/``, :mod:`ignjax.data.shipped`) and the
``learned`` agent's default policy (``policy/``, its ``README.md`` says how
it was made; :data:`ignjax.agents.learned.source.SHIPPED`)."""
