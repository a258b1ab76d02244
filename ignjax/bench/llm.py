"""MLLM evaluation throughput: the ``llm`` block of the bench record
(``python -m ignjax.bench --llm``).

Against the local scripted server (:class:`~ignjax.agents.llm.serve.ScriptedServer`,
a test double: real HTTP on 127.0.0.1, replies scripted from the request
text) with ``latency_s`` (+-25% jitter) and ``concurrency`` requests served
at once, the ``vlm`` agent reads 8 views at 128 px (its Planner panel,
JPEG). The scripted policy moves (a direction and cell chosen from the
request's hash) until the prompt says turn ``DECISIONS``, then stops, so
every episode is ``DECISIONS`` decisions long.

* ``batched``: the host loop (:mod:`ignjax.evaluate.hostloop`) with
  ``concurrency`` episodes in flight and the client's concurrency equal to
  the server's;
* ``sequential``: the field's usual loop, one episode at a time and one
  blocking request per decision (the same host loop with one slot and one
  request in flight), on the first episodes only; episodes per hour
  extrapolated from its wall time.

``utilisation`` is the batched run's mean requests in flight divided by the
concurrency, over the whole run (compilation of the simulator's jitted
pieces happens before the first request and is not counted in it, but is in
the wall times). ``host_ms_per_decision``: the batched loop against a
zero-latency server (observation, rendering, composition, encoding,
request, parse, step), wall time per decision after a warm-up run. Both
loops' programs are compiled before anything is timed.
``limited_by`` names what bounds the batched figure: the server's
concurrency x latency, or the host (rendering and stepping) when its
decisions per second stay below what the server could answer.
"""

from __future__ import annotations

import re
import time

from ignjax.bench.timing import log

DECISIONS = 6


def _policy(req: dict) -> str:
    import hashlib
    import json

    text = json.dumps(req.get("messages", []), sort_keys=True)
    m = re.search(r"Turn (\d+) of", text)
    turn = int(m.group(1)) if m else 1
    h = hashlib.sha256(text.encode()).digest()
    if turn >= DECISIONS:
        d = {"action": "stop", "direction": 0, "col": 4, "row": 1, "question": 1, "reason": "scripted stop"}
    else:
        d = {"action": "move", "direction": h[0] % 8, "col": 1 + h[1] % 8, "row": 1 + h[2] % 3, "question": 1,
             "reason": "scripted move"}
    return json.dumps(d)


def _run(es, srv, batch: int, concurrency: int, views, sim, cache_dir):
    from ignjax.agents.llm.agent import VlmAgent
    from ignjax.agents.llm.config import LLMConfig
    from ignjax.evaluate.hostloop import run_llm_agent

    llm = LLMConfig(endpoints=(srv.base_url,), model=srv.model, api_key_env=None, concurrency=concurrency,
                    cache_dir=cache_dir, timeout_s=120.0)
    t0 = time.perf_counter()
    res = run_llm_agent(es, VlmAgent(), llm, sim=sim, views=views, batch=batch)
    return res, time.perf_counter() - t0


def bench_llm(es, quick: bool, latency: float = 4.0, concurrency: int = 64) -> dict:
    """The ``llm`` block (module docstring)."""
    from ignjax.agents.llm.serve import ScriptedServer
    from ignjax.sim.types import SimConfig
    from ignjax.sim.views import ViewConfig

    sim = SimConfig(max_steps=DECISIONS + 2)
    views = ViewConfig(size=128, workers=0)
    n_batched = concurrency * (2 if quick else 4)
    n_seq = 1 if quick else 3
    batched_es = es.subset(range(min(n_batched, len(es))))
    out = {"concurrency": concurrency, "latency_s": latency, "views": sim.n_views, "size": views.size,
           "decisions_per_episode": DECISIONS, "episodes": {"batched": len(batched_es), "sequential": n_seq}}
    # host cost per decision: zero-latency server, after a warm-up (compilation, render workers)
    with ScriptedServer(latency=0.0, concurrency=concurrency, policy=_policy) as srv:
        warm = es.subset(range(min(concurrency, len(es))))
        _run(warm, srv, concurrency, concurrency, views, sim, None)
        _run(es.subset(range(1)), srv, 1, 1, views, sim, None)  # the sequential loop's programs, compiled too
        res, wall = _run(warm, srv, concurrency, concurrency, views, sim, None)
    out["host_ms_per_decision"] = 1000.0 * wall / max(1, res.stats["decisions"])
    log(f"  host {out['host_ms_per_decision']:.1f} ms a decision ({res.stats['decisions']} decisions, zero latency)")
    with ScriptedServer(latency=latency, jitter=0.25, concurrency=concurrency, policy=_policy) as srv:
        res_b, wall_b = _run(batched_es, srv, concurrency, concurrency, views, sim, None)
        res_s, wall_s = _run(es.subset(range(n_seq)), srv, 1, 1, views, sim, None)
    eph_b = 3600.0 * len(batched_es) / wall_b
    eph_s = 3600.0 * n_seq / wall_s
    out["episodes_per_hour"] = {"batched": eph_b, "sequential": eph_s}
    out["speedup_vs_sequential"] = eph_b / eph_s
    out["utilisation"] = res_b.stats["utilisation"]
    out["wall_s"] = {"batched": wall_b, "sequential": wall_s}
    out["max_in_flight"] = res_b.stats["max_in_flight"]
    server_rate = concurrency / latency
    host_rate = 1000.0 / out["host_ms_per_decision"]
    out["limited_by"] = "server" if host_rate >= server_rate else "host"
    log(f"  batched {eph_b:.0f} episodes/h, sequential {eph_s:.0f}: {out['speedup_vs_sequential']:.1f}x; "
        f"utilisation {out['utilisation']:.2f}; host {host_rate:.1f} decisions/s vs server {server_rate:.1f}/s "
        f"-> limited by the {out['limited_by']}")
    return out


__all__ = ["bench_llm"]
