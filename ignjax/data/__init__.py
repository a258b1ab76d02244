"""Data files shipped with the package: the ProcTHOR asset table and the
paper's published cue statistics (read with :mod:`importlib.resources`)."""
