"""Configuration of ``python -m ignjax.rl.train``: one frozen dataclass per TOML table.

:class:`TrainConfig` has the tables ``run``, ``houses`` (the training
episodes), ``env`` (the environment's parameters), ``ppo`` (the learner),
``policy`` (the network) and ``sim`` (the simulator's
:class:`~ignjax.sim.types.SimConfig`). Each section checks its values in
``__post_init__``; :func:`resolve` layers defaults <- ``--config`` file <-
``--set table.key=value`` items with :func:`ignjax.settings.resolve_sections`,
so every error names ``file:line`` or ``--set`` and the key.

**Training houses.** By default the trainer builds its own benchmark from
procedural houses of seed :data:`TRAIN_HOUSE_SEED` (1000), disjoint from the
shipped benchmark's seed (:data:`ignjax.data.shipped.SCENE_SEED`, 0) and from
every house the evaluation judges a policy on; ``houses.seed`` equal to the
shipped seed is refused.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from typing import Any, ClassVar

from ignjax.data import shipped
from ignjax.errors import ConfigError
from ignjax.protocol import LOCKED_COSTS
from ignjax.settings import check_fields, resolve_sections, sections_toml
from ignjax.sim.types import SimConfig

TRAIN_HOUSE_SEED = 1000
"""Default seed of the training houses (``generate_houses(count, 1000)``); the shipped benchmark's is 0."""
CORES = ("gru", "mlp")
"""The policy's cores: a GRU over the episode (memory) or none (each step's observation alone)."""


def _positive(section: str, obj, *names: str) -> None:
    for n in names:
        if not getattr(obj, n) > 0:
            raise ConfigError(None, f"{section}.{n}", f"must be > 0, got {getattr(obj, n)}")


@dataclass(frozen=True)
class RunConfig:
    """Where a training run goes and its seed.

    Attributes:
        name: folder of the run under ``out``.
        out: folder holding the run folders.
        seed: the seed of every random choice of the run (initial weights, episodes, actions, minibatches).
    """

    SECTION: ClassVar[str] = "run"
    name: str = "ppo"
    out: str = "runs/rl"
    seed: int = 0

    def __post_init__(self):
        check_fields(self, self.SECTION)
        if not self.name or "/" in self.name:
            raise ConfigError(None, "run.name", f"must be a folder name, got {self.name!r}")


@dataclass(frozen=True)
class HousesConfig:
    """The training episodes.

    Attributes:
        episodes: an episode file to train on; empty: a benchmark built from ``count`` procedural houses of
            ``seed`` into the run folder's ``houses/`` (reused by ``--resume``).
        count: procedural houses built when ``episodes`` is empty.
        seed: seed of the procedural houses and of their episodes; must differ from the shipped benchmark's (0).
        subset: episodes kept per built benchmark (easy:medium:hard 30:40:30); 0: every episode built.
    """

    SECTION: ClassVar[str] = "houses"
    episodes: str = ""
    count: int = 8
    seed: int = TRAIN_HOUSE_SEED
    subset: int = 0

    def __post_init__(self):
        check_fields(self, self.SECTION)
        _positive(self.SECTION, self, "count")
        if self.seed < 0:
            raise ConfigError(None, "houses.seed", f"must be >= 0, got {self.seed}")
        if not self.episodes and self.seed == shipped.SCENE_SEED:
            raise ConfigError(None, "houses.seed", f"{self.seed} is the shipped benchmark's house seed: training "
                                                   "houses must differ from the houses a policy is judged on")
        if self.subset < 0:
            raise ConfigError(None, "houses.subset", f"must be >= 0, got {self.subset}")


@dataclass(frozen=True)
class EnvConfig:
    """The environment's parameters (:func:`ignjax.rl.params.make_params`).

    Attributes:
        costs: the per-type question costs at scale 1 (the locked costs by default).
        sample_costs: draw each episode's costs (costs x a log-uniform scale); false: charge ``costs``.
        cost_scale: (low, high) of the drawn scale. The trainer's recipe draws from x0.02 (costs below a
            quarter of the locked ones in about 4 episodes in 10) so the policy learns what answers are worth
            before their price: drawn from x0.25, the same 20 M-step run stopped asking within 2 M steps and
            never asked again (docs/agents.md, "Training").
        per_type_prob: probability that an episode's types draw their scales apart.
        tau: success threshold of the reward, m.
        shaping: weight of the potential-based distance shaping, per metre of geodesic progress (0: off; the
            environment's own default is off, the trainer's recipe, which trained the shipped policy, uses 0.1).
            The curve's return is the WSR alone.
    """

    SECTION: ClassVar[str] = "env"
    costs: tuple[float, ...] = tuple(LOCKED_COSTS)
    sample_costs: bool = True
    cost_scale: tuple[float, ...] = (0.02, 8.0)
    per_type_prob: float = 0.25
    tau: float = 1.5
    shaping: float = 0.1

    def __post_init__(self):
        check_fields(self, self.SECTION)
        if len(self.costs) != 4 or any(c < 0 for c in self.costs):
            raise ConfigError(None, "env.costs", f"expected 4 non-negative costs, got {list(self.costs)}")
        lo_hi = self.cost_scale
        if len(lo_hi) != 2 or not 0 < lo_hi[0] <= lo_hi[1]:
            raise ConfigError(None, "env.cost_scale", f"expected [low, high] with 0 < low <= high, got {list(lo_hi)}")
        if not 0 <= self.per_type_prob <= 1:
            raise ConfigError(None, "env.per_type_prob", f"must lie in [0, 1], got {self.per_type_prob}")
        _positive(self.SECTION, self, "tau")
        if self.shaping < 0:
            raise ConfigError(None, "env.shaping", f"must be >= 0, got {self.shaping}")


@dataclass(frozen=True)
class PPOConfig:
    """The learner: PPO with clipped ratios and GAE, the whole loop one jitted program per ``updates_per_call``.

    Attributes:
        total_steps: environment steps of the run (rounded up to whole updates of num_envs x steps).
        num_envs: environments stepped together (split over the devices).
        steps: environment steps per environment per update (the rollout's length).
        epochs: passes over each rollout.
        minibatches: minibatches per epoch (whole environments' sequences; must divide num_envs per device).
        lr: Adam's learning rate.
        anneal_lr: decay the learning rate linearly to 0 over the run.
        gamma: discount.
        gae_lambda: GAE's lambda.
        clip: PPO's ratio clip.
        ent_coef: weight of the entropy bonus.
        vf_coef: weight of the value loss.
        max_grad_norm: global gradient-norm clip.
        updates_per_call: updates per call of the compiled program (the progress bar's and curve's grain).
        checkpoint_every: updates between checkpoints (rounded up to whole calls); the last update is always saved.
    """

    SECTION: ClassVar[str] = "ppo"
    total_steps: int = 20_000_000
    num_envs: int = 1024
    steps: int = 32
    epochs: int = 4
    minibatches: int = 4
    lr: float = 1e-3
    anneal_lr: bool = True
    gamma: float = 0.99
    gae_lambda: float = 0.95
    clip: float = 0.2
    ent_coef: float = 0.01
    vf_coef: float = 0.5
    max_grad_norm: float = 0.5
    updates_per_call: int = 10
    checkpoint_every: int = 100

    def __post_init__(self):
        check_fields(self, self.SECTION)
        _positive(self.SECTION, self, "total_steps", "num_envs", "steps", "epochs", "minibatches", "lr", "clip",
                  "max_grad_norm", "updates_per_call", "checkpoint_every")
        for key in ("gamma", "gae_lambda"):
            if not 0 < getattr(self, key) <= 1:
                raise ConfigError(None, f"ppo.{key}", f"must lie in (0, 1], got {getattr(self, key)}")
        for key in ("ent_coef", "vf_coef"):
            if getattr(self, key) < 0:
                raise ConfigError(None, f"ppo.{key}", f"must be >= 0, got {getattr(self, key)}")
        if self.num_envs % self.minibatches:
            raise ConfigError(None, "ppo.minibatches", f"must divide ppo.num_envs ({self.num_envs}), got "
                                                       f"{self.minibatches}")

    @property
    def updates(self) -> int:
        """Updates of the run."""
        per = self.num_envs * self.steps
        return -(-self.total_steps // per)


@dataclass(frozen=True)
class PolicyConfig:
    """The network (:mod:`ignjax.rl.policy`).

    Attributes:
        core: "gru": a GRU carries memory over the episode (reset at its start); "mlp": no memory.
        hidden: width of the encoder's layers and of the core.
        layers: dense layers of the encoder before the core.
    """

    SECTION: ClassVar[str] = "policy"
    core: str = "gru"
    hidden: int = 64
    layers: int = 2

    def __post_init__(self):
        check_fields(self, self.SECTION)
        if self.core not in CORES:
            raise ConfigError(None, "policy.core", f"must be one of {', '.join(CORES)}, got {self.core!r}")
        _positive(self.SECTION, self, "hidden", "layers")


SECTIONS: dict[str, type] = {"run": RunConfig, "houses": HousesConfig, "env": EnvConfig, "ppo": PPOConfig,
                             "policy": PolicyConfig, "sim": SimConfig}
"""TOML table name -> section class, in file order."""


@dataclass(frozen=True)
class TrainConfig:
    """The whole configuration of a training run (one attribute per table of :data:`SECTIONS`)."""

    run: RunConfig = dataclasses.field(default_factory=RunConfig)
    houses: HousesConfig = dataclasses.field(default_factory=HousesConfig)
    env: EnvConfig = dataclasses.field(default_factory=EnvConfig)
    ppo: PPOConfig = dataclasses.field(default_factory=PPOConfig)
    policy: PolicyConfig = dataclasses.field(default_factory=PolicyConfig)
    sim: SimConfig = dataclasses.field(default_factory=SimConfig)

    @classmethod
    def from_dict(cls, data: dict[str, dict[str, Any]]) -> "TrainConfig":
        return cls(**{name: SECTIONS[name](**data.get(name, {})) for name in SECTIONS})

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """``table -> key -> value`` (lists for tuples): ``run.json``'s ``config``."""
        plain = lambda d: {k: list(v) if isinstance(v, tuple) else v for k, v in d.items()}  # noqa: E731
        return {name: plain(dataclasses.asdict(getattr(self, name))) for name in SECTIONS}

    def fingerprint(self, ignore=("run.name", "run.out", "ppo.checkpoint_every")) -> str:
        """Hash of what decides the run's trajectory (not where it goes or how often it saves)."""
        import hashlib

        d = self.to_dict()
        for item in ignore:
            table, key = item.split(".")
            d[table].pop(key)
        return hashlib.sha256(json.dumps(d, sort_keys=True).encode()).hexdigest()[:16]


def resolve(config_file=None, sets=()) -> TrainConfig:
    """Defaults <- ``config_file`` (TOML) <- ``--set`` items; errors name ``file:line`` or ``--set`` and the key."""
    return resolve_sections(SECTIONS, TrainConfig.from_dict, config_file, sets)


def to_toml(cfg: TrainConfig = TrainConfig()) -> str:
    """``cfg`` as a commented TOML file (every table and key)."""
    head = ["# python -m ignjax.rl.train --config FILE: every key with its value and what it means."]
    return "\n".join(sections_toml({name: getattr(cfg, name) for name in SECTIONS}, head)) + "\n"


__all__ = ["CORES", "EnvConfig", "HousesConfig", "PPOConfig", "PolicyConfig", "RunConfig", "SECTIONS",
           "TRAIN_HOUSE_SEED", "TrainConfig", "resolve", "to_toml"]
