"""The trainer's host loop: environment and network from the configuration, the state from the seed or the
newest checkpoint, the compiled calls with a progress bar, the curve and the checkpoints.

Only numbers come back to the host between calls (each call's per-update metrics, moved with
``np.asarray``); the state stays on the devices except when a checkpoint is written.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ignjax.episodes.dataset import load_benchmark
from ignjax.rl import checkpoint as C
from ignjax.rl import curve as cli
from ignjax.rl.env import make
from ignjax.rl.policy import Policy
from ignjax.rl.ppo import Trainer, train_calls
from ignjax.rl.trainconfig import TrainConfig


def make_policy(cfg: TrainConfig, n_actions: int) -> Policy:
    return Policy(n_actions, cfg.policy.hidden, cfg.policy.layers, cfg.policy.core)


def policy_record(cfg: TrainConfig) -> dict:
    """The network's settings as the checkpoint's record holds them."""
    return {"core": cfg.policy.core, "hidden": cfg.policy.hidden, "layers": cfg.policy.layers}


def make_trainer(cfg: TrainConfig, episodes: Path) -> Trainer:
    e = cfg.env
    env, envp = make(load_benchmark(episodes), cfg.sim, costs=e.costs, sample_costs=e.sample_costs,
                     cost_scale=e.cost_scale, per_type_prob=e.per_type_prob, tau=e.tau, shaping=e.shaping,
                     gamma=cfg.ppo.gamma)
    return Trainer(env, envp, make_policy(cfg, env.num_actions), cfg.ppo)


def start_state(cfg: TrainConfig, trainer: Trainer, out: Path, resume: bool):
    """(shared, rows, update) from the seed, or from the newest checkpoint when resuming (checked first)."""
    last = C.latest(out) if resume else None
    if last is None:
        shared, rows = trainer.init(cfg.run.seed)
        return shared, rows, 0
    found = C.read_record(last)
    C.check_record(found, C.record(cfg.sim, policy_record(cfg), cfg.fingerprint(), found.get("update", 0)), last)
    shared, rows = trainer.place(*C.load(last, trainer.shapes()))
    return shared, rows, int(found["update"])


def train(cfg: TrainConfig, out: Path, episodes: Path, resume: bool, progress: bool) -> Path:
    """Run the updates left; write the curve after every call and a checkpoint every ``checkpoint_every``."""
    ppo = cfg.ppo
    trainer = make_trainer(cfg, episodes)
    shared, rows, start = start_state(cfg, trainer, out, resume)
    curve = cli.read_curve(out / "curve.csv", start)
    wall0 = float(curve[-1]["wall_s"]) if curve else 0.0
    per_update = ppo.num_envs * ppo.steps
    bar = _bar(ppo.updates * per_update, start * per_update, progress)
    t0, update, saved = time.perf_counter(), start, start
    for shared, rows, m in train_calls(trainer, shared, rows, ppo.updates, ppo.updates_per_call):
        wall = wall0 + time.perf_counter() - t0
        for i in range(len(m["return"])):
            update += 1
            curve.append({"update": update, "steps": update * per_update, "wall_s": f"{wall:.1f}",
                          **{k: _fmt(m[k][i]) for k in cli.COLUMNS[3:]}})
        cli.write_curve(out, curve)
        bar.update(len(m["return"]) * per_update)
        bar.set_postfix(ret=f"{np.nanmean(m['return']):.3f}", succ=f"{np.nanmean(m['success']):.3f}",
                        asks=f"{np.nanmean(m['questions']):.2f}")
        if update - saved >= ppo.checkpoint_every or update == ppo.updates:
            C.save(out, (shared, rows), C.record(cfg.sim, policy_record(cfg), cfg.fingerprint(), update))
            saved = update
    bar.close()
    return out


def _fmt(x) -> str:
    x = float(x)
    return "nan" if x != x else f"{x:.6g}"


def _bar(total: int, initial: int, enabled: bool):
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, unit="step", unit_scale=True, disable=not enabled, smoothing=0.3,
                desc="ppo")


__all__ = ["make_policy", "make_trainer", "policy_record", "start_state", "train"]
