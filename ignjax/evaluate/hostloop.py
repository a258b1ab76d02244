"""The host loop of MLLM agents: batched asynchronous model calls between
jitted simulator steps.

All live episodes step together. The loop keeps ``batch`` slots; each holds
one episode. A round:

1. the jitted step runs for the rows whose decision has arrived (the other
   rows are left as they are: a row that waits never blocks a row that is
   ready), and records each stepped row's trajectory entry;
2. rows whose episode ended are written out (outcome, trajectory, transcript,
   accounting: one checkpoint line each) and refilled from the queue of
   remaining episodes (continuous batching on our side, so the server stays
   busy);
3. for the rows that need a decision, the jitted observation; then their
   views are rendered and the Planner panels composed and encoded
   (:class:`~ignjax.sim.views.ViewRenderer`) in a worker thread, one render
   at a time: while it runs, the loop keeps stepping the rows whose replies
   arrive, and the rows that become ready meanwhile are rendered together
   in the next call. A call takes at most half the client's capacity
   (``concurrency`` x endpoints / 2 rows, oldest first), so at the start,
   or when many rows become ready at once, the first requests leave while
   the rest render. When a render finishes, one request per row is sent;
   all requests are in flight at once, bounded per endpoint by the client
   (:class:`~ignjax.agents.llm.client.ChatClient`);
4. the loop wakes when any reply or render finishes and takes every reply
   that has arrived by then.

Bad replies: a reply that does not parse or names an out-of-range value is
answered with a short correction and asked again (``agent.reasks`` times),
then the agent's default action is taken and the reply counted in
``invalid_replies``. Requests that keep failing (the client's retry caps
spent) end that episode with stop reason ``model_failure`` and the reason in
``failure``; the other episodes continue. A cache miss under replay ends the
run with the request's hash.

Question texts: an agent that writes its questions
(:attr:`~ignjax.agents.llm.agent.LLMAgent.writes_questions`) hands the text
of an ASK to ``ctx.note_question``; the decision's transcript record carries
it as ``question`` ("" when the agent's controller asked without one), and
:func:`ignjax.evaluate.accounting.question_texts` collects them (the Type-3 content analysis reads
them). The oracle answers by type either way.

Route hint: after every step of a row with an active Type-3 hint, the loop
words the controller's report on it (:func:`ignjax.sim.oracle_text.hint_report_text`
of ``Answer.hint_progress`` and ``Answer.hint_bearing``: closer / farther /
reached, and the side the hinted area lies on now, recomputed by the
simulator from the new pose and heading); the next decision carries it as
:attr:`~ignjax.agents.llm.agent.Decision.hint_report`, next to the
executor's report on the move itself (``last_move``).

Paraphrase (``llm.paraphrase``): before a decision, each oracle answer the
agent has not read yet (refusals excepted) is sent through the same client
(:func:`ignjax.sim.oracle_text.paraphrase_messages`; one request per answer,
no re-ask, transcript role ``paraphrase``, counted like every model call);
the rewording replaces the template in what the agent reads when
:func:`ignjax.sim.oracle_text.paraphrase_leaks` finds nothing in it, and
otherwise (or when the reply is unusable) the template stays and the
episode's ``paraphrase_rejected`` counts it. An answer the agent never reads
(asked at the episode's last step) is not paraphrased.

Resume and recovery (:mod:`ignjax.evaluate.recovery`): every episode that
ends is appended to ``<out>/llm/<agent>.progress.jsonl`` (flushed and synced).
A run started again with the same settings keeps the episodes that ended
normally there and runs the others from their start, those that ended by a
model failure included; their earlier requests come from the response cache
(no request sent twice, no question charged twice: the simulator replays the
same decisions), so the outcomes equal an uninterrupted run. A file written
with other settings is refused.

Accounting and transcripts (:mod:`ignjax.evaluate.accounting`): every HTTP
attempt counts as a request, answered or not; the controller's own decisions
are transcript records of role ``controller`` naming the rule that fired.

Determinism: an episode's course depends on its episode, its key (seed and
index in the file), the simulator and the replies; not on its slot, the
batch size or the order replies arrive in. Transcripts are written at the
end sorted by episode and step.

The pieces: :mod:`ignjax.evaluate.rows` (the jitted programs over chosen rows,
what the host keeps of each running episode, the progress file's settings
key), :mod:`ignjax.evaluate.decisions` (a row's decision: what it shows, the
model calls that make it, the batch action it comes to); this module drives
the rounds.
"""

from __future__ import annotations

import asyncio
import dataclasses
import os
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.agents.llm.agent import ASK, LLMAgent
from ignjax.agents.llm.cache import ResponseCache
from ignjax.agents.llm.client import ChatClient
from ignjax.agents.llm.config import LLMConfig
from ignjax.episodes.dataset import EpisodeSet
from ignjax.errors import ConfigError
from ignjax.evaluate import records as R
from ignjax.evaluate.decisions import DecisionMaker
from ignjax.evaluate.records import LoopResult
from ignjax.evaluate.recovery import ProgressLog
from ignjax.evaluate.rows import (EpisodeState, RunState, abort_rows, observe_rows, outcome_rows, reset_all,
                                  reset_rows, settings_hash, step_rows)
from ignjax.fileio import atomic_write
from ignjax.protocol import LOCKED_COSTS
from ignjax.sim import env as E
from ignjax.sim import oracle_text as OT
from ignjax.sim import types as T
from ignjax.sim.rollout import episode_keys
from ignjax.sim.views import ViewConfig


class HostLoop:
    """One agent over an episode set (:func:`run_llm_agent` builds and runs it)."""

    def __init__(self, es: EpisodeSet, agent: LLMAgent, llm: LLMConfig, *, sim: T.SimConfig, views: ViewConfig,
                 batch: int, seed: int, costs, out: Path | None, save_images: int, progress: bool, world=None,
                 renderer=None):
        from ignjax.evaluate.runner import make_world

        self.es, self.agent, self.llm, self.sim, self.views = es, agent, llm, sim, views
        self.seed, self.costs, self.out, self.save_images, self.progress = seed, tuple(costs), out, save_images, progress
        if world is not None and world.config != sim:
            raise ConfigError(None, "world", "the given world was made with other simulator settings")
        self.world = world if world is not None else make_world(es, sim)
        E.check_specs(self.world, es.specs)
        self.n = len(es)
        self.B = max(1, min(int(batch), self.n))
        self.render_rows = max(1, llm.concurrency * len(llm.endpoints) // 2)
        self.keys = episode_keys(seed, es.key_index)
        self.categories = es.bank.categories
        self.renderer, self._own_renderer = None, False
        if agent.renders and renderer is not None:
            if renderer.bank is not es.bank or renderer.sim != sim or renderer.config != views:
                raise ConfigError(None, "renderer", "the given renderer was made for another bank, simulator settings "
                                                    "or view settings")
            self.renderer = renderer
        elif agent.renders:  # made before the first request: render workers start here
            from ignjax.sim.views import ViewRenderer

            self.renderer, self._own_renderer = ViewRenderer(es.bank, sim, views), True
        self.maker = DecisionMaker(es, agent, sim=sim, views=views, costs=self.costs, save_images=save_images,
                                   renderer=self.renderer)
        w = self.world
        self._reset = lambda *a: reset_rows(w, *a)
        self._reset_all = lambda *a: reset_all(w, *a)
        self._step = lambda *a: step_rows(w, *a)
        self._abort = abort_rows
        self._observe = lambda st: observe_rows(w, st)
        self._outcome = lambda st: outcome_rows(w, st)

    # -- the episodes in the rows -----------------------------------------------
    def _fill(self, run: RunState, states, free_rows):
        """Start the next queued episodes in ``free_rows``: ``(states, the rows started)``."""
        rows, idx = [], []
        for r in free_rows:
            if not run.queue:
                break
            i = run.queue.pop()
            ep = run.slots[r] = EpisodeState(i, self.agent.start(self.es.records[i]["episode_id"]))
            if self.sim.upfront_description:  # given at reset (and charged) as one Type-1 and one Type-2 answer
                o = self.es.records[i]["oracle"]
                ep.answers = [(1, o["appearance"]), (2, o["region"])]
                ep.unread = [0, 1] if self.llm.paraphrase else []
            run.traj_rows[i] = []
            rows.append(r)
            idx.append(i)
        if not rows:
            return states, []
        take = np.zeros(self.B, np.int64)
        take[rows] = idx
        mask = np.zeros(self.B, bool)
        mask[rows] = True
        specs = jax.tree.map(lambda a: a[take], self.es.specs)
        return self._reset(specs, self.keys[take], jnp.asarray(mask), states), rows

    def _note_step(self, run: RunState, acts, cand, step_mask, before_step, rec, pose, answers) -> None:
        """Each stepped row's trajectory record, the oracle's answer in words and the active hint's report."""
        for r in np.flatnonzero(step_mask):
            ep = run.slots[r]
            run.traj_rows[ep.index].append((int(before_step[r]), pose[r], [x[r] for x in rec]))
            if acts[r, 0] == ASK:
                self._answer(ep, int(acts[r, 4]), answers, r, int(before_step[r]), pointed=int(cand[r]) != T.NO_CANDIDATE)
            ep.progress = OT.hint_report_text(int(answers.hint_progress[r]), int(answers.hint_bearing[r])) \
                if answers.hint_active[r] else ""

    def _answer(self, ep: EpisodeState, q: int, answers, r: int, step: int, pointed: bool) -> None:
        """Append the oracle's answer to a question of type ``q`` in words (row ``r`` of ``answers``)."""
        er = self.es.records[ep.index]
        txt = OT.answer_text(
            q, bool(answers.refused[r]), appearance=er["oracle"]["appearance"], region=er["oracle"]["region"],
            hint_room_label=int(answers.hint_room_label[r]), hint_sector=int(answers.hint_sector[r]),
            hint_landmark=int(answers.hint_landmark[r]), hint_in_room=bool(answers.hint_in_room[r]),
            confirm=int(answers.confirm[r]), follow_up=int(answers.follow_up[r]), categories=self.categories,
            key=f"{er['episode_id']}:{step}", pointed=pointed)
        ep.answers.append((q, txt))
        if self.llm.paraphrase and not answers.refused[r]:
            ep.unread.append(len(ep.answers) - 1)

    def _retire(self, run: RunState, ended, outs, pose, log: ProgressLog, bar, client: ChatClient) -> None:
        """Record the episodes of rows ``ended`` (progress file, images) and free their slots."""
        for r in ended:
            ep = run.slots[r]
            entry = R.episode_entry(self.es, self.sim, ep, outs, r, run.traj_rows.pop(ep.index), pose[r])
            run.records[ep.index] = entry
            log.append(entry)
            self._write_images(ep)
            run.slots[r] = None
            if bar:
                st = client.stats()
                bar.set_postfix_str(f"in flight {st.in_flight}, tok {st.prompt_tokens + st.completion_tokens}, "
                                    f"retries {st.retries}", refresh=False)
                bar.update(1)

    def _write_images(self, ep: EpisodeState) -> None:
        if self.out is None or not ep.images:
            return
        eid = self.es.records[ep.index]["episode_id"]
        folder = self.out / "images" / self.agent.name / eid
        for step, img, role in ep.images:
            ext = "jpg" if img.mime == "image/jpeg" else "png"
            atomic_write(folder / f"{step:03d}_{role}.{ext}", img.data)

    # -- the loop -------------------------------------------------------------
    def _progress_bar(self, done: int):
        if not self.progress:
            return None
        import sys

        from tqdm.auto import tqdm

        return tqdm(total=self.n, initial=done, desc=self.agent.name, unit="ep", file=sys.stderr, dynamic_ncols=True)

    async def _round(self, run: RunState, client: ChatClient, states, ready: dict, log: ProgressLog, bar):
        """Apply one round of replies ``ready``: step the rows, record what happened, retire the episodes that
        ended and start queued ones in their rows. Returns ``(states, the rows that need a decision)``."""
        loop = asyncio.get_running_loop()
        action, acts, cand, step_mask, fail_mask = self.maker.actions(ready, run.slots)
        run.decisions += int(step_mask.sum())
        before_step = await loop.run_in_executor(None, np.asarray, states.step)
        states, rec = await loop.run_in_executor(None, self._step, states, action, jnp.asarray(step_mask))
        if fail_mask.any():
            states = await loop.run_in_executor(None, self._abort, states, jnp.asarray(fail_mask))
        rec, pose, done_now, answers = await loop.run_in_executor(None, lambda st=states, rc=rec: (
            [np.asarray(x) for x in rc], np.asarray(st.pose), np.asarray(st.done), jax.tree.map(np.asarray, st.answers)))
        self._note_step(run, acts, cand, step_mask, before_step, rec, pose, answers)
        ended = [int(r) for r in np.flatnonzero((step_mask | fail_mask) & done_now)]
        refilled = []
        if ended:
            outs = await loop.run_in_executor(None, lambda st=states: jax.tree.map(np.asarray, self._outcome(st)))
            self._retire(run, ended, outs, pose, log, bar, client)
            states, refilled = await loop.run_in_executor(None, self._fill, run, states, ended)
        return states, sorted({int(r) for r in np.flatnonzero(step_mask & ~done_now)} | set(refilled))

    async def _drive(self, run: RunState, client: ChatClient, states, log: ProgressLog, bar) -> None:
        """Fill the rows and run rounds until every queued episode has ended: prepare the rows that need a
        decision, render them one call at a time, send each rendered row's decision, and apply the replies
        that have arrived whenever a reply or a render finishes."""
        loop = asyncio.get_running_loop()
        states, need = self._fill(run, states, list(range(self.B)))
        tasks: dict = {}
        waiting: list[dict] = []  # rows prepared for a decision, not yet rendered
        render = None  # the one render in progress (its rows' panels), or None
        while True:
            if need:
                waiting += await loop.run_in_executor(None, lambda st=states, rs=need: self.maker.prepare(
                    rs, run.slots, st, jax.tree.map(np.asarray, dataclasses.asdict(self._observe(st)))))
                need = []
            if waiting and render is None:
                # rendered while the loop keeps stepping rows whose replies arrive; rows that become
                # ready meanwhile are rendered together in the next call (at most render_rows a call,
                # oldest first, so the first requests leave while the rest render)
                render = loop.run_in_executor(None, self.maker.render, waiting[:self.render_rows], run.slots)
                waiting = waiting[self.render_rows:]
            if not tasks and render is None:
                break
            done, _ = await asyncio.wait(list(tasks) + ([render] if render is not None else []),
                                         return_when=asyncio.FIRST_COMPLETED)
            if render in done:
                for r, d in render.result():
                    tasks[asyncio.ensure_future(self.maker.decide(client, run.slots[r], d))] = r
                render = None
            ready = {tasks.pop(t): t.result() for t in done if t in tasks}
            if ready:
                states, need = await self._round(run, client, states, ready, log, bar)

    async def run(self) -> LoopResult:
        key = settings_hash(self.es, self.agent, self.llm, self.sim, self.views, self.seed, self.costs)
        log = ProgressLog(None if self.out is None else self.out / "llm" / f"{self.agent.name}.progress.jsonl", key,
                          self.agent.name, self.n)
        finished, failed_before = log.load()
        log.open()
        B = self.B
        run = RunState(queue=[i for i in reversed(range(self.n)) if i not in finished], slots=[None] * B)
        # every slot starts empty: a padding episode (valid False) is done at reset
        pad = jax.tree.map(lambda a: a[np.zeros(B, np.int64)], self.es.specs)
        pad = dataclasses.replace(pad, valid=jnp.zeros(B, bool))
        states = self._reset_all(pad, self.keys[np.zeros(B, np.int64)])
        t_start = time.perf_counter()
        bar = self._progress_bar(len(finished))
        cache = ResponseCache(self.llm.cache_dir) if self.llm.cache_dir else None
        try:
            async with ChatClient(self.llm, cache=cache) as client:
                t_stats0 = client.stats()
                await self._drive(run, client, states, log, bar)
                stats = client.stats()
                util = client.utilisation(t_stats0)
                wall = time.perf_counter() - t_start
        finally:
            log.close()
            if bar:
                bar.close()
            if cache is not None:
                cache.close()
            if self.renderer is not None and self._own_renderer:
                self.renderer.close()
        records = {**run.records, **finished}
        stats = {"wall_s": wall, "decisions": run.decisions, "utilisation": util, "requests": stats.requests_sent,
                 "retries": stats.retries, "max_in_flight": stats.max_in_flight, "resumed": len(finished),
                 "rerun": len(failed_before), "failures": sum(bool(r["failure"]) for r in records.values()),
                 "paraphrased": sum(c["role"] == "paraphrase" for r in records.values() for c in r["calls"]),
                 "paraphrase_rejected": sum(r["accounting"]["paraphrase_rejected"] for r in records.values())}
        return R.loop_result([records[i] for i in range(self.n)], stats, self.sim)


def run_llm_agent(es: EpisodeSet, agent: LLMAgent, llm: LLMConfig, *, sim: T.SimConfig = T.SimConfig(),
                  views: ViewConfig = ViewConfig(), batch: int = 64, seed: int = 0, costs=LOCKED_COSTS,
                  out: str | os.PathLike | None = None, save_images: int = 0, progress: bool = False, world=None,
                  renderer=None) -> LoopResult:
    """Run an MLLM agent over every episode of ``es`` (module docstring).

    Args:
        es: the episodes.
        agent: the MLLM agent (:mod:`ignjax.agents.llm.agent`).
        llm: endpoints, model and request settings (cache in ``llm.cache_dir``).
        sim: simulator settings (``n_views`` is the panel's view count); an
            agent's ``sim_overrides`` (e.g. ``tandem-4v``'s view count) replace
            the settings they name.
        views: image settings (default :data:`~ignjax.sim.views.config.DEFAULT_SIZE`, 448 px views: a
            1344 px panel).
        batch: episodes in flight at once (slots).
        seed: seed of the episodes' keys (as :func:`ignjax.evaluate.runner.run_agent`).
        costs: the question costs shown to a cost-aware agent.
        out: run folder for the checkpoint (``llm/<agent>.progress.jsonl``) and
            images; None: no checkpoint.
        save_images: write the images of the first N episodes to
            ``images/<agent>/<episode id>/<step>_panel.jpg`` and, for a Grounder,
            ``<step>_grounder.jpg`` (for the viewer, which marks the chosen cell on it).
        progress: show a progress bar (episodes, ETA, requests in flight,
            tokens, retries).
        world: a :class:`~ignjax.sim.env.World` made from ``es`` (or the set it
            was cut from) with ``sim``, to share across runs (default: made here).
        renderer: a :class:`~ignjax.sim.views.ViewRenderer` of ``es.bank`` with
            ``sim`` and ``views``, to share across runs (its render processes
            and contexts stay warm; the caller closes it). Default: one made
            for this run and closed at its end.

    Raises:
        ReplayMissError: under ``llm.replay``, a request not in the cache.
        InputError: a checkpoint written with other settings.
    """
    if batch < 1:
        raise ConfigError(None, "batch", f"must be >= 1, got {batch}")
    from ignjax.agents.llm.catalog import sim_overrides

    overrides = sim_overrides(agent, llm)
    if overrides:  # e.g. the observation ablation's view count, the no-QA variant's upfront description
        sim = dataclasses.replace(sim, **overrides)
    loop = HostLoop(es, agent, llm, sim=sim, views=views, batch=batch, seed=seed, costs=costs,
                    out=Path(out) if out is not None else None, save_images=save_images, progress=progress,
                    world=world, renderer=renderer)
    return asyncio.run(loop.run())


__all__ = ["HostLoop", "LoopResult", "run_llm_agent"]
