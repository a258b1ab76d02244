"""Configuration of ``python -m ignjax.sweep``: one frozen dataclass tree.

:class:`SweepConfig` has one section per TOML table: ``run``, ``benchmark``,
``eval``, ``costs``, ``difficulty``, ``derive-costs`` (attribute
``derive_costs``), ``analysis``, ``sim`` (the simulator's own
:class:`ignjax.sim.types.SimConfig`), ``llm`` (the model server of the MLLM
agents, :class:`ignjax.agents.llm.config.LLMConfig`) and ``views`` (their
rendered observations, :class:`ignjax.sim.views.ViewConfig`). Each section checks its values in
``__post_init__`` and raises :class:`ConfigError` naming the key, so a
configuration built from Python is checked like one read from a file.

:func:`resolve` layers defaults <- :data:`QUICK` (``--quick``) <- a TOML file
<- ``--set section.key=value`` items (later wins); a name not in the schema,
a value of the wrong type or one that fails a check is an error naming the
file and line (or ``--set``) and the key. :func:`fingerprint` hashes a
configuration and the studies (``run.json``). ``sweeps/default.toml`` is
:func:`default_toml`'s text (a test keeps them equal); regenerate it with
``python -c "from ignjax.config import default_toml; print(default_toml(), end='')" > sweeps/default.toml``.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import os
import textwrap
from dataclasses import dataclass
from typing import Any, ClassVar

from ignjax.agents import registry
from ignjax.agents.llm.catalog import LLM_AGENTS, get_llm_agent
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.params import check_param_value, make_params, param_docs, param_record, param_values
from ignjax.arrays import field_docs, parse_assignment
from ignjax.episodes.difficulty import validate_alpha, validate_thresholds
from ignjax.errors import ConfigError
from ignjax.protocol import DIFFICULTY_ALPHA, DIFFICULTY_THRESHOLDS, LOCKED_COSTS, SUCCESS_REQUIRES_STOP, SUCCESS_THRESHOLDS
from ignjax.settings import check_fields as _check_fields
from ignjax.settings import check_value as _check_value
from ignjax.settings import line_of as _line_of
from ignjax.settings import load_toml, sections_toml
from ignjax.settings import toml_value as _toml_value
from ignjax.sim.types import SimConfig
from ignjax.sim.views.config import ViewConfig
from ignjax.studies.cost_sensitivity import validate_costs

# ---------------------------------------------------------------------------
# value checks shared by every section
# ---------------------------------------------------------------------------


def _check_agent(name: str, key: str) -> None:
    known = list(registry()) + list(LLM_AGENTS)
    if name not in known:
        raise ConfigError(None, key, f"unknown agent {name!r}; known: {', '.join(known)}")


# ---------------------------------------------------------------------------
# sections
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class RunConfig:
    """Where a run goes and its seed.

    Attributes:
        name: folder of the run under ``out`` (also the report's title).
        out: folder holding the run folders, and ``_benchmarks/`` (benchmarks built from ``benchmark.scenes``,
            reused across runs).
        seed: PRNG seed of every rollout (each episode's key folds in its index in the episode file).
    """

    SECTION: ClassVar[str] = "run"
    name: str = "default"
    out: str = "runs"
    seed: int = 0

    def __post_init__(self):
        _check_fields(self, self.SECTION)


@dataclass(frozen=True)
class BenchmarkConfig:
    """The episodes the studies run on.

    Attributes:
        episodes: an episode file (.jsonl or .jsonl.gz); empty: the shipped scenes/benchmark.jsonl.gz when the
            other settings of this section are the defaults, else one built from ``scenes``.
        scenes: scene folder or file to build the benchmark from; empty: the shipped scenes/ folder.
        subset: episodes in a built benchmark (sampled easy:medium:hard 30:40:30).
        seed: seed of a built benchmark's random choices.
        limit: > 0: keep only N episodes spread evenly over the file (quick runs); 0: all.
    """

    SECTION: ClassVar[str] = "benchmark"
    episodes: str = ""
    scenes: str = ""
    subset: int = 500
    seed: int = 0
    limit: int = 0

    def __post_init__(self):
        _check_fields(self, self.SECTION)


@dataclass(frozen=True)
class EvalConfig:
    """The evaluation: agents x episodes, and the metrics' settings.

    Attributes:
        agents: the agents evaluated: JAX-native agents (``ignjax.agents.registry()``) and MLLM agents
            (``ignjax.agents.llm.catalog.LLM_AGENTS``, e.g. ``vlm``; they need the ``[llm]`` table's server).
        batch: episodes per compiled rollout.
        parts: devices each batch is sharded over (``ignjax.sim.rollout``); 0: all of them.
        bank_mb: the most one bank of scenes (its tables, probe maps and goal fields; one copy per device) may
            take, MiB; a benchmark whose scenes do not fit runs in buckets of scenes of similar size, one at a
            time, with the same results (``ignjax.evaluate.runner.plan_run``).
        thresholds: success distances tau of the SR / OSR / WSR columns, m; positive and increasing.
        costs: per-type question costs charged by WSR (Type 1 appearance, 2 region, 3 route, 4 confirmation);
            default the paper's locked costs.
        require_stop: success also requires an explicit STOP (Habitat's convention); false: the paper's rule,
            final distance <= tau however the episode ended (STOP or step budget).
    """

    SECTION: ClassVar[str] = "eval"
    agents: tuple[str, ...] = ("random", "explorer", "naive_asker", "eig", "shortest_path")
    batch: int = 256
    parts: int = 0
    bank_mb: float = 1024.0
    thresholds: tuple[float, ...] = SUCCESS_THRESHOLDS
    costs: tuple[float, ...] = LOCKED_COSTS
    require_stop: bool = SUCCESS_REQUIRES_STOP

    def __post_init__(self):
        _check_fields(self, self.SECTION)
        for name in self.agents:
            _check_agent(name, "eval.agents")
        if not self.agents:
            raise ConfigError(None, "eval.agents", "must name at least one agent")
        if len(self.costs) != 4:
            raise ConfigError(None, "eval.costs", f"expected 4 costs (one per question type), got {list(self.costs)}")
        validate_costs(self.costs, "eval.costs")
        if self.batch < 1:
            raise ConfigError(None, "eval.batch", "must be >= 1")
        if self.parts < 0:
            raise ConfigError(None, "eval.parts", f"must be >= 0 (0: all devices), got {self.parts}")
        if not self.bank_mb > 0:
            raise ConfigError(None, "eval.bank_mb", f"must be > 0, got {self.bank_mb}")
        if tuple(sorted(self.thresholds)) != self.thresholds or any(t <= 0 for t in self.thresholds):
            raise ConfigError(None, "eval.thresholds", "must be positive and increasing")


@dataclass(frozen=True)
class CostsConfig:
    """The cost-weight sensitivity study.

    Attributes:
        samples: offline cost vectors: row 0 the locked costs, row 1 uniform, the rest uniform on the simplex
            scaled to the locked sum; >= 2.
        seed: seed of the offline cost sample.
        agent: the cost-aware agent re-run in the loop under each charged cost vector.
        scales: in the loop: the locked costs times each scale (positive).
        per_type_factor: in the loop: also each type's cost alone times this factor; 0: skip.
        normalize: accepted for existing files; the studies do not read it.
    """

    SECTION: ClassVar[str] = "costs"
    samples: int = 100_000
    seed: int = 0
    agent: str = "eig"
    scales: tuple[float, ...] = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0)
    per_type_factor: float = 4.0
    normalize: bool = False

    def __post_init__(self):
        _check_fields(self, self.SECTION)
        _check_agent(self.agent, "costs.agent")
        if self.agent not in ("eig",) and not registry()[self.agent].asks:
            raise ConfigError(None, "costs.agent", f"{self.agent!r} never asks: nothing to sweep")
        if any(s <= 0 for s in self.scales) or not self.scales:
            raise ConfigError(None, "costs.scales", f"scales must be positive, got {list(self.scales)}")
        if self.samples < 2:
            raise ConfigError(None, "costs.samples", "must be >= 2")


@dataclass(frozen=True)
class DifficultyConfig:
    """The difficulty-coefficient ablation and calibration.

    Attributes:
        alpha: the reference coefficients of (F_distractor, F_room, F_context, F_start); on the simplex.
        thresholds: the reference bin thresholds of D (easy/medium, medium/hard); 0 <= t0 < t1 <= 1.
        normalize: rescale an ``alpha`` that does not sum to 1 instead of rejecting it.
        alpha_step: grid step of the alpha simplex; in (0, 0.5].
        threshold_step: grid step of the threshold pairs; in (0, 0.5].
        split_seed: seed of the calibration's fit / held-out split of the episodes.
        empty: a setting with an empty bin counts as "unordered" or is skipped ("skip").
    """

    SECTION: ClassVar[str] = "difficulty"
    alpha: tuple[float, ...] = DIFFICULTY_ALPHA
    thresholds: tuple[float, ...] = DIFFICULTY_THRESHOLDS
    normalize: bool = False
    alpha_step: float = 0.05
    threshold_step: float = 0.05
    split_seed: int = 0
    empty: str = "unordered"

    def __post_init__(self):
        _check_fields(self, self.SECTION)
        for key in ("alpha_step", "threshold_step"):
            v = getattr(self, key)
            if not 0 < v <= 0.5:
                raise ConfigError(None, f"difficulty.{key}", f"must be in (0, 0.5], got {v}")
        object.__setattr__(self, "alpha", tuple(validate_alpha(self.alpha, normalize=self.normalize,
                                                               where="difficulty.alpha")))
        object.__setattr__(self, "thresholds", tuple(validate_thresholds(self.thresholds, "difficulty.thresholds")))
        if self.empty not in ("unordered", "skip"):
            raise ConfigError(None, "difficulty.empty", "must be 'unordered' or 'skip'")


@dataclass(frozen=True)
class DeriveCostsConfig:
    """The paper's cost construction from cue statistics (TOML table ``[derive-costs]``).

    Attributes:
        annotations: cue-annotation JSONL file; empty: the paper's published statistics.
        assumption: how the published statistics' unpublished cues are completed: "proxy" or "drop".
        lambdas: weights (lambda_s, lambda_h, lambda_r) of the cue utility; 3 non-negative numbers.
        fit: also fit the lambdas that best reproduce the locked costs.
    """

    SECTION: ClassVar[str] = "derive-costs"
    annotations: str = ""
    assumption: str = "proxy"
    lambdas: tuple[float, ...] = (1 / 3, 1 / 3, 1 / 3)
    fit: bool = True

    def __post_init__(self):
        _check_fields(self, self.SECTION)
        if len(self.lambdas) != 3 or any(v < 0 for v in self.lambdas):
            raise ConfigError(None, "derive-costs.lambdas", f"expected 3 non-negative weights, got {list(self.lambdas)}")


@dataclass(frozen=True)
class AnalysisConfig:
    """The interaction analyses from one agent's question traces and trajectories.

    Attributes:
        agent: the agent analysed (also rolled out when not in ``eval.agents``).
        horizon: matched horizon of Delta-U, planner steps.
        radius: explored-area radius around the path, m.
        trajectories: top-down trajectory plots (0: none).
    """

    SECTION: ClassVar[str] = "analysis"
    agent: str = "eig"
    horizon: int = 5
    radius: float = 1.0
    trajectories: int = 4

    def __post_init__(self):
        _check_fields(self, self.SECTION)
        _check_agent(self.agent, "analysis.agent")


@dataclass(frozen=True)
class AgentsConfig:
    """Every agent's parameters (TOML tables ``[agents.<name>]``, one per registered agent).

    Attributes:
        params: agent name -> parameter name -> value, for every agent of
            :func:`ignjax.agents.registry` (defaults filled in; see
            :func:`ignjax.agents.params.param_values`). A cost-aware agent's
            ``costs`` are not here: it plans with the charged ``eval.costs``.
    """

    SECTION: ClassVar[str] = "agents"
    params: Any = None

    def __post_init__(self):
        given = self.params or {}
        if not isinstance(given, dict):
            raise ConfigError(None, "agents", f"must be a table of [agents.<name>] tables, got {given!r}")
        known = registry()
        full = {}
        for name in given:
            if name not in known:
                raise ConfigError(None, f"agents.{name}", f"unknown agent; known: {', '.join(known)}")
            if not isinstance(given[name], dict):
                raise ConfigError(None, f"agents.{name}", "must be a table of parameter = value")
        for name, agent in known.items():
            values = dict(param_values(agent))
            for key, value in given.get(name, {}).items():
                values[key] = check_param_value(agent, key, value)
            full[name] = values
        object.__setattr__(self, "params", full)

    def __eq__(self, other):
        return isinstance(other, AgentsConfig) and self.params == other.params

    __hash__ = None

    def make(self, name: str, costs=None, sim: SimConfig | None = None):
        """The parameter pytree of agent ``name`` with these values, planning
        with ``costs`` (the charged costs) if it is cost-aware; ``sim``: the
        simulator's configuration (the learned agent's observation is laid
        out and checked by it)."""
        return make_params(registry()[name], self.params[name], costs, sim)

    def used(self, names, sim: SimConfig | None = None) -> dict[str, dict[str, Any]]:
        """``name -> parameters`` of the agents ``names`` (for run.json and report headers): their values, for an
        agent loaded from files what was loaded (the learned agent's checkpoint path and weights' digest, checked
        under ``sim``); an MLLM agent's options."""
        def one(n):
            if n not in self.params:
                return {k: v for k, v in vars(get_llm_agent(n)).items() if k not in ('name', 'description')}
            agent = registry()[n]
            return param_record(agent, self.params[n], sim) if agent.source is not None else dict(self.params[n])

        return {n: one(n) for n in dict.fromkeys(names)}


@dataclass(frozen=True)
class SweepConfig:
    """The whole configuration of a sweep run (one attribute per section).

    Attributes:
        run: :class:`RunConfig`.
        benchmark: :class:`BenchmarkConfig`.
        eval: :class:`EvalConfig`.
        costs: :class:`CostsConfig`.
        difficulty: :class:`DifficultyConfig`.
        derive_costs: :class:`DeriveCostsConfig` (TOML table ``[derive-costs]``).
        analysis: :class:`AnalysisConfig`.
        sim: the simulator's :class:`ignjax.sim.types.SimConfig`.
        llm: the model server and request settings of the MLLM agents (:class:`ignjax.agents.llm.config.LLMConfig`);
            needed only when ``eval.agents`` names one.
        views: their rendered observations (:class:`ignjax.sim.views.ViewConfig`).
        agents: :class:`AgentsConfig` (tables ``[agents.<name>]``).
    """

    run: RunConfig = dataclasses.field(default_factory=RunConfig)
    benchmark: BenchmarkConfig = dataclasses.field(default_factory=BenchmarkConfig)
    eval: EvalConfig = dataclasses.field(default_factory=EvalConfig)
    costs: CostsConfig = dataclasses.field(default_factory=CostsConfig)
    difficulty: DifficultyConfig = dataclasses.field(default_factory=DifficultyConfig)
    derive_costs: DeriveCostsConfig = dataclasses.field(default_factory=DeriveCostsConfig)
    analysis: AnalysisConfig = dataclasses.field(default_factory=AnalysisConfig)
    sim: SimConfig = dataclasses.field(default_factory=SimConfig)
    llm: LLMConfig = dataclasses.field(default_factory=LLMConfig)
    views: ViewConfig = dataclasses.field(default_factory=ViewConfig)
    agents: AgentsConfig = dataclasses.field(default_factory=AgentsConfig)

    def __post_init__(self):
        for f in dataclasses.fields(self):
            cls = SECTIONS[_TOML_NAME[f.name]]
            if not isinstance(getattr(self, f.name), cls):
                raise ConfigError(None, _TOML_NAME[f.name], f"must be a {cls.__name__}, got {getattr(self, f.name)!r}")
        mllm = [a for a in self.eval.agents if a in LLM_AGENTS]
        if mllm:
            try:
                self.llm.check_usable()
            except ConfigError as e:
                raise ConfigError(None, e.where, f"{e.reason}: eval.agents names the MLLM agent {mllm[0]!r}, which "
                                                 "needs a model server (llm.endpoints, llm.model)") from None

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """``TOML table -> key -> value`` (lists for tuples): ``run.json``'s ``config``."""
        def plain(items):
            return {k: list(v) if isinstance(v, tuple) else v for k, v in items.items()}

        out = {name: plain(dataclasses.asdict(section)) for name, section in self.sections().items() if name != "agents"}
        out["agents"] = {name: plain(values) for name, values in self.agents.params.items()}
        return out

    def sections(self) -> dict[str, Any]:
        """``TOML table name -> section object``, in file order."""
        return {_TOML_NAME[f.name]: getattr(self, f.name) for f in dataclasses.fields(self)}

    @classmethod
    def from_dict(cls, data: dict[str, dict[str, Any]]) -> "SweepConfig":
        """Build from ``TOML table -> key -> value`` (missing keys take their defaults)."""
        for name, items in data.items():
            _check_names(name, items, "dict")
        return cls(**{_ATTR_NAME[name]: (AgentsConfig(data.get(name, {})) if name == "agents"
                                         else SECTIONS[name](**data.get(name, {}))) for name in SECTIONS})


SECTIONS: dict[str, type] = {
    "run": RunConfig, "benchmark": BenchmarkConfig, "eval": EvalConfig, "costs": CostsConfig,
    "difficulty": DifficultyConfig, "derive-costs": DeriveCostsConfig, "analysis": AnalysisConfig, "sim": SimConfig,
    "llm": LLMConfig, "views": ViewConfig, "agents": AgentsConfig,
}
"""TOML table name -> section class, in file order."""
_ATTR_NAME = {name: name.replace("-", "_") for name in SECTIONS}
_TOML_NAME = {attr: name for name, attr in _ATTR_NAME.items()}

QUICK: dict[str, dict[str, Any]] = {
    "benchmark": {"limit": 60},
    "eval": {"batch": 64},
    "costs": {"samples": 20_000, "scales": [0.25, 1.0, 4.0]},
    "difficulty": {"alpha_step": 0.1, "threshold_step": 0.1},
    "analysis": {"trajectories": 2},
}
"""The sizes ``--quick`` replaces (CI and smoke runs). The image size is not one of them: a quick run's
MLLM agents see the views a full run's see (``views.size``, :data:`ignjax.sim.views.config.DEFAULT_SIZE`)."""


@functools.cache
def _defaults(section: str) -> dict[str, Any]:
    """``key -> default value`` of a section (the types its values are checked against);
    for ``agents.<name>``, that agent's parameters."""
    if section.startswith("agents."):
        return AgentsConfig().params[section.split(".", 1)[1]]
    d = SECTIONS[section]()
    return {f.name: getattr(d, f.name) for f in dataclasses.fields(d)}


def _check_names(section: str, items: Any, where: str, text: str | None = None) -> None:
    if section not in SECTIONS:
        line = _line_of(text, section) if text else None
        raise ConfigError(f"{where}:{line}" if line else where, section, f"unknown section; known: {', '.join(SECTIONS)}")
    if not isinstance(items, dict):
        raise ConfigError(where, section, "must be a table of settings")
    if section == "agents":
        for name, values in items.items():
            if name not in registry():
                line = _line_of(text, f"agents.{name}") if text else None
                raise ConfigError(f"{where}:{line}" if line else where, f"agents.{name}",
                                  f"unknown agent; known: {', '.join(registry())}")
            _check_names_agent(name, values, where, text)
        return
    for key in items:
        if key not in _defaults(section):
            line = _line_of(text, section, key) if text else None
            raise ConfigError(f"{where}:{line}" if line else where, f"{section}.{key}",
                              f"unknown key; known: {', '.join(_defaults(section))}")


# ---------------------------------------------------------------------------
# TOML files, --set items, resolution
# ---------------------------------------------------------------------------


def _check_names_agent(name: str, items: Any, where: str, text: str | None) -> None:
    if not isinstance(items, dict):
        raise ConfigError(where, f"agents.{name}", "must be a table of parameter = value")
    for key in items:
        if key not in _defaults(f"agents.{name}"):
            line = _line_of(text, f"agents.{name}", key) if text else None
            check_param_value(registry()[name], key, None, f"{where}:{line}" if line else where)


def parse_set(item: str) -> dict:
    """``section.key=value`` or ``agents.<name>.key=value`` (value in TOML
    syntax; a bare word is a string)."""
    name, value = parse_assignment(item, "--set")
    section, key = name.rsplit(".", 1)
    if section.startswith("agents."):
        agent = section.split(".", 1)[1]
        _check_names("agents", {agent: {key: value}}, "--set")
        return {"agents": {agent: {key: value}}}
    if section not in SECTIONS:
        raise ConfigError(None, "--set", f"unknown section {section!r}; known: {', '.join(SECTIONS)}")
    if key not in _defaults(section):
        raise ConfigError(None, "--set", f"unknown key {section}.{key}; known: {', '.join(_defaults(section))}")
    return {section: {key: value}}


def resolve(config_file: str | os.PathLike | None = None, sets: list[str] = (), quick: bool = False) -> SweepConfig:
    """Defaults <- quick sizes <- TOML file <- ``--set`` items (later wins).

    Names and types are checked as each layer is applied, the values' meaning
    once all are (a later layer may repair an earlier one's value); every
    error names where the offending key was set (``file:line``, ``--set`` or
    ``quick``) and the key.
    """
    values: dict[str, dict[str, Any]] = {name: {} for name in SECTIONS}
    origin: dict[str, str] = {}

    def apply(overrides: dict, where: str, text: str | None = None) -> None:
        for section, items in overrides.items():
            _check_names(section, items, where, text)
            if section == "agents":
                for agent, params in items.items():
                    for key, value in params.items():
                        line = _line_of(text, f"agents.{agent}", key) if text else None
                        loc = f"{where}:{line}" if line else where
                        values["agents"].setdefault(agent, {})[key] = check_param_value(registry()[agent], key, value, loc)
                        origin[f"agents.{agent}.{key}"] = loc
                continue
            for key, value in items.items():
                line = _line_of(text, section, key) if text else None
                loc = f"{where}:{line}" if line else where
                values[section][key] = _check_value(f"{section}.{key}", value, _defaults(section)[key], loc)
                origin[f"{section}.{key}"] = loc

    if quick:
        apply(QUICK, "quick")
    if config_file:
        data, text = load_toml(config_file)
        apply(data, str(config_file), text)
    for item in sets:
        apply(parse_set(item), "--set")
    try:
        return SweepConfig.from_dict(values)
    except ConfigError as e:
        loc = origin.get(e.where.split("[", 1)[0])
        if loc and not e.path:
            raise ConfigError(loc, e.where, e.reason) from None
        raise


def digest(obj: Any) -> str:
    """16 hex digits of the SHA-256 of ``obj``'s canonical JSON."""
    return hashlib.sha256(json.dumps(obj, sort_keys=True).encode()).hexdigest()[:16]


FINGERPRINT_IGNORES = {"llm": ("endpoints", "concurrency", "timeout_s", "cache_dir", "replay"), "views": ("workers",)}
"""Settings that change how a run is served or computed, not its outputs: a run resumed with another model
server address, concurrency or render process count is the same run."""


def rolled_out(cfg: SweepConfig, studies) -> list[str]:
    """The agents ``studies`` roll out: ``eval.agents`` (the eval, difficulty and analysis studies),
    ``analysis.agent`` and, for the cost study, ``costs.agent``."""
    if not any(s in studies for s in ("eval", "costs", "difficulty", "analysis")):
        return []
    extra = ([cfg.analysis.agent] if "analysis" in studies else []) + ([cfg.costs.agent] if "costs" in studies else [])
    return list(dict.fromkeys(list(cfg.eval.agents) + extra))


def loaded_agents(cfg: SweepConfig, studies) -> dict[str, dict]:
    """``name -> what was loaded`` for the agents ``studies`` roll out whose parameters are files (the learned
    agent: its checkpoint's path and weights' SHA-256), each read and checked under ``cfg.sim``.

    Raises:
        InputError: a checkpoint that is missing or does not fit this package and simulator configuration.
    """
    names = [n for n in rolled_out(cfg, studies) if n in registry() and registry()[n].source is not None]
    return cfg.agents.used(names, cfg.sim)


def fingerprint(cfg: SweepConfig, studies: list[str]) -> str:
    """Hash of what determines a run's outputs (configuration + studies; not :data:`FINGERPRINT_IGNORES`;
    with the digests of the weights the rolled-out agents load, :func:`loaded_agents`, so a policy retrained
    into the same folder is another run)."""
    d = cfg.to_dict()
    for section, keys in FINGERPRINT_IGNORES.items():
        d[section] = {k: v for k, v in d[section].items() if k not in keys}
    loaded = {n: r["weights_sha256"] for n, r in loaded_agents(cfg, studies).items()}
    return digest({"config": d, "studies": list(studies), **({"weights": loaded} if loaded else {})})


# ---------------------------------------------------------------------------
# the configuration as TOML (sweeps/default.toml)
# ---------------------------------------------------------------------------


def to_toml(cfg: SweepConfig, header: str = "") -> str:
    """``cfg`` as a TOML file: every table and key, each key under its description."""
    out = [f"# {line}".rstrip() for line in header.splitlines()]

    def wrap(text):
        return textwrap.wrap(text.replace("``", "`"), 110, initial_indent="# ", subsequent_indent="# ")

    for name, section in cfg.sections().items():
        if name == "agents":
            for agent, values in section.params.items():
                docs = param_docs(registry()[agent])
                out += ["", f"[agents.{agent}]"]
                out += wrap(f"Parameters of the `{agent}` agent (a cost-aware agent's costs are eval.costs).")
                for key, value in values.items():
                    out += wrap(docs.get(key, ""))
                    out.append(f"{key} = {_toml_value(value)}")
            continue
        sections_toml({name: section}, out)
    return "\n".join(out) + "\n"


DEFAULT_TOML_HEADER = """\
The default study of `python -m ignjax.sweep`: every key with its default value and what it means.
Any key may be left out; `--set section.key=value` overrides one on the command line.
Generated by ignjax.config.default_toml() (tests/sweep/test_sweep.py checks that this file matches it)."""


def default_toml() -> str:
    """The text of ``sweeps/default.toml``: :func:`to_toml` of the defaults."""
    return to_toml(SweepConfig(), DEFAULT_TOML_HEADER)


__all__ = [
    "AnalysisConfig", "BenchmarkConfig", "CostsConfig", "DeriveCostsConfig", "DifficultyConfig", "EvalConfig", "QUICK",
    "RunConfig", "SECTIONS", "SweepConfig", "default_toml", "digest", "field_docs", "fingerprint", "load_toml",
    "loaded_agents", "parse_set", "resolve", "rolled_out", "to_toml",
]
