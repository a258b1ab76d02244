"""Settings of the LLM client: :class:`LLMConfig`, one frozen dataclass.

The config holds only values that are safe to write into ``run.json``: the
API key is never a field. ``api_key_env`` is the *name* of an environment
variable, read by the client when it starts (see
:mod:`ignjax.agents.llm.client`); if that variable is unset the client sends
no ``Authorization`` header, which is what local servers (vLLM, the scripted
test double) expect.

Every value is checked when the config is built, directly or through
:meth:`LLMConfig.from_dict` (the form a TOML table arrives in); a bad value
raises :class:`~ignjax.errors.ConfigError` naming the field and the reason,
e.g. ``llm.timeout_s: must be > 0, got -1``. The value of
``api_key_env`` is never echoed in an error, in case someone pasted the key
itself there.

The defaults name no server (``endpoints = []``, ``model = ""``), so that the
sweep's ``[llm]`` table can exist in every configuration; a config is
*usable* (:meth:`LLMConfig.check_usable`, called by the client and by
:meth:`LLMConfig.from_dict`) once it names a model and at least one endpoint
(or replays from a cache).
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math
import re
from dataclasses import dataclass
from typing import Any, ClassVar

from ignjax.errors import ConfigError

STRUCTURED_MODES = ("auto", "json_schema", "none")
IMAGE_DETAILS = ("auto", "low", "high")
PRICE_KEYS = ("prompt", "completion")
# request keys the client sets itself; extra_body may not override them
RESERVED_BODY_KEYS = frozenset({"model", "messages", "temperature", "seed", "max_tokens", "response_format", "stream"})
_ENV_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class LLMConfig:
    """How to reach an OpenAI-compatible chat-completions server and how to
    call it.

    Attributes:
        endpoints: base URLs such as ``http://127.0.0.1:8000/v1``; requests
            go to ``{base}/chat/completions``. Several endpoints share the
            load (least requests in flight first). May be empty only in
            replay mode.
        model: the model name sent in every request.
        api_key_env: NAME of the environment variable holding the API key
            (``None`` or ``""``: never send one). Unset variable: no header.
        temperature: sampling temperature, in [0, 2]; 0 (deterministic
            decoding), the paper's setting.
        seed: sampling seed sent with each request (``None``: not sent); also
            seeds the retry jitter.
        max_tokens: completion token limit per request; 1024, the paper's
            cap for each Planner, Grounder and Oracle call.
        timeout_s: total time allowed for one HTTP attempt.
        concurrency: requests in flight at once, per endpoint.
        max_retries: retries of one request after its first attempt.
        max_retries_per_episode: retries summed over all requests with the
            same ``tag`` (an episode id); an empty tag has no such cap.
        backoff_base_s: first retry waits up to this (full jitter), doubling
            each retry.
        backoff_max_s: cap of one wait, ``Retry-After`` included.
        structured: ``"json_schema"`` sends ``response_format`` with the
            request's schema; ``"none"`` never sends it (prompt + tolerant
            parser); ``"auto"`` sends it and falls back to ``"none"`` per
            endpoint after a 400 that names response_format / json_schema /
            guided decoding.
        image_detail: ``detail`` of image parts (``auto``/``low``/``high``;
            ``None``: not sent).
        cache_dir: folder of the response cache ``llm_cache.sqlite``
            (``None``: no cache).
        replay: answer only from the cache, never send; a miss is an error.
            Needs ``cache_dir`` (or a cache given to the client).
        paraphrase: send each oracle answer the agent reads through the
            model for a rewording first (same endpoints, cache and
            accounting; transcript role ``paraphrase``); a rewording that
            breaks the template's rules
            (:func:`ignjax.sim.oracle_text.paraphrase_leaks`) is dropped for
            the template and counted in ``paraphrase_rejected``. Changes
            results, so it is part of a run's fingerprint.
        naive_unbudgeted: the naive-QA rows (agents whose name ends in
            ``-naive``) run with no question budget, the reading of the
            paper's naive rows whose |Q| exceeds the budget (docs/protocol.md,
            "Reading the paper's tables"); every other agent keeps the budget.
            Changes results, so it is part of a run's fingerprint.
        prices: USD per 1M tokens, ``{"prompt": x, "completion": y}``.
        extra_body: extra keys merged into each request's JSON (for example
            vLLM's ``guided_decoding_backend``); may not set the keys the
            client sets itself (model, messages, temperature, seed,
            max_tokens, response_format, stream).
    """

    SECTION: ClassVar[str] = "llm"
    endpoints: tuple[str, ...] = ()
    model: str = ""
    api_key_env: str | None = "OPENAI_API_KEY"
    temperature: float = 0.0
    seed: int | None = 0
    max_tokens: int = 1024
    timeout_s: float = 120.0
    concurrency: int = 16
    max_retries: int = 6
    max_retries_per_episode: int = 60
    backoff_base_s: float = 0.5
    backoff_max_s: float = 30.0
    structured: str = "auto"
    image_detail: str | None = None
    cache_dir: str | None = None
    replay: bool = False
    paraphrase: bool = False
    naive_unbudgeted: bool = False
    prices: dict | None = None
    extra_body: dict | None = None

    def __post_init__(self):
        _validate(self, self.SECTION, None)

    @classmethod
    def from_dict(cls, d: Any, where: str = "llm", path: str | None = None) -> "LLMConfig":
        """Build a usable config from a plain mapping (a TOML table, JSON object).

        Args:
            d: the mapping; unknown keys are errors, ``endpoints`` (unless
                ``replay``) and ``model`` are required.
            where: how the table is named in messages (``llm``).
            path: the file it came from, if any (first part of messages).
        """
        if not isinstance(d, dict):
            raise ConfigError(path, where, f"expected a table of settings, got {type(d).__name__}")
        names = [f.name for f in dataclasses.fields(cls)]
        unknown = sorted(set(d) - set(names))
        if unknown:
            raise ConfigError(path, f"{where}.{unknown[0]}", f"unknown setting; known: {', '.join(names)}")
        for req in ("endpoints", "model"):
            if req not in d and not (req == "endpoints" and d.get("replay") is True):
                raise ConfigError(path, f"{where}.{req}", "required setting is missing")
        values = dict(d)
        if isinstance(values["endpoints"], list):
            values["endpoints"] = tuple(values["endpoints"])
        obj = object.__new__(cls)
        for name in names:
            default = next(f.default for f in dataclasses.fields(cls) if f.name == name)
            object.__setattr__(obj, name, values.get(name, default))
        _validate(obj, where, path)
        obj.check_usable(where, path)
        return obj

    def check_usable(self, where: str = "llm", path: str | None = None) -> None:
        """Raise :class:`ConfigError` unless the config names a model and at
        least one endpoint (none needed under ``replay``)."""
        if not self.endpoints and not self.replay:
            _fail(path, where, "endpoints", "needs at least one URL such as http://127.0.0.1:8000/v1 "
                                            "(empty is allowed only with replay = true)")
        if not self.model.strip():
            _fail(path, where, "model", "needs the served model's name")

    def public_dict(self) -> dict:
        """Plain JSON-ready values, safe for ``run.json``: the config holds no
        key (``api_key_env`` is a variable's name)."""
        out = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            out[f.name] = list(v) if isinstance(v, tuple) else copy.deepcopy(v)
        return out

    @property
    def structured_wanted(self) -> bool:
        """Whether requests with a schema start with ``response_format``."""
        return self.structured != "none"


def _fail(path, where, name, reason) -> None:
    raise ConfigError(path, f"{where}.{name}", reason)


def _number(obj, name, where, path, *, lo=None, lo_open=False, hi=None) -> None:
    v = getattr(obj, name)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        _fail(path, where, name, f"expected a finite number, got {v!r}")
    if lo is not None and (v <= lo if lo_open else v < lo):
        _fail(path, where, name, f"must be {'>' if lo_open else '>='} {lo}, got {v!r}")
    if hi is not None and v > hi:
        _fail(path, where, name, f"must be <= {hi}, got {v!r}")
    object.__setattr__(obj, name, float(v))


def _integer(obj, name, where, path, *, lo: int, optional=False) -> None:
    v = getattr(obj, name)
    if v is None and optional:
        return
    if isinstance(v, bool) or not isinstance(v, int):
        _fail(path, where, name, f"expected an integer{' or none' if optional else ''}, got {v!r}")
    if v < lo:
        _fail(path, where, name, f"must be >= {lo}, got {v!r}")


def _choice(obj, name, where, path, choices, optional=False) -> None:
    v = getattr(obj, name)
    if v is None and optional:
        return
    if v not in choices:
        _fail(path, where, name, f"must be one of {', '.join(map(repr, choices))}, got {v!r}")


def _validate(obj: LLMConfig, where: str, path: str | None) -> None:
    """Check and normalise every field of ``obj`` in place (frozen: via
    ``object.__setattr__``)."""
    eps = obj.endpoints
    if isinstance(eps, str):
        eps = (eps,)
    if not isinstance(eps, (tuple, list)) or not all(isinstance(e, str) for e in eps):
        _fail(path, where, "endpoints", f"expected a list of URLs, got {eps!r}")
    eps = tuple(e.rstrip("/") for e in eps)
    for i, e in enumerate(eps):
        if not re.match(r"^https?://[^/\s]+", e):
            _fail(path, where, f"endpoints[{i}]", f"expected an http:// or https:// base URL such as "
                  f"http://127.0.0.1:8000/v1, got {e!r}")
    if len(set(eps)) != len(eps):
        _fail(path, where, "endpoints", "lists the same URL twice")
    for name in ("replay", "paraphrase", "naive_unbudgeted"):
        if not isinstance(getattr(obj, name), bool):
            _fail(path, where, name, f"expected true or false, got {getattr(obj, name)!r}")
    object.__setattr__(obj, "endpoints", eps)

    if not isinstance(obj.model, str):
        _fail(path, where, "model", f"expected a model name, got {obj.model!r}")
    ak = obj.api_key_env
    if ak == "":
        ak = None
        object.__setattr__(obj, "api_key_env", None)
    if ak is not None and (not isinstance(ak, str) or not _ENV_NAME.match(ak)):
        # never echo the value: it may be the key itself pasted in the wrong place
        _fail(path, where, "api_key_env", "must be the NAME of an environment variable (letters, digits, "
              "underscore), or none; the key itself belongs in that variable, not in the config")
    _number(obj, "temperature", where, path, lo=0.0, hi=2.0)
    _integer(obj, "seed", where, path, lo=-(2**63), optional=True)
    _integer(obj, "max_tokens", where, path, lo=1)
    _number(obj, "timeout_s", where, path, lo=0.0, lo_open=True)
    _integer(obj, "concurrency", where, path, lo=1)
    _integer(obj, "max_retries", where, path, lo=0)
    _integer(obj, "max_retries_per_episode", where, path, lo=0)
    _number(obj, "backoff_base_s", where, path, lo=0.0)
    _number(obj, "backoff_max_s", where, path, lo=0.0)
    if obj.backoff_max_s < obj.backoff_base_s:
        _fail(path, where, "backoff_max_s", f"must be >= backoff_base_s ({obj.backoff_base_s}), got {obj.backoff_max_s}")
    _choice(obj, "structured", where, path, STRUCTURED_MODES)
    _choice(obj, "image_detail", where, path, IMAGE_DETAILS, optional=True)
    cd = obj.cache_dir
    if cd is not None:
        if hasattr(cd, "__fspath__"):
            cd = str(cd)
        if not isinstance(cd, str) or not cd:
            _fail(path, where, "cache_dir", f"expected a folder path or none, got {cd!r}")
        object.__setattr__(obj, "cache_dir", cd)

    pr = obj.prices
    if pr is not None:
        if not isinstance(pr, dict):
            _fail(path, where, "prices", f"expected a table {{prompt = x, completion = y}}, got {pr!r}")
        extra = sorted(set(pr) - set(PRICE_KEYS))
        if extra:
            _fail(path, where, f"prices.{extra[0]}", f"unknown key; known: {', '.join(PRICE_KEYS)}")
        for k in PRICE_KEYS:
            v = pr.get(k)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                _fail(path, where, f"prices.{k}", f"expected a number >= 0 (USD per 1M tokens), got {v!r}")
        object.__setattr__(obj, "prices", {k: float(pr[k]) for k in PRICE_KEYS})

    eb = obj.extra_body
    if eb is not None:
        if not isinstance(eb, dict) or not all(isinstance(k, str) for k in eb):
            _fail(path, where, "extra_body", f"expected a table with string keys, got {eb!r}")
        clash = sorted(set(eb) & RESERVED_BODY_KEYS)
        if clash:
            _fail(path, where, f"extra_body.{clash[0]}", "is set by the client itself; use the matching [llm] setting")
        try:
            json.dumps(eb)
        except (TypeError, ValueError) as e:
            _fail(path, where, "extra_body", f"must be JSON-serialisable: {e}")
        object.__setattr__(obj, "extra_body", copy.deepcopy(eb))


__all__ = ["IMAGE_DETAILS", "LLMConfig", "STRUCTURED_MODES"]
