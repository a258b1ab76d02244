"""Error types. Every error raised on bad input names the file, the place in
it (prim path, JSON field, line) and the reason, so a user can fix the input
without reading our code."""

from __future__ import annotations

import os


class IgnjaxError(Exception):
    """Base class of all errors raised by ignjax on bad input or bad config."""


class InputError(IgnjaxError, ValueError):
    """Bad input file or value.

    Args:
        path: the file (or other source) the problem is in; may be empty.
        where: the place inside it: a prim path, a JSON field path such as
            ``rooms[2].floorPolygon``, a line number (``line 7``) or a
            config key.
        reason: what is wrong, in words.
    """

    def __init__(self, path: str | os.PathLike | None, where: str | None, reason: str):
        self.path = str(path) if path else ""
        self.where = where or ""
        self.reason = reason
        parts = [p for p in (self.path, self.where) if p]
        super().__init__(": ".join(parts + [reason]))

    def __reduce__(self):
        # pickled by its fields, so that it crosses process boundaries (a
        # worker of ``--workers N``) as the same error
        return type(self), (self.path or None, self.where or None, self.reason), self.__dict__


class SceneError(InputError):
    """A scene source cannot be turned into a valid :class:`Scene`."""


class EpisodeError(InputError):
    """An episode file or record is invalid."""


class ConfigError(InputError):
    """A configuration value, TOML file or command-line option is invalid."""


def call_recording_warnings(fn, *args):
    """``(fn(*args), warnings)``: the warnings the call raised, as
    ``(category, message)`` pairs that cross process boundaries (the unit
    of work of a worker process, whose warnings :func:`warn_again` raises
    in the parent)."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = fn(*args)
    return result, [(w.category, str(w.message)) for w in caught]


def warn_again(caught, stacklevel: int = 3) -> None:
    """Raise the ``(category, message)`` pairs of :func:`call_recording_warnings` here, in order."""
    import warnings

    for category, message in caught:
        warnings.warn(message, category, stacklevel=stacklevel)

