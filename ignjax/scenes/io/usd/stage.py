"""Opening a USD stage and reading what every stage states: its up axis, its
unit, the semantic class labels on its prims; the ``ignjax:`` and semantic
attribute names that export and import share; import warnings, and USD's own
diagnostics kept off stderr and turned into short ones of ours.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import sys
import warnings
from pathlib import Path

from pxr import Tf, Usd, UsdGeom

from ignjax.errors import SceneError

NS = "ignjax:"
ATTR_KIND = NS + "kind"
"""Token naming what an ``ignjax`` prim is: scene, room, wall, door,
instance, geom or bbox."""
ATTR_ID = NS + "id"

ISAAC_TYPE_ATTR = "semantic:Semantics:params:semanticType"
ISAAC_DATA_ATTR = "semantic:Semantics:params:semanticData"
LABELS_TAXONOMY = "class"
LABELS_ATTR = f"semantics:labels:{LABELS_TAXONOMY}"

_SCENES_DIR = str(Path(__file__).parents[2])
"""``ignjax/scenes``: import warnings point at the first caller outside it."""


class UsdImportWarning(UserWarning):
    """Something in a stage was skipped or repaired on import (a missing
    sublayer, reference or payload, an invalid ``defaultPrim``, prims of
    unsupported types)."""


def warn_import(source: str, message: str) -> None:
    """Issue a :class:`UsdImportWarning` about ``source``, attributed to the
    first caller outside ``ignjax.scenes``."""
    frame, level = sys._getframe(0), 1
    while frame is not None and frame.f_code.co_filename.startswith(_SCENES_DIR):
        frame, level = frame.f_back, level + 1
    warnings.warn(f"{source}: {message}", UsdImportWarning, stacklevel=level)


MAX_SEPARATE_WARNINGS = 3
"""Up to this many USD messages of one kind are warned about one by one;
more become one summary warning with a count and examples."""

_INTERNALS = re.compile(r"pxr|\bTf|\.cpp\b|Error in '|Traceback")
_STAGE_NOTE = re.compile(r"\s*\([^()]*\bon stage @[^@]*@ <0x[0-9a-fA-F]+>\)")


def one_line(text) -> str:
    """USD's message text on one line, without the trailing
    ``(instantiating stage on stage @...@ <0x...>)`` note."""
    return _STAGE_NOTE.sub("", " ".join(str(text).split())).strip()


@contextlib.contextmanager
def usd_diagnostics():
    """Keep USD's own warnings and status messages off stderr while the block
    runs (``Tf.DiagnosticTrap``; usd-core releases without it print them as
    before).

    Yields:
        A list that, once the block has ended, holds the text of each
        warning USD issued in it (one line each), for the caller to report
        with :func:`warn_usd_messages`.
    """
    texts: list[str] = []
    trap_type = getattr(Tf, "DiagnosticTrap", None)
    if trap_type is None:
        yield texts
        return
    with trap_type() as trap:
        try:
            yield texts
        finally:
            texts.extend(one_line(w.commentary) for w in trap.GetWarnings())
            trap.Clear()


def summarize(items: list[str], what: str, limit: int = MAX_SEPARATE_WARNINGS) -> list[str]:
    """The items as they are when there are at most ``limit``, else one line
    ``"<n> <what>, e.g. a; b; c; and <k> more"``."""
    if len(items) <= limit:
        return list(items)
    return [f"{len(items)} {what}, e.g. {'; '.join(items[:limit])}; and {len(items) - limit} more"]


def warn_usd_messages(source: str, messages, known=()) -> None:
    """Warn about USD's own messages (from :func:`usd_diagnostics`) that say
    something not already reported: those that contain none of the ``known``
    texts (the composition errors, warned about on their own), once each,
    in short, and as one summary line when there are many."""
    seen = [m for m in dict.fromkeys(messages) if m and not any(k and k in m for k in known)]
    short = [m if len(m) <= 200 else m[:197] + "..." for m in seen]
    for line in summarize(short, "further messages from USD"):
        warn_import(source, f"USD reported: {line}")


def _open_reason(path: Path, error: Exception) -> str:
    """Why USD could not open ``path``: one short line of our own (the
    first cause USD gives, without its internals or the file's path)."""
    try:
        with open(path, "rb") as f:
            head = f.read(4096)
        if not head.strip():
            return "empty file"
    except OSError:
        pass
    causes = [getattr(a, "commentary", None) for a in getattr(error, "args", ())]
    cause = next((one_line(c) for c in causes if c), "")
    cause = re.sub(r"@?<[^<>]*>@?|@[^@]*@", "", cause)  # paths: the message names the file already
    cause = re.sub(r"^is\s+", "", " ".join(cause.split()).strip(" :;,.-'"))
    if not cause or _INTERNALS.search(cause):
        return "not a readable USD file"
    cause = cause[0].lower() + cause[1:]
    if len(cause) > 100:
        cause = cause[:97].rstrip() + "..."
    return f"not a readable USD file ({cause})"


def open_stage(path: str | os.PathLike):
    """Open a stage with all payloads loaded.

    USD's own diagnostics are kept off stderr: its composition errors stay
    on the stage (``GetCompositionErrors``) for the caller to report, and
    other warnings it issues while opening become
    :class:`UsdImportWarning` (see :func:`warn_usd_messages`).

    Raises:
        SceneError: the file is missing, empty, or not a USD file USD can
            open; one line naming the file and the first cause USD gives,
            without the library's internals.
    """
    p = Path(path)
    if not p.exists():
        raise SceneError(p, None, "no such file")
    if p.is_dir():
        raise SceneError(p, None, "is a directory, not a USD file")
    with usd_diagnostics() as messages:
        try:
            stage = Usd.Stage.Open(str(p), load=Usd.Stage.LoadAll)
        except (Tf.ErrorException, RuntimeError) as e:
            stage, error = None, e
        else:
            error = None
    if error is not None:
        raise SceneError(p, None, _open_reason(p, error)) from None
    if stage is None:
        raise SceneError(p, None, "not a readable USD file")
    warn_usd_messages(str(p), messages, [one_line(e) for e in stage.GetCompositionErrors()])
    return stage


def stage_up_axis(stage, path: str | os.PathLike | None = None) -> str:
    """The stage's ``upAxis``: ``"Y"`` or ``"Z"`` (unauthored: USD's fallback, Y).

    Raises:
        SceneError: any other authored value (``X``, or an invalid token),
            naming the file, ``upAxis`` and the value.
    """
    if stage.HasAuthoredMetadata("upAxis"):
        value = str(stage.GetMetadata("upAxis"))
    else:
        value = str(UsdGeom.GetFallbackUpAxis())
    if value not in ("Y", "Z"):
        raise SceneError(path or stage.GetRootLayer().identifier, "upAxis",
                         f"unsupported upAxis {value!r}: USD stages must be Y-up or Z-up")
    return value


def stage_meters_per_unit(stage, path: str | os.PathLike | None = None) -> float:
    """The stage's ``metersPerUnit`` (unauthored: USD's fallback, 0.01).

    Raises:
        SceneError: the value is not a positive finite number.
    """
    value = float(UsdGeom.GetStageMetersPerUnit(stage))
    if not math.isfinite(value) or value <= 0:
        raise SceneError(path or stage.GetRootLayer().identifier, "metersPerUnit",
                         f"metersPerUnit must be a positive number, got {value!r}")
    return value


_ISAAC_TYPE_RE = re.compile(r"^semantic:(?P<inst>[^:]+):params:semanticType$")


def prim_semantic_label(prim) -> str | None:
    """The class label authored on ``prim`` itself, or None.

    Looked up in this order: ``ignjax:category``; ``UsdSemantics.LabelsAPI``
    ``semantics:labels:class`` (first non-empty token); Isaac-style
    ``semantic:<name>:params:semanticType == "class"`` with its
    ``semanticData`` (the part before a comma when it lists several).
    """
    attr = prim.GetAttribute(NS + "category")
    if attr and attr.HasAuthoredValue():
        value = attr.Get()
        if value:
            return str(value)
    names = prim.GetAuthoredPropertyNames()
    for name in names:
        if name.startswith("semantics:labels:") and name.split(":", 2)[2].lower() == LABELS_TAXONOMY:
            value = prim.GetAttribute(name).Get()
            for token in (value or ()):
                if str(token).strip():
                    return str(token).strip()
    for name in names:
        m = _ISAAC_TYPE_RE.match(name)
        if not m:
            continue
        if str(prim.GetAttribute(name).Get() or "").strip().lower() != LABELS_TAXONOMY:
            continue
        data = prim.GetAttribute(f"semantic:{m.group('inst')}:params:semanticData")
        value = str(data.Get() or "").split(",")[0].strip() if data else ""
        if value:
            return value
    return None
