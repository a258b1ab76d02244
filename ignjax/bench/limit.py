"""What the machine allows a decision step: the ``limit`` block of
``python -m ignjax.bench``.

Two halves, measured in the same run:

* **The machine's rates** (:func:`machine_rates`), each measured on every
  device the rollouts shard over (one program per device under
  ``shard_map``, as the rollouts run): random gathers of one int32 from a
  cache-resident table (``CACHED_TABLE_BYTES``) and from a table the size of
  the simulator's world (its arrays' bytes, at least 64 MB), the read
  bandwidth of a large reduction, and the rate of fused elementwise float32
  operations on cache-resident data.
* **The step's work** (:func:`step_work`): the rollout program an agent runs
  at the bench's batch size, counted as it runs. The program's jaxpr is
  evaluated once more with counters threaded through its loops (every
  ``while``, ``scan`` and ``cond`` carries its own counts), compiled and run
  on the same episodes: table look-ups (index tuples of every ``gather``,
  split by whether the table fits in ``CACHED_TABLE_BYTES``), scattered
  rows, elementwise operations (one per output element of an arithmetic,
  logical, comparison or select primitive, 2 per multiply-add of a
  ``dot_general``, one per input element of a reduction), each divided by
  the rollout's decision steps. It is the work the program does, masked
  lanes of a vectorised loop included, not an ideal count.

:func:`limit` puts them together: one decision costs at least its
look-ups at the cached-gather rate (the rates are for all devices at once),
``64 x world-sized look-ups / bandwidth`` of memory traffic (every such
look-up a cache line from memory: an upper estimate of the traffic, so this
term can only overstate) and ``elementwise / elementwise rate`` of
arithmetic; the limit is one over the largest of the three, and ``bound``
names it. The cached rate is the hardware's best: the rollout's rays read
neighbouring cells one after the other, so most look-ups in the world's
tables find their line in cache. ``steps_per_s_uncached`` is the other end
of the range: every world-sized look-up at the random rate of a table that
size. The limit is a bound on this program, not on the task: work removed
from the rollout raises the limit and the figure together.
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import numpy as np
from jax.extend import core as jcore
from jax.sharding import PartitionSpec as P

from ignjax.bench.timing import log, time_interleaved

CACHED_TABLE_BYTES = 1 << 18
"""A table this small (256 KB) stays in a core's L2 cache: its look-ups run
at the cached-gather rate; larger ones at the world-sized table's rate."""
LINE_BYTES = 64
"""Bytes a look-up in a table that does not fit in cache moves from memory."""
LIMIT_BATCH = 4096
"""Episodes of the rollouts whose limit the bench reports."""
GATHERS_PER_CALL = 1 << 22
"""Look-ups per device in one timed gather call."""

ELEMENTWISE = frozenset(
    "add sub mul div rem max min neg abs sign floor ceil round sqrt rsqrt cbrt exp exp2 log log1p expm1 sin cos "
    "tan asin acos atan atan2 sinh cosh tanh logistic pow integer_pow and or not xor eq ne lt le gt ge select_n "
    "clamp shift_left shift_right_logical shift_right_arithmetic square nextafter is_finite population_count "
    "erf erfc erf_inv".split())
REDUCTIONS = frozenset("reduce_sum reduce_max reduce_min reduce_prod reduce_and reduce_or reduce_xor argmax argmin "
                       "cumsum cummax cummin cumprod cumlogsumexp reduce_precision".split())
CALLS = ("pjit", "jit", "closed_call", "core_call", "remat", "checkpoint", "custom_jvp_call", "custom_vjp_call",
         "custom_vjp_call_jaxpr")
COUNTERS = ("gather_cached", "gather_world", "scatter_rows", "elementwise")


# ---------------------------------------------------------------------------
# the step's work: the program's jaxpr, evaluated with counters
# ---------------------------------------------------------------------------


def _static(e, iv) -> np.ndarray:
    """Counts of one primitive that has no sub-program (shape-based)."""
    k = np.zeros(len(COUNTERS))
    p = e.primitive.name
    if p == "gather":
        op, idx = iv[0], iv[1]
        lookups = math.prod(np.shape(idx)[:-1])
        nbytes = math.prod(np.shape(op)) * np.dtype(op.dtype).itemsize
        k[0 if nbytes <= CACHED_TABLE_BYTES else 1] += lookups
    elif p.startswith("scatter"):
        k[2] += math.prod(np.shape(iv[1])[:-1])
    elif p in ELEMENTWISE:
        k[3] += sum(math.prod(v.aval.shape) for v in e.outvars)
    elif p == "dot_general":
        (lc, _), _ = e.params["dimension_numbers"]
        k[3] += 2 * math.prod(e.outvars[0].aval.shape) * math.prod(np.shape(iv[0])[d] for d in lc)
    elif p in REDUCTIONS:
        k[3] += math.prod(np.shape(iv[0]))
    return k


class _Counts:
    """Counts of a piece of program: a static part (numpy) and the traced
    counts of the loops inside it."""

    def __init__(self):
        self.static = np.zeros(len(COUNTERS))
        self.dynamic = []

    def total(self):
        t = jnp.asarray(self.static, jnp.float32)
        for d in self.dynamic:
            t = t + d
        return t


def _eval(jaxpr, consts, args, counts: _Counts):
    env = {}

    def read(v):
        return v.val if isinstance(v, jcore.Literal) else env[v]

    for v, a in zip(jaxpr.constvars, consts):
        env[v] = a
    for v, a in zip(jaxpr.invars, args):
        env[v] = a
    for e in jaxpr.eqns:
        iv = [read(v) for v in e.invars]
        outs = _primitive(e, iv, counts)
        if not e.primitive.multiple_results:
            outs = [outs]
        for v, o in zip(e.outvars, outs):
            env[v] = o
    return [read(v) for v in jaxpr.outvars]


def _eval_closed(cj, args, counts: _Counts):
    return _eval(cj.jaxpr, cj.consts, args, counts)


def _counted(cj, args):
    """(outputs, (len(COUNTERS),) float32 counts) of a closed jaxpr."""
    c = _Counts()
    outs = _eval_closed(cj, list(args), c)
    return outs, c.total()


def _primitive(e, iv, counts: _Counts):
    p, prm = e.primitive.name, e.params
    if p in CALLS:
        j = prm.get("jaxpr") or prm.get("call_jaxpr") or prm.get("fun_jaxpr")
        return _eval_closed(j, iv, counts) if hasattr(j, "consts") else _eval(j, [], iv, counts)
    if p == "while":
        cn, bn = prm["cond_nconsts"], prm["body_nconsts"]
        cc, bc, carry = iv[:cn], iv[cn:cn + bn], iv[cn + bn:]

        def cond(state):
            # a vmapped loop whose test differs between lanes keeps a batched test (its lowering reduces it)
            return jnp.any(_counted(prm["cond_jaxpr"], cc + list(state[0]))[0][0])

        def body(state):
            carry, k = state
            (pred,), kc = _counted(prm["cond_jaxpr"], cc + list(carry))  # the test that let this iteration run
            outs, kb = _counted(prm["body_jaxpr"], bc + list(carry))
            if jnp.ndim(pred):
                # a batched test (vmap): as JAX lowers it, lanes whose test is false keep their carry, one
                # select per element of every carry
                outs = [jnp.where(jnp.reshape(pred, jnp.shape(pred) + (1,) * (jnp.ndim(o) - jnp.ndim(pred))), o, c)
                        for o, c in zip(outs, carry)]
                kb = kb.at[COUNTERS.index("elementwise")].add(float(sum(math.prod(jnp.shape(o)) for o in outs)))
            return tuple(outs), k + kb + kc

        out, k = jax.lax.while_loop(cond, body, (tuple(carry), jnp.zeros(len(COUNTERS), jnp.float32)))
        counts.dynamic.append(k)
        return list(out)
    if p == "scan":
        nc, ncar = prm["num_consts"], prm["num_carry"]
        consts, carry, xs = iv[:nc], iv[nc:nc + ncar], iv[nc + ncar:]

        def body(state, x):
            carry, k = state
            outs, kb = _counted(prm["jaxpr"], consts + list(carry) + list(x))
            return (tuple(outs[:ncar]), k + kb), tuple(outs[ncar:])

        (carry, k), ys = jax.lax.scan(body, (tuple(carry), jnp.zeros(len(COUNTERS), jnp.float32)), tuple(xs),
                                      length=prm["length"], reverse=prm["reverse"])
        counts.dynamic.append(k)
        return list(carry) + list(ys)
    if p == "cond":
        def branch(b):
            def f(*ops):
                outs, k = _counted(b, ops)
                return tuple(outs) + (k,)
            return f

        branches = [branch(b) for b in prm["branches"]]
        out = jax.lax.switch(iv[0], branches, *iv[1:])
        counts.dynamic.append(out[-1])
        return list(out[:-1])
    if p == "shard_map":
        return _eval(prm["jaxpr"], [], iv, counts)
    counts.static += _static(e, iv)
    return e.primitive.bind(*iv, **prm)


def counted_program(fn, *args):
    """A jitted function of ``args`` that runs ``fn`` and returns its
    outputs and its work (:data:`COUNTERS`, float32 totals)."""
    cj = jax.make_jaxpr(fn)(*args)
    tree = jax.tree.structure(jax.eval_shape(fn, *args))

    @jax.jit
    def run(*a):
        outs, k = _counted(cj, jax.tree.leaves(a))
        return jax.tree.unflatten(tree, outs), k

    return run


def step_work(world, specs, agent, params, keys) -> dict:
    """Work per decision step of :func:`ignjax.sim.rollout.rollout`
    (module docstring): look-ups in cached and world-sized tables,
    scattered rows and elementwise operations, each per decision step, of
    the program one device runs (its share of the batch at the widths of
    the whole batch: the first ``rows`` episodes, whose ``decisions`` the
    counts are divided by)."""
    from ignjax.sim import rollout as R

    parts = R.batch_parts()
    n = specs.scene.shape[0]
    share, widths = R.shard_layout(n, parts)  # one device's rows: the program each device runs
    specs, keys = R.pad_batch(specs, keys, share * parts)
    specs, keys = jax.tree.map(lambda a: a[:share], specs), keys[:share]
    run = counted_program(lambda w, s, p, k: R._rollout(w, s, agent, p, k, widths), world, specs, params, keys)
    (out, _), counts = run(world, specs, params, keys)
    steps = float(np.asarray(out.steps)[:min(share, n)].sum())
    per = np.asarray(counts, np.float64) / max(steps, 1.0)
    return {"rows": min(share, n), "decisions": steps, **{name: float(v) for name, v in zip(COUNTERS, per)}}


# ---------------------------------------------------------------------------
# the machine's rates
# ---------------------------------------------------------------------------


def _on_devices(fn, parts: int):
    """``fn(x, *shared)`` run on each of ``parts`` devices at once (``x``'s
    leading axis split over them, ``shared`` replicated); returns a jitted
    function of ``(x, *shared)`` and a function that places such arguments
    on the devices (so no call times their transfer)."""
    from jax.sharding import NamedSharding

    from ignjax.sim.rollout import AXIS, device_mesh

    mesh = device_mesh(parts)

    def run(x, *shared):
        return jax.shard_map(fn, mesh=mesh, in_specs=(P(AXIS),) + (P(),) * len(shared), out_specs=P(AXIS),
                             check_vma=False)(x, *shared)

    def place(x, *shared):
        return (jax.device_put(x, NamedSharding(mesh, P(AXIS))),) + tuple(
            jax.device_put(a, NamedSharding(mesh, P())) for a in shared)
    return jax.jit(run), place


def machine_rates(world_bytes: int, quick: bool = False) -> dict:
    """Rates of this machine over every device the rollouts use: gathers
    per second from a cache-resident and a world-sized table, read bytes per
    second, and fused elementwise float32 operations per second."""
    from ignjax.sim.rollout import batch_parts

    parts = batch_parts()
    n = GATHERS_PER_CALL // (4 if quick else 1)
    rng = np.random.default_rng(0)
    big = max(int(world_bytes), 64 << 20) // 4

    def lookups(idx, table):  # independent look-ups (a dependent chain would time latency, not throughput)
        return jnp.sum(table[idx[0]], keepdims=True)[None]

    gather, place = _on_devices(lookups, parts)
    t_small = rng.integers(0, 1 << 20, CACHED_TABLE_BYTES // 4, dtype=np.int32)
    t_big = rng.integers(0, 1 << 20, big, dtype=np.int32)
    small_args = place(rng.integers(0, t_small.size, (parts, n), dtype=np.int32), t_small)
    big_args = place(rng.integers(0, big, (parts, n), dtype=np.int32), t_big)
    read, place = _on_devices(lambda x: jnp.sum(x[0], keepdims=True)[None], parts)
    stream = place(rng.random((parts, (256 << 20) // 4 // parts), dtype=np.float32))
    reps = 128

    def arith(x):
        y = x[0]
        for _ in range(reps):  # 4 operations a round (compare, multiply-add, multiply, select), one fused loop
            y = jnp.where(y > 0.5, y * 0.999 + 0.001, y * 1.001)
        return y[None]

    elementwise, place = _on_devices(arith, parts)
    block = place(rng.random((parts, 1 << 16), dtype=np.float32))  # 256 KB a device: cache-resident
    t_s, t_b, t_r, t_a = time_interleaved([
        lambda: jax.block_until_ready(gather(*small_args)), lambda: jax.block_until_ready(gather(*big_args)),
        lambda: jax.block_until_ready(read(*stream)), lambda: jax.block_until_ready(elementwise(*block))],
        repeat=3 if quick else 5)
    return {"devices": parts, "gather_cached_per_s": parts * n / t_s, "gather_world_per_s": parts * n / t_b,
            "world_table_bytes": 4 * big, "bandwidth_bytes_per_s": stream[0].nbytes / t_r,
            "elementwise_per_s": 4 * reps * block[0].size / t_a}


def limit(rates: dict, work: dict) -> dict:
    """Decision steps/s the machine allows ``work`` (module docstring):
    ``steps_per_s`` with every look-up at the cached-gather rate (the
    hardware's best), ``steps_per_s_uncached`` with each world-sized
    look-up at the random world-sized rate instead (every one a cache
    miss: the other end of the range)."""
    looks = work["gather_cached"] + work["gather_world"]
    t = {"gather": looks / rates["gather_cached_per_s"],
         "bandwidth": LINE_BYTES * work["gather_world"] / rates["bandwidth_bytes_per_s"],
         "compute": work["elementwise"] / rates["elementwise_per_s"]}
    bound = max(t, key=t.get)
    missed = dict(t, gather=work["gather_cached"] / rates["gather_cached_per_s"]
                  + work["gather_world"] / rates["gather_world_per_s"])
    return {"steps_per_s": 1.0 / t[bound], "bound": bound, "seconds_per_step": {k: float(v) for k, v in t.items()},
            "steps_per_s_uncached": 1.0 / max(missed.values())}


def bench_limit(es, world, agents, batch: int, steps_per_s: dict, quick: bool) -> dict:
    """The ``limit`` block: the machine's rates, each agent's work per
    decision at ``batch`` episodes, its limit and the fraction of it the
    bench's figure (``steps_per_s[agent][str(batch)]``) reaches; the
    top-level ``steps_per_s`` and ``bound`` are the EIG agent's."""
    from ignjax.agents import get_agent
    from ignjax.sim.rollout import episode_keys

    world_bytes = sum(int(np.asarray(a).nbytes) for a in jax.tree.leaves(world) if hasattr(a, "nbytes"))
    rates = machine_rates(world_bytes, quick)
    log(f"  gathers {rates['gather_cached_per_s'] / 1e6:.0f} M/s cached, {rates['gather_world_per_s'] / 1e6:.0f} M/s "
        f"from {rates['world_table_bytes'] >> 20} MB; read {rates['bandwidth_bytes_per_s'] / 1e9:.1f} GB/s; "
        f"elementwise {rates['elementwise_per_s'] / 1e9:.1f} G/s ({rates['devices']} devices)")
    idx = np.arange(batch) % len(es)
    specs = jax.tree.map(lambda a: a[idx], es.specs)
    keys = episode_keys(0, np.arange(batch))
    out = {"rates": rates, "batch": batch, "agents": {}}
    for name in agents:
        agent = get_agent(name)
        work = step_work(world, specs, agent, agent.default_params(), keys)
        lim = limit(rates, work)
        got = steps_per_s.get(name, {}).get(str(batch))
        entry = {"work": work, **lim}
        if got:
            entry["fraction"] = got / lim["steps_per_s"]
        out["agents"][name] = entry
        log(f"  {name:14s} {work['gather_cached'] + work['gather_world']:7.0f} look-ups "
            f"({work['gather_world']:.0f} world-sized), {work['elementwise'] / 1e3:.0f}k elementwise a decision: "
            f"limit {lim['steps_per_s']:.0f} steps/s ({lim['bound']}; {lim['steps_per_s_uncached']:.0f} if every "
            f"world-sized look-up missed the cache)"
            + (f", bench {got:.0f} = {got / lim['steps_per_s']:.0%}" if got else ""))
    head = out["agents"].get("eig") or next(iter(out["agents"].values()))
    out["steps_per_s"], out["bound"] = head["steps_per_s"], head["bound"]
    if "fraction" in head:
        out["fraction"] = head["fraction"]
    return out
