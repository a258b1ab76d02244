"""MLLM evaluation throughput: the ``llm`` block of the bench record
(``python -m ignjax.bench --llm``).

Against the local scripted server (:class:`~ignjax.agents.llm.serve.ScriptedServer`,
a test double: real HTTP on 127.0.0.1, replies scripted from the request
text) with ``latency_s`` (+-25% jitter) and ``concurrency`` requests served
at once, the ``vlm`` agent reads 8 views at 128 px (``size``; its Planner
panel, JPEG). The scripted policy moves (a direction and cell chosen from the
request's hash) until the prompt says turn ``DECISIONS``, then stops, so
every episode is ``DECISIONS`` decisions long.

* ``batched``: the host loop (:mod:`ignjax.evaluate.hostloop`) with
  ``EPISODES_PER_SLOT`` x ``concurrency`` episodes in flight and the
  client's concurrency equal to the server's: while a row is stepped,
  rendered and encoded, another row's request is already queued for the
  server slot its reply frees (with only ``concurrency`` episodes, every
  host-side pause of a row leaves a server slot idle);
* ``sequential``: the field's usual loop, one episode at a time and one
  blocking request per decision (the same host loop with one slot and one
  request in flight), on the first episodes only; episodes per hour
  extrapolated from its wall time.

Wall times are the loop's own (``stats["wall_s"]``: first reset to last
outcome); every run of the block shares one simulator world and one
renderer, made once (render processes started, rendering contexts built by
the warm-up), so neither the world's construction nor process start-up is
in any figure.

``utilisation`` is the batched run's mean requests in flight divided by the
concurrency, over the whole run (compilation of the simulator's jitted
pieces happens before the first request and is not counted in it, but is in
the wall times). ``host_ms_per_decision``: the batched loop against a
zero-latency server (observation, rendering, composition, encoding,
request, parse, step), wall time per decision of the batched run's
episodes and batch (``wall_s["host"]`` over ``decisions["host"]``;
``decisions`` counts each run's decision steps, ``wall_s`` times each
run). A zero-latency warm-up run of the batched run's own episodes and
batch comes first, so both loops' programs are
compiled and the render contexts of the batched run's scenes made
(:class:`~ignjax.sim.views.contexts.SceneContexts` keeps them) before
anything is timed.
``limited_by`` names what bounds the batched figure: the server's
concurrency / latency, or the host (rendering and stepping) when its
decisions per second stay below what the server could answer.

``vllm``: the same loop (the ``vlm`` agent, the same views) against a real
model server: the tiny Qwen2-VL-style model under vLLM's CPU build
(:mod:`ignjax.agents.llm.vllm_server`, ``--max-num-seqs 8``, vLLM's own
continuous batching), started for the measurement on this machine. The
weights are random, so the decisions are arbitrary but schema-valid
(structured output, temperature 0, no response cache): the figure is
decisions per second, not quality. It runs on the first episodes of the
file (loaded on their own, so the simulator's world holds only their
scenes), ``VLLM_MAX_STEPS`` decisions at most each (fewer where the model
stops): ``batched`` keeps 8 episodes and 8 requests in flight (refilled from
``episodes.batched`` episodes), ``sequential`` runs one episode and one
request at a time. ``decisions_per_s`` is simulator steps taken over the
loop's wall time (``wall_s``: from its first reset to its last outcome; the
world's construction before it is not counted); re-asked replies cost
requests, not decisions. ``request_s``: mean seconds a request waited on the
server. The loop's programs are compiled (against the scripted server, while
vLLM starts) and the server warmed up on another episode before anything is
timed. Every run shares one world and one renderer (render processes and
contexts made once, before the timed runs). The server shares
the machine's cores with the loop's rendering and stepping, so on a small
CPU machine both figures include that contention.
Where the environment that ``.ci/prepare-vllm`` builds is absent the block is
``{"skipped": reason}``; a server that fails to start gives ``{"failed":
reason}`` (its log's tail on stderr).
"""

from __future__ import annotations

import contextlib
import math
import re
import time
from concurrent.futures import ThreadPoolExecutor, wait

from ignjax.bench.timing import log

DECISIONS = 6
EPISODES_PER_SLOT = 2
"""Episodes in flight per server slot in the batched run (module docstring)."""
VLLM_MAX_NUM_SEQS = 8
VLLM_MAX_STEPS = 4
"""Decision budget of an episode against vLLM (episodes end there unless the model stops first)."""
VLLM_BATCH = 8
"""Episodes (and requests) in flight in the batched run against vLLM."""
VLLM_MAX_TOKENS = 256
"""Completion limit: above the longest schema-valid reply (a 200-character reason), so replies are not cut short."""


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


def _run(es, srv, batch: int, concurrency: int, views, sim, cache_dir, shared=None, **llm_options):
    """One host-loop run; its wall time is the loop's own (``stats["wall_s"]``: from the first reset to the last
    outcome), with the world and renderer of ``shared`` (made once, warm) when given."""
    from ignjax.agents.llm.agent import VlmAgent
    from ignjax.agents.llm.config import LLMConfig
    from ignjax.evaluate.hostloop import run_llm_agent

    llm = LLMConfig(endpoints=(srv.base_url,), model=srv.model, api_key_env=None, concurrency=concurrency,
                    cache_dir=cache_dir, **{"timeout_s": 120.0, **llm_options})
    res = run_llm_agent(es, VlmAgent(), llm, sim=sim, views=views, batch=batch, **(shared or {}))
    return res, float(res.stats["wall_s"])


@contextlib.contextmanager
def _shared(es, sim, views):
    """The world and renderer every run of a figure reuses (render processes and contexts warm across runs)."""
    from ignjax.evaluate.runner import make_world
    from ignjax.sim.views import ViewRenderer

    renderer = ViewRenderer(es.bank, sim, views)
    try:
        yield {"world": make_world(es, sim), "renderer": renderer}
    finally:
        renderer.close()


def bench_llm(es, quick: bool, latency: float = 4.0, concurrency: int = 64, size: int = 128,
              vllm: bool = True) -> dict:
    """The ``llm`` block (module docstring): views of ``size`` px; ``vllm=False`` leaves out the ``vllm``
    figures (``{"skipped": ...}``)."""
    from ignjax.agents.llm.serve import ScriptedServer
    from ignjax.sim.types import SimConfig
    from ignjax.sim.views import ViewConfig

    sim = SimConfig(max_steps=DECISIONS + 2)
    views = ViewConfig(size=size, workers=0)
    n_batched = concurrency * (2 if quick else 4)
    n_seq = 1 if quick else 3
    batched_es = es.subset(range(min(n_batched, len(es))))
    in_flight = EPISODES_PER_SLOT * concurrency
    out = {"concurrency": concurrency, "latency_s": latency, "views": sim.n_views, "size": views.size,
           "decisions_per_episode": DECISIONS, "episodes": {"batched": len(batched_es), "sequential": n_seq},
           "episodes_in_flight": {"batched": in_flight, "sequential": 1}}
    with _shared(es, sim, views) as shared:
        # host cost per decision: zero-latency server, after a warm-up on the batched run's own episodes and
        # batch (its programs compiled, the render contexts of its scenes made)
        with ScriptedServer(latency=0.0, concurrency=concurrency, policy=_policy) as srv:
            _run(batched_es, srv, in_flight, concurrency, views, sim, None, shared)
            _run(es.subset(range(1)), srv, 1, 1, views, sim, None, shared)  # the sequential loop's programs too
            res_h, wall_h = _run(batched_es, srv, in_flight, concurrency, views, sim, None, shared)
        log(f"  host {1000.0 * wall_h / max(1, res_h.stats['decisions']):.1f} ms a decision "
            f"({res_h.stats['decisions']} decisions, zero latency)")
        with ScriptedServer(latency=latency, jitter=0.25, concurrency=concurrency, policy=_policy) as srv:
            res_b, wall_b = _run(batched_es, srv, in_flight, concurrency, views, sim, None, shared)
            res_s, wall_s = _run(es.subset(range(n_seq)), srv, 1, 1, views, sim, None, shared)
    out["wall_s"] = {"host": wall_h, "batched": wall_b, "sequential": wall_s}
    out["decisions"] = {k: int(r.stats["decisions"]) for k, r in (("host", res_h), ("batched", res_b),
                                                                  ("sequential", res_s))}
    out.update(scripted_figures(out["episodes"], out["wall_s"], out["decisions"], concurrency, latency))
    out["utilisation"] = res_b.stats["utilisation"]
    out["max_in_flight"] = res_b.stats["max_in_flight"]
    eph = out["episodes_per_hour"]
    log(f"  batched {eph['batched']:.0f} episodes/h, sequential {eph['sequential']:.0f}: "
        f"{out['speedup_vs_sequential']:.1f}x; utilisation {out['utilisation']:.2f}; host "
        f"{1000.0 / out['host_ms_per_decision']:.1f} decisions/s vs server {_server_rate(concurrency, latency):.1f}/s "
        f"-> limited by the {out['limited_by']}")
    out["vllm"] = bench_vllm(es, quick, views) if vllm else {"skipped": "not requested"}
    return out


def scripted_figures(episodes: dict, wall_s: dict, decisions: dict, concurrency: int, latency: float) -> dict:
    """The figures the scripted-server runs derive (module docstring) from their episodes, wall times and
    decisions (``host``: the zero-latency run): episodes per hour of ``batched`` and ``sequential`` and their
    ratio, host milliseconds per decision, and what limits the batched figure: the host when its decisions per
    second stay below what the server answers (``concurrency / latency``), else the server."""
    eph = {k: 3600.0 * episodes[k] / wall_s[k] for k in ("batched", "sequential")}
    host_ms = 1000.0 * wall_s["host"] / max(1, decisions["host"])
    return {"episodes_per_hour": eph, "speedup_vs_sequential": eph["batched"] / eph["sequential"],
            "host_ms_per_decision": host_ms,
            "limited_by": "server" if 1000.0 / host_ms >= _server_rate(concurrency, latency) else "host"}


def _server_rate(concurrency: int, latency: float) -> float:
    """Decisions per second the scripted server answers at most: ``concurrency / latency``."""
    return concurrency / latency if latency > 0 else math.inf


def bench_vllm(es, quick: bool, views) -> dict:
    """The ``llm`` block's ``vllm`` figures (module docstring): decisions/s of
    the host loop against the tiny model's vLLM server, batched and sequential.

    Runs on the first episodes of ``es``'s file (loaded again on their own,
    so the simulator's world holds only their scenes)."""
    from ignjax.agents.llm.serve import ScriptedServer
    from ignjax.agents.llm.vllm_server import (
        VllmServerError,
        environment_problem,
        start_vllm_server,
        vllm_home,
    )
    from ignjax.episodes.dataset import load_benchmark
    from ignjax.sim.types import SimConfig

    home = vllm_home()
    problem = environment_problem(home)
    if problem:
        reason = f"vLLM server environment not prepared: run .ci/prepare-vllm ({problem})"
        log(f"  vLLM: skipped ({reason})")
        return {"skipped": reason}
    t_part = time.perf_counter()
    n_b = 2 * VLLM_BATCH if quick else 4 * VLLM_BATCH
    n_s = 2 if quick else 4
    n = max(1 + n_b + n_s, VLLM_BATCH)
    if len(es) < n:
        raise ValueError(f"the vLLM figures need {n} episodes, {es.path} has {len(es)}")
    small = load_benchmark(es.path, limit=n)
    warm_es = small.subset(range(1))
    batched_es = small.subset(range(1, 1 + n_b))
    seq_es = small.subset(range(1 + n_b, 1 + n_b + n_s))
    sim = SimConfig(max_steps=VLLM_MAX_STEPS)
    opts = {"temperature": 0.0, "structured": "json_schema", "max_tokens": VLLM_MAX_TOKENS, "timeout_s": 300.0}
    out = {"max_num_seqs": VLLM_MAX_NUM_SEQS, "in_flight": {"batched": VLLM_BATCH, "sequential": 1},
           "max_steps": sim.max_steps, "max_tokens": VLLM_MAX_TOKENS, "render_workers": views.workers,
           "episodes": {"batched": n_b, "sequential": n_s}}
    log(f"  the same loop against the tiny model's vLLM server (max-num-seqs {VLLM_MAX_NUM_SEQS}, random weights) ...")
    try:
        with contextlib.ExitStack() as stack, ThreadPoolExecutor(1) as pool:
            t0 = time.perf_counter()

            def start():
                srv = stack.enter_context(start_vllm_server(home, max_num_seqs=VLLM_MAX_NUM_SEQS))
                return srv, time.perf_counter() - t0

            starting = pool.submit(start)  # the server starts while the loop's programs compile
            try:
                shared = stack.enter_context(_shared(small, sim, views))
                with ScriptedServer(latency=0.0, concurrency=VLLM_BATCH, policy=_policy) as scripted:
                    _run(small.subset(range(VLLM_BATCH)), scripted, VLLM_BATCH, VLLM_BATCH, views, sim, None, shared)
                    _run(warm_es, scripted, 1, 1, views, sim, None, shared)
            except BaseException:
                wait([starting])  # then the stack stops the server
                raise
            server, out["server_start_s"] = starting.result()
            _run(warm_es, server, 1, 1, views, sim, None, shared, **opts)  # warm-up: the server's first requests
            res_b, _ = _run(batched_es, server, VLLM_BATCH, VLLM_BATCH, views, sim, None, shared, **opts)
            res_s, _ = _run(seq_es, server, 1, 1, views, sim, None, shared, **opts)
    except VllmServerError as exc:
        log(f"  vLLM: {exc}")
        return {"failed": str(exc).splitlines()[0]}
    runs = {"batched": res_b, "sequential": res_s}
    acc = {k: r.accounting for k, r in runs.items()}
    out["decisions"] = {k: int(r.stats["decisions"]) for k, r in runs.items()}
    out["requests"] = {k: int(a["requests"].sum()) for k, a in acc.items()}
    out["invalid_replies"] = {k: int(a["invalid_replies"].sum()) for k, a in acc.items()}
    out["failed_episodes"] = {k: sum(bool(f) for f in a["failure"]) for k, a in acc.items()}
    out["wall_s"] = {k: float(r.stats["wall_s"]) for k, r in runs.items()}
    out.update(vllm_figures(out["decisions"], out["requests"],
                            {k: float(a["model_latency_s"].sum()) for k, a in acc.items()}, out["wall_s"]))
    out["utilisation"] = res_b.stats["utilisation"]
    d, w = out["decisions_per_s"], out["wall_s"]
    log(f"  vLLM: batched {d['batched']:.2f} decisions/s ({out['decisions']['batched']} in {w['batched']:.1f} s), "
        f"sequential {d['sequential']:.2f} ({out['decisions']['sequential']} in {w['sequential']:.1f} s): "
        f"{out['speedup']:.1f}x; a request {out['request_s']['batched']:.2f} s batched, "
        f"{out['request_s']['sequential']:.2f} s alone; server start {out['server_start_s']:.0f} s, "
        f"{time.perf_counter() - t_part:.0f} s in all")
    return out


def vllm_figures(decisions: dict, requests: dict, request_seconds: dict, wall_s: dict) -> dict:
    """The ``vllm`` figures derived from each run's (``batched``, ``sequential``) decisions, requests, seconds
    its requests waited on the server in all, and wall time: ``request_s`` (mean seconds a request waited; 0
    without requests), ``decisions_per_s`` and ``speedup`` (batched over sequential decisions per second)."""
    rate = {k: decisions[k] / wall_s[k] for k in ("batched", "sequential")}
    return {"request_s": {k: request_seconds[k] / max(1, requests[k]) for k in rate}, "decisions_per_s": rate,
            "speedup": rate["batched"] / rate["sequential"]}


__all__ = ["bench_llm", "bench_vllm", "scripted_figures", "vllm_figures"]
