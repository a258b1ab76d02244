"""PPO on the RL environment, the whole loop in one jitted program.

:func:`train_calls` runs ``updates_per_call`` PPO updates per call of one
compiled program: a ``lax.scan`` over updates, each a ``lax.scan`` of
``steps`` environment steps (the policy's step, the masked categorical draw,
:meth:`ignjax.rl.env.Env.step_batch` with auto-reset), GAE, then ``epochs`` x
``minibatches`` Adam steps on the clipped PPO loss over whole environments'
sequences (the GRU re-run from each sequence's stored first state). The
program is a ``shard_map`` over this process's devices (one CPU device per
core): each device steps its share of the environments and holds a copy of
the weights; the gradients, the advantage statistics and the metrics are
averaged across the devices inside the program (``lax.pmean`` / ``psum``),
so the copies stay equal and nothing eager touches sharded arrays.

**Randomness**: every draw comes from the run's seed: the weights and the
per-row key of each environment at :func:`init_state`; a step's action and
environment keys fold the global step index into the row's key; the
minibatch permutations fold the update, the epoch and the device index into
the shared key. So a run is a function of its configuration, and a run
resumed from a checkpoint (taken between calls) continues with the same
bytes as one that never stopped.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import partial

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import NamedSharding
from jax.sharding import PartitionSpec as P

from ignjax.arrays import pytree_dataclass
from ignjax.errors import ConfigError
from ignjax.errors.extras import optional_module
from ignjax.rl.env import Env, EnvState
from ignjax.rl.params import EnvParams
from ignjax.rl.policy import Policy, init_params, sequence
from ignjax.rl.trainconfig import PPOConfig
from ignjax.rl.vector import env_parts
from ignjax.sim.rollout import AXIS, ROLLOUT_COMPILER_OPTIONS, device_mesh, replicate_world

optax = optional_module("optax", "rl")

STREAMS = (0x7077, 0x7276, 0x6B73)
"""Folded into the seed's key for the weights, the first resets and the rows' keys."""
METRICS = ("episodes", "return", "success", "questions", "length", "reward", "loss_policy", "loss_value",
           "entropy", "approx_kl", "lr")
"""The per-update metrics :func:`train_calls` returns (means over the update's ended episodes for
``return``, ``success``, ``questions`` and ``length``; NaN when none ended)."""


@pytree_dataclass
class Shared:
    """What every device holds a copy of: the weights, Adam's state, the update counter and the shared key (uint32 data)."""

    params: dict
    opt_state: tuple
    update: jax.Array
    key: jax.Array


@pytree_dataclass
class Rows:
    """Per environment (leading axis B, split over the devices): its state, current observation and mask,
    whether its next step begins an episode, the policy's memory and the row's key (uint32 data)."""

    env: EnvState
    obs: jax.Array
    mask: jax.Array
    first: jax.Array
    carry: jax.Array
    key: jax.Array


@pytree_dataclass
class Transition:
    obs: jax.Array
    mask: jax.Array
    first: jax.Array
    action: jax.Array
    logp: jax.Array
    value: jax.Array
    reward: jax.Array
    done: jax.Array
    wsr: jax.Array
    success: jax.Array
    questions: jax.Array
    length: jax.Array


def make_optimizer(ppo: PPOConfig):
    """Adam after a global-norm clip, its learning rate annealed linearly to 0 over the run when ``anneal_lr``."""
    n = ppo.updates * ppo.epochs * ppo.minibatches
    lr = optax.linear_schedule(ppo.lr, 0.0, n) if ppo.anneal_lr else ppo.lr
    return optax.chain(optax.clip_by_global_norm(ppo.max_grad_norm), optax.adam(lr, eps=1e-5))


def learning_rate(ppo: PPOConfig, update) -> jax.Array:
    """The learning rate at the start of update ``update``."""
    n = ppo.updates * ppo.epochs * ppo.minibatches
    frac = 1.0 - update * ppo.epochs * ppo.minibatches / n
    return ppo.lr * (jnp.clip(frac, 0.0, 1.0) if ppo.anneal_lr else 1.0)


@dataclass(frozen=True)
class Program:
    """The static part of a training call (a jit's static argument): the environment, the network, the
    learner's settings, the updates per call and the simulator's chunk."""

    env: Env
    policy: Policy
    ppo: PPOConfig
    n: int
    chunk: int | None = None

    def __call__(self, envp: EnvParams, shared: Shared, rows: Rows):
        def one(carry, _):
            shared, rows = carry
            rows, traj, h0, last = self.rollout(envp, shared, rows)
            shared, losses = self.learn(shared, traj, h0, last)
            return (shared, rows), {**self.episode_metrics(traj), **losses}

        (shared, rows), metrics = jax.lax.scan(one, (shared, rows), None, length=self.n)
        return shared, rows, metrics

    # ------------------------------------------------------------------ acting

    def rollout(self, envp: EnvParams, shared: Shared, rows: Rows):
        """``steps`` environment steps of every local row: (rows after, transitions (T, B_d), first memory, last value)."""
        T = self.ppo.steps
        h0 = rows.carry

        def step(rows: Rows, t):
            tg = shared.update.astype(jnp.uint32) * jnp.uint32(T) + t
            k = jax.vmap(lambda kd: jax.random.split(jax.random.fold_in(jax.random.wrap_key_data(kd), tg)))(rows.key)
            carry, logits, value = self.policy.apply(shared.params, rows.carry, rows.obs, rows.first, rows.mask)
            action = jax.vmap(jax.random.categorical)(k[:, 0], logits).astype(jnp.int32)
            logp = jnp.take_along_axis(jax.nn.log_softmax(logits), action[:, None], -1)[:, 0]
            obs, env, reward, done, info = self.env.step_batch(k[:, 1], rows.env, action, envp, self.chunk)
            out = info["outcome"]
            tr = Transition(obs=rows.obs, mask=rows.mask, first=rows.first, action=action, logp=logp, value=value,
                            reward=reward, done=done, wsr=info["wsr"], success=info["success"],
                            questions=jnp.sum(out.n_questions, -1).astype(jnp.float32),
                            length=out.steps.astype(jnp.float32))
            nxt = Rows(env=env, obs=obs, mask=info["action_mask"], first=done, carry=carry, key=rows.key)
            return nxt, tr

        rows, traj = jax.lax.scan(step, rows, jnp.arange(T, dtype=jnp.uint32))
        _, _, last = self.policy.apply(shared.params, rows.carry, rows.obs, rows.first, rows.mask)
        return rows, traj, h0, last

    # ------------------------------------------------------------------ learning

    def advantages(self, traj: Transition, last: jax.Array):
        """GAE(gamma, lambda): (advantages, returns), each (T, B_d); an ended episode's next value is 0."""
        g, lam = self.ppo.gamma, self.ppo.gae_lambda

        def body(nxt, x):
            adv_next, v_next = nxt
            reward, value, done = x
            live = 1.0 - done.astype(jnp.float32)
            adv = reward + g * v_next * live - value + g * lam * live * adv_next
            return (adv, value), adv

        _, adv = jax.lax.scan(body, (jnp.zeros_like(last), last), (traj.reward, traj.value, traj.done), reverse=True)
        return adv, adv + traj.value

    def loss(self, params, mb: dict):
        """The PPO loss of one minibatch of sequences: (total, (policy, value, entropy, approx_kl))."""
        logits, values = sequence(self.policy, params, mb["h0"], mb["obs"], mb["first"], mb["mask"])
        logp_all = jax.nn.log_softmax(logits)
        logp = jnp.take_along_axis(logp_all, mb["action"][..., None], -1)[..., 0]
        ratio = jnp.exp(logp - mb["logp"])
        adv = mb["adv"]
        clipped = jnp.clip(ratio, 1.0 - self.ppo.clip, 1.0 + self.ppo.clip)
        pg = -jnp.mean(jnp.minimum(ratio * adv, clipped * adv))
        v_loss = 0.5 * jnp.mean((values - mb["ret"]) ** 2)
        entropy = -jnp.mean(jnp.sum(jnp.where(mb["mask"], jnp.exp(logp_all) * logp_all, 0.0), -1))
        kl = jnp.mean((ratio - 1.0) - (logp - mb["logp"]))
        total = pg + self.ppo.vf_coef * v_loss - self.ppo.ent_coef * entropy
        return total, (pg, v_loss, entropy, kl)

    def learn(self, shared: Shared, traj: Transition, h0, last):
        """``epochs`` x ``minibatches`` Adam steps on the rollout; the gradients averaged over the devices."""
        adv, ret = self.advantages(traj, last)
        mean = jax.lax.pmean(jnp.mean(adv), AXIS)
        std = jnp.sqrt(jax.lax.pmean(jnp.mean((adv - mean) ** 2), AXIS))
        data = {"obs": traj.obs, "mask": traj.mask, "first": traj.first, "action": traj.action, "logp": traj.logp,
                "adv": (adv - mean) / (std + 1e-8), "ret": ret}
        tx = make_optimizer(self.ppo)
        M = self.ppo.minibatches
        B = h0.shape[0]
        key = jax.random.fold_in(jax.random.fold_in(jax.random.wrap_key_data(shared.key), shared.update),
                                 jax.lax.axis_index(AXIS))

        def minibatch(carry, mb):
            params, opt_state = carry
            grads, aux = jax.grad(self.loss, has_aux=True)(params, mb)
            grads = jax.lax.pmean(grads, AXIS)
            updates, opt_state = tx.update(grads, opt_state, params)
            return (optax.apply_updates(params, updates), opt_state), aux

        def epoch(carry, e):
            perm = jax.random.permutation(jax.random.fold_in(key, e), B)
            split = lambda a, ax: jnp.moveaxis(jnp.take(a, perm, axis=ax).reshape(  # noqa: E731
                a.shape[:ax] + (M, B // M) + a.shape[ax + 1:]), ax, 0)
            mbs = {k: split(v, 1) for k, v in data.items()} | {"h0": split(h0, 0)}
            return jax.lax.scan(minibatch, carry, mbs)

        (params, opt_state), aux = jax.lax.scan(epoch, (shared.params, shared.opt_state), jnp.arange(self.ppo.epochs))
        losses = {name: jax.lax.pmean(jnp.mean(a), AXIS) for name, a in
                  zip(("loss_policy", "loss_value", "entropy", "approx_kl"), aux)}
        losses["lr"] = learning_rate(self.ppo, shared.update)
        return Shared(params=params, opt_state=opt_state, update=shared.update + 1, key=shared.key), losses

    @staticmethod
    def episode_metrics(traj: Transition) -> dict:
        """Sums over the devices of the update's ended episodes, as means per episode."""
        done = traj.done.astype(jnp.float32)
        n = jax.lax.psum(jnp.sum(done), AXIS)
        mean = lambda x: jax.lax.psum(jnp.sum(x * done), AXIS) / n  # noqa: E731
        total = jax.lax.psum(jnp.sum(traj.reward), AXIS)
        B = jax.lax.psum(traj.reward.shape[1], AXIS)
        return {"episodes": n, "return": mean(traj.wsr), "success": mean(traj.success.astype(jnp.float32)),
                "questions": mean(traj.questions), "length": mean(traj.length), "reward": total / B}


@partial(jax.jit, static_argnames=("program", "mesh"), compiler_options=ROLLOUT_COMPILER_OPTIONS)
def _call(envp, shared, rows, *, program, mesh):
    return jax.shard_map(program, mesh=mesh, in_specs=(P(), P(), P(AXIS)), out_specs=(P(), P(AXIS), P()),
                         check_vma=False)(envp, shared, rows)


@dataclass(frozen=True)
class _Init:
    env: Env
    policy: Policy
    chunk: int | None

    def __call__(self, envp, rows):
        reset_keys, row_keys = rows
        obs, state = self.env.reset_batch(jax.random.wrap_key_data(reset_keys), envp, self.chunk)
        B = obs.shape[0]
        return Rows(env=state, obs=obs, mask=jax.vmap(self.env.action_mask)(state), first=jnp.ones(B, bool),
                    carry=self.policy.initial_carry(B), key=row_keys)


@partial(jax.jit, static_argnames=("fn", "mesh"), compiler_options=ROLLOUT_COMPILER_OPTIONS)
def _init_rows(envp, rows, *, fn, mesh):
    return jax.shard_map(fn, mesh=mesh, in_specs=(P(), P(AXIS)), out_specs=P(AXIS), check_vma=False)(envp, rows)


class Trainer:
    """The compiled training program over a mesh of this process's devices.

    Args:
        env: the environment; ``envp`` its parameters (the world is copied once to each device).
        policy: the network.
        ppo: the learner's settings.
        parts: devices (None: as many as divide ``ppo.num_envs``).

    Raises:
        ConfigError: ``ppo.minibatches`` does not divide the environments of one device.
    """

    def __init__(self, env: Env, envp: EnvParams, policy: Policy, ppo: PPOConfig, parts: int | None = None,
                 chunk: int | None = None):
        env.check(envp)
        self.env, self.policy, self.ppo, self.chunk = env, policy, ppo, chunk
        self.parts = env_parts(ppo.num_envs, parts)
        per_device = ppo.num_envs // self.parts
        if per_device % ppo.minibatches:
            raise ConfigError(None, "ppo.minibatches", f"must divide the {per_device} environments of each of the "
                                                       f"{self.parts} devices, got {ppo.minibatches}")
        self.mesh = device_mesh(self.parts)
        self.envp = dataclasses.replace(envp, world=replicate_world(envp.world, self.mesh))

    def shapes(self) -> tuple[Shared, Rows]:
        """The shapes and dtypes of :meth:`init`'s state (nothing computed): a checkpoint's layout."""
        def state():
            key = jax.random.key(0)
            params = init_params(self.policy, key, self.env.observation_space().shape[0])
            shared = Shared(params=params, opt_state=make_optimizer(self.ppo).init(params), update=jnp.int32(0),
                            key=jax.random.key_data(key))
            keys = jax.random.key_data(jax.random.split(key, self.ppo.num_envs))
            return shared, _Init(self.env, self.policy, self.chunk)(self.envp, (keys, keys))

        return jax.eval_shape(state)

    def init(self, seed: int) -> tuple[Shared, Rows]:
        """The state before the first update: weights, Adam's state and B fresh episodes, all drawn from ``seed``."""
        key = jax.random.key(seed)
        k_params, k_reset, k_rows = (jax.random.fold_in(key, s) for s in STREAMS)
        params = init_params(self.policy, k_params, self.env.observation_space().shape[0])
        shared = Shared(params=params, opt_state=make_optimizer(self.ppo).init(params), update=jnp.int32(0),
                        key=jax.random.key_data(key))
        B = self.ppo.num_envs
        data = lambda k: jax.random.key_data(jax.random.split(k, B))  # noqa: E731
        rows = _init_rows(self.envp, (data(k_reset), data(k_rows)), fn=_Init(self.env, self.policy, self.chunk),
                          mesh=self.mesh)
        return self.place(shared, rows)

    def place(self, shared: Shared, rows: Rows) -> tuple[Shared, Rows]:
        """``shared`` copied to every device and ``rows`` split over them, as the compiled program returns
        them (so the first call and a resumed one compile the same program as every later call)."""
        rep, split = NamedSharding(self.mesh, P()), NamedSharding(self.mesh, P(AXIS))
        return jax.device_put(shared, rep), jax.device_put(rows, split)

    def call(self, shared: Shared, rows: Rows, n: int):
        """``n`` updates: (shared, rows, metrics: name -> (n,) numpy array on the host)."""
        program = Program(self.env, self.policy, self.ppo, int(n), self.chunk)
        shared, rows, metrics = _call(self.envp, shared, rows, program=program, mesh=self.mesh)
        return shared, rows, {k: np.asarray(jax.device_get(v)) for k, v in metrics.items()}


def train_calls(trainer: Trainer, shared: Shared, rows: Rows, updates: int, per_call: int):
    """Yield (shared, rows, metrics) after each call until ``updates`` (absolute) updates are done; a call runs
    ``per_call`` updates, the last one fewer when they do not divide the rest."""
    done = int(jax.device_get(shared.update))
    while done < updates:
        n = min(per_call, updates - done)
        shared, rows, metrics = trainer.call(shared, rows, n)
        done += n
        yield shared, rows, metrics


__all__ = ["METRICS", "Program", "Rows", "STREAMS", "Shared", "Trainer", "Transition", "learning_rate",
           "make_optimizer", "train_calls"]
