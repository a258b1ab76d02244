"""The optional parts of the install (extras): ``pip install "ignjax[llm]"``,
``"ignjax[render]"`` and ``"ignjax[rl]"``. A module that needs one imports its packages with
:func:`optional_module`, so that the core install still imports it, and a
command checks with :func:`require_extra` before any work; either way a user
without the part reads one line naming the ``pip install`` that adds it."""

from __future__ import annotations

import importlib

from ignjax.errors import IgnjaxError

EXTRAS = {"llm": "MLLM agents and the scripted model server", "render": "MuJoCo Warp's batch renderer",
          "rl": "the Gymnasium vector-environment adapter and the PPO trainer of the RL environment"}
"""The optional parts of the install (``pip install "ignjax[NAME]"``) and what each one is for."""


class MissingExtra(IgnjaxError, ImportError):
    """A package of an optional part of the install is not installed.

    Args:
        package: the missing module's name (``aiohttp``).
        extra: the extra that installs it (a key of :data:`EXTRAS`).
    """

    def __init__(self, package: str, extra: str):
        self.package, self.extra = package, extra
        super().__init__(f"the {package!r} package is not installed; it comes with the {extra!r} extra "
                         f"({EXTRAS[extra]}): pip install \"ignjax[{extra}]\"")

    def __reduce__(self):
        return type(self), (self.package, self.extra), self.__dict__


class _Absent:
    """Stands for a module of an optional part that is not installed: using
    any of its names raises :class:`MissingExtra`, so a module that merely
    imports it (``import ignjax.agents.llm``) still imports."""

    def __init__(self, package: str, extra: str):
        self._package, self._extra = package, extra

    def __getattr__(self, name: str):
        if name.startswith("__"):
            raise AttributeError(name)
        raise MissingExtra(self._package, self._extra)


def optional_module(name: str, extra: str):
    """``importlib.import_module(name)``, or, when the package is not
    installed, a stand-in whose every attribute raises :class:`MissingExtra`
    naming ``pip install "ignjax[extra]"``."""
    try:
        return importlib.import_module(name)
    except ImportError:
        return _Absent(name.partition(".")[0], extra)


def require_extra(package: str, extra: str) -> None:
    """Raise :class:`MissingExtra` now, before any work, when ``package`` (of
    the extra ``extra``) cannot be imported."""
    try:
        importlib.import_module(package)
    except ImportError:
        raise MissingExtra(package, extra) from None


__all__ = ["EXTRAS", "MissingExtra", "optional_module", "require_extra"]
