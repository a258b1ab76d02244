"""The oracle's words: array facts -> short natural-language answers (host side).

The simulator computes answers as arrays (:class:`ignjax.sim.types.Answer`,
by :mod:`ignjax.sim.oracle`); agents that read language (MLLM agents, logs,
reports) get them rendered here. The templates are our own wording; they
follow the paper's rules:

* Type 1 (appearance) repeats the episode's target description, which
  never names a room.
* Type 2 (region) names the goal room and a coarse region, never an
  appearance detail.
* Type 3 (route) says which way to go, egocentrically ("to your left"),
  toward which room and past which landmark: never a digit, a unit, a
  compass direction, a heading, a coordinate, a step count or a path length
  (:func:`route_leaks` checks this).
* Type 4 (confirmation) says yes or no with a short reason and, after a
  yes, whether to stop now or take one closer move first.
* After each step with an active route hint, the controller's report
  (:func:`hint_report_text`) says whether the agent got closer and on which
  side the hinted area lies now, relative to its current facing (the same
  egocentric words, no digit or compass word).

Optionally (``llm.paraphrase``), a model rewords each answer before the
agent reads it (:func:`paraphrase_messages`, :data:`PARAPHRASE_SCHEMA`;
the host loop sends it). A rewording replaces the template only when
:func:`paraphrase_leaks` finds nothing in it that the template's own rules
forbid; otherwise the template is used.
"""

from __future__ import annotations

import re
import zlib

from ignjax.protocol import QUESTION_TYPES
from ignjax.scenes import vocab
from ignjax.sim import types as T

SECTOR_PHRASES = (
    "straight ahead", "ahead and to your left", "to your left", "behind you on the left",
    "behind you", "behind you on the right", "to your right", "ahead and to your right",
)
"""Egocentric direction of sector k (view layout: 0 front, 2 left, 4 rear, 6 right)."""

HINT_PROGRESS_TEXT = {
    T.HINT_NONE: "",
    T.HINT_CLOSER: "You are getting closer to the area the last route hint pointed to.",
    T.HINT_SAME: "You have not got any closer to the area the last route hint pointed to.",
    T.HINT_FARTHER: "You are moving away from the area the last route hint pointed to.",
    T.HINT_REACHED: "You have reached the area the last route hint pointed to.",
    T.HINT_STOP: "You are close enough to the target to stop if you can see it.",
}


def _pick(options: tuple[str, ...], key: str) -> str:
    return options[zlib.crc32(key.encode()) % len(options)]


def _category(categories: tuple[str, ...], code: int) -> str | None:
    return vocab.category_display(categories[code]) if 0 <= code < len(categories) else None


def _room(code: int) -> str | None:
    return vocab.ROOM_DISPLAY[vocab.ALL_ROOM_LABELS[code]] if 0 <= code < len(vocab.ALL_ROOM_LABELS) else None


def appearance_text(description: str) -> str:
    """Type 1: the sanitized target description."""
    return description


def region_text(goal_region: str) -> str:
    """Type 2: the goal room and region fact of the episode."""
    return goal_region


def route_text(room_label: int, sector: int, landmark: int, in_room: bool, categories: tuple[str, ...],
               key: str = "") -> str:
    """Type 3: a coarse route hint from its array facts.

    Args:
        room_label: label code of the room the route leads toward.
        sector: egocentric sector 0..7 of the way to take.
        landmark: category code of a landmark on the way, or -1.
        in_room: the first stretch of the route stays in the current room.
        categories: the bank's category vocabulary.
        key: varies the wording deterministically (e.g. episode id + step).
    """
    way = SECTOR_PHRASES[int(sector) % 8]
    room = _room(int(room_label))
    mark = _category(categories, int(landmark))
    past = f", past the {mark}" if mark else ""
    if in_room or room is None:
        return _pick((f"Stay in this room and head {way}{past}.",
                      f"You do not need to leave this room yet; go {way}{past}.",
                      f"Keep to this room and move {way}{past}."), key)
    return _pick((f"Head {way} and go through toward the {room}{past}.",
                  f"Take the way {way}; it leads toward the {room}{past}.",
                  f"Go {way}, in the direction of the {room}{past}."), key)


def confirm_text(answer: int, follow_up: int, key: str = "", pointed: bool = True) -> str:
    """Type 4: yes/no with a short reason and the follow-up instruction;
    ``pointed`` False: the question pointed at no object (a no with that reason)."""
    if not pointed:
        return _pick(("No: there is no object at the place you asked about.",
                      "No. Nothing there is an object that could be checked."), key)
    if answer == 1:
        if follow_up == T.FOLLOW_STOP_NOW:
            return _pick(("Yes, that is the one, and you are close enough: stop here.",
                          "Yes, that is it. You can stop now."), key)
        return _pick(("Yes, that is the one. Move a little closer, then stop.",
                      "Yes, that is it; get a little closer and then stop."), key)
    return _pick(("No, that is not the one you are looking for.",
                  "No. The one in front of you is not the target.",
                  "No, the target is not what you are looking at."), key)


def refused_text() -> str:
    return "You have no questions left; keep searching on your own."


def answer_text(question: int, refused: bool, *, appearance: str, region: str, hint_room_label: int = -1,
                hint_sector: int = 0, hint_landmark: int = -1, hint_in_room: bool = False, confirm: int = -1,
                follow_up: int = 0, categories: tuple[str, ...] = (), key: str = "", pointed: bool = True) -> str:
    """The oracle's answer to one question of type ``question`` (1..4) in
    words, from the episode's texts (Type 1: its description, Type 2: its
    goal region) and the answer's array facts (Types 3 and 4); the refusal
    when the question was refused. ``key`` varies the wording
    deterministically (episode id and step)."""
    if refused:
        return refused_text()
    if question == 1:
        return appearance_text(appearance)
    if question == 2:
        return region_text(region)
    if question == 3:
        return route_text(hint_room_label, hint_sector, hint_landmark, hint_in_room, categories, key)
    if question == 4:
        return confirm_text(confirm, follow_up, key, pointed)
    return ""


def hint_progress_text(progress: int) -> str:
    """Qualitative progress report of an active Type-3 hint after a step."""
    return HINT_PROGRESS_TEXT.get(int(progress), "")


def hint_bearing_phrase(progress: int, bearing: int) -> str:
    """Where the active hint's area lies now, relative to the agent's current
    facing (:attr:`~ignjax.sim.types.Answer.hint_bearing`, sector 0..7): a
    :data:`SECTOR_PHRASES` entry. "" without a bearing (-1: no hint) and once
    the area is reached or the target is within the stop radius
    (``progress`` :data:`~ignjax.sim.types.HINT_REACHED` or ``HINT_STOP``):
    the agent then stands at the hinted area, and its side no longer guides."""
    b, p = int(bearing), int(progress)
    if not 0 <= b < len(SECTOR_PHRASES) or p in (T.HINT_REACHED, T.HINT_STOP):
        return ""
    return SECTOR_PHRASES[b]


def hint_report_text(progress: int, bearing: int) -> str:
    """What the controller reports about an active Type-3 hint after a step:
    its progress (:func:`hint_progress_text`) and where the hinted area lies
    now (:func:`hint_bearing_phrase`), e.g. "You are getting closer to the
    area the last route hint pointed to; it is now ahead and to your left."
    The paper's controller recomputes the relative bearing after every move
    or turn, so the hint's side stays current after a detour. Just after the
    hint was given (no progress yet) only the direction is said; "" with
    neither (no hint)."""
    said = hint_progress_text(progress)
    way = hint_bearing_phrase(progress, bearing)
    if not way:
        return said
    if not said:
        return f"The area the last route hint pointed to is {way}."
    return f"{said[:-1]}; it is now {way}."


_DIGIT = re.compile(r"\d")
_UNITS = re.compile(r"\b(met(er|re)s?|cm|mm|km|centimet(er|re)s?|millimet(er|re)s?|feet|foot|ft|yards?|inch(es)?|steps?|paces?|"
                    r"degrees?|deg|rad(ians?)?|seconds?|minutes?)\b", re.I)
_COMPASS = re.compile(r"\b(north|south|east|west|north-?east|north-?west|south-?east|south-?west|northern|southern|"
                      r"eastern|western|heading|bearing|azimuth|compass)\b", re.I)
_COORD = re.compile(r"\b[xyz]\s*[=:]|\(\s*-?[\d.]+\s*,|\bcoordinates?\b", re.I)
_NUMBER_WORDS = re.compile(r"\b(zero|one|two|three|four|five|six|seven|eight|nine|ten|eleven|twelve|twenty|thirty|"
                           r"forty|fifty|hundred|half|quarter|dozen)\b", re.I)


def route_leaks(text: str) -> list[str]:
    """Everything in a Type-3 text that the protocol forbids: digits, number
    words, units, compass words and headings, coordinates. Empty when clean."""
    out = []
    for name, pat in (("digit", _DIGIT), ("unit", _UNITS), ("compass", _COMPASS), ("coordinate", _COORD),
                      ("number word", _NUMBER_WORDS)):
        out += [f"{name}: {m.group(0)!r}" for m in pat.finditer(text)]
    return out


# ---------------------------------------------------------------------------
# paraphrase by a model (llm.paraphrase)
# ---------------------------------------------------------------------------

PARAPHRASE_SCHEMA = {
    "type": "object",
    "properties": {"text": {"type": "string", "maxLength": 400}},
    "required": ["text"],
    "additionalProperties": False,
}
"""JSON schema of a paraphrase reply: ``{"text": "<the reworded answer>"}``."""

PARAPHRASE_SYSTEM = (
    "You reword the short answers a helper gives to a robot that is searching a house for one object. Say the "
    "same thing in your own words, in one or two short sentences, speaking to the robot. Keep the meaning "
    "exactly: add nothing (no new details, places or reasons), leave nothing out, keep a yes a yes and a no a no, "
    "and use no numbers, distances, units or compass directions. "
    'Reply with one JSON object and nothing else: {"text": "<the reworded answer>"}.'
)
"""The paraphrase request's system prompt (our wording)."""


def paraphrase_messages(question: int, text: str) -> list[dict]:
    """Chat messages asking a model to reword the oracle's answer ``text`` to a
    question of type ``question`` (1..4) without adding information."""
    kind = QUESTION_TYPES[int(question) - 1]
    return [{"role": "system", "content": PARAPHRASE_SYSTEM},
            {"role": "user", "content": f"The helper's answer to a {kind} question:\n{text}"}]


def _words(words) -> re.Pattern:
    alt = "|".join(sorted((re.escape(w) for w in words), key=len, reverse=True))
    return re.compile(rf"\b({alt})(e?s)?\b", re.I)


_ROOM_WORDS = _words(vocab.ROOM_DISPLAY[label] for label in vocab.ROOM_LABELS)
_LOOK_WORDS = _words(tuple(vocab.COLORS) + ("grey",) + vocab.MATERIALS)
_YES = re.compile(r"\byes\b", re.I)
_NO = re.compile(r"\b(no|not|nope)\b|n[\'\u2019]t\b", re.I)
_CLOSER = re.compile(r"\b(closer|nearer)\b", re.I)


def paraphrase_leaks(question: int, text: str, template: str) -> list[str]:
    """What in a model's rewording ``text`` of the oracle's answer
    ``template`` (question type ``question``) breaks a rule the template
    keeps; empty when the rewording may replace the template.

    Simple word checks, each against the template's own rules:

    * every type: an empty rewording;
    * Type 1 (appearance; never places the target): a room name
      (:data:`~ignjax.scenes.vocab.ROOM_LABELS`, plurals too) the template
      does not contain;
    * Type 2 (region; adds no appearance detail): a colour or material word
      (:data:`~ignjax.scenes.vocab.COLORS`, ``MATERIALS``) the template does
      not contain;
    * Type 3 (route): :func:`route_leaks`, the template's own filter;
    * Type 4 (confirmation): :func:`route_leaks` too (a confirmation gives no
      distance) but for number words ("that is the one"), and the
      answer kept: the template starts with "Yes" or
      "No"; a yes needs the word "yes" and no negation (no, not, n't: a
      rewording that negates anything is refused, erring on the side of the
      template), a no needs a negation and no "yes"; a yes that says to move
      closer keeps "closer" (or "nearer").
    """
    t = str(text or "").strip()
    if not t:
        return ["empty: the rewording is empty"]
    q = int(question)
    out: list[str] = []
    if q == 1:
        out += [f"room: {m.group(0)!r}" for m in _ROOM_WORDS.finditer(t)
                if not re.search(rf"\b{re.escape(m.group(1))}", template, re.I)]
    elif q == 2:
        out += [f"appearance: {m.group(0)!r}" for m in _LOOK_WORDS.finditer(t)
                if not re.search(rf"\b{re.escape(m.group(1))}", template, re.I)]
    elif q == 3:
        out += route_leaks(t)
    elif q == 4:  # "that is the one": a pronoun in a confirmation, not a count
        out += [x for x in route_leaks(t) if not x.startswith("number word")]
    if q == 4:
        yes = str(template).lstrip().lower().startswith("yes")
        if yes and (not _YES.search(t) or _NO.search(t)):
            out.append("answer: the rewording does not keep the yes")
        if not yes and (not _NO.search(t) or _YES.search(t)):
            out.append("answer: the rewording does not keep the no")
        if yes and _CLOSER.search(template) and not _CLOSER.search(t):
            out.append("follow-up: the rewording drops the closer move")
    return out
