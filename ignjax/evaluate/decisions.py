"""One row's decision in the MLLM host loop (:mod:`ignjax.evaluate.hostloop`),
from the simulator's state to the action it comes to: :class:`DecisionMaker`.

* What a decision shows (:meth:`DecisionMaker.prepare`,
  :meth:`DecisionMaker.render`): the round's state and observation taken
  for the rows that need a decision (percept, answers in words, the last
  move and the route hint's report, the ``text`` observation), then their
  views rendered, the Planner panels composed and encoded into a
  :class:`~ignjax.agents.llm.agent.Decision` each; what the front view
  showed is kept to resolve a Type-4 cell.
* Making it (:meth:`DecisionMaker.decide`): the unread oracle answers
  paraphrased first (``llm.paraphrase``), then the agent's
  :meth:`~ignjax.agents.llm.agent.LLMAgent.decide` with a
  :class:`~ignjax.evaluate.context.DecisionContext`, whose model calls go
  through :meth:`DecisionMaker.query` (re-asks, accounting, transcript
  records). A decision is ``("act", tuple)`` or ``("fail", reason)``.
* The action it comes to (:meth:`DecisionMaker.actions`): a round's
  decisions as the batch's :class:`~ignjax.sim.types.Action`, the Type-4
  candidates resolved (:mod:`ignjax.evaluate.candidates`).
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.agents.llm.agent import ASK, Decision, LLMAgent, compass_degrees
from ignjax.agents.llm.client import ChatClient
from ignjax.agents.llm.messages import ChatRequest, ImagePart, LLMRequestError
from ignjax.episodes.dataset import EpisodeSet
from ignjax.evaluate import accounting as A
from ignjax.evaluate import candidates as C
from ignjax.evaluate.context import DecisionContext
from ignjax.evaluate.rows import EpisodeState
from ignjax.evaluate.textobs import last_move_text, observation_text
from ignjax.scenes import vocab
from ignjax.sim import oracle_text as OT
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig


class DecisionMaker:
    """The decisions of one agent's episodes (:class:`~ignjax.evaluate.hostloop.HostLoop` makes one per run):
    ``renderer`` renders the panels (None: the agent does not render), ``save_images`` keeps the images of the
    first N episodes."""

    def __init__(self, es: EpisodeSet, agent: LLMAgent, *, sim: T.SimConfig, views: ViewConfig, costs,
                 save_images: int, renderer=None):
        from ignjax.sim.views.compose import view_names

        self.es, self.agent, self.sim, self.views, self.costs = es, agent, sim, views, costs
        self.save_images, self.renderer = save_images, renderer
        self.names = view_names(sim.n_views)
        self.categories = es.bank.categories
        self._structural = np.asarray(es.bank.instances.structural)
        self._centers = np.asarray(es.bank.instances.center)

    # -- what a decision shows --------------------------------------------------
    def prepare(self, rows, slots, states, obs) -> list[dict]:
        """What the decisions of ``rows`` need, taken from this round's state
        and observation (a row's entries stay as they are until its decision
        is made, so the panels may be rendered later, while other rows step)."""
        scene = np.asarray(states.episode.scene)
        pose = np.asarray(states.pose)
        step = np.asarray(states.step)
        qleft = np.asarray(obs["questions_left"])
        ans = jax.tree.map(np.asarray, states.answers)
        out = []
        for r in rows:
            ep = slots[r]
            percept = {"open": obs["free_space"][r].min(axis=-1).tolist(), "odometry": obs["odometry"][r][:2].tolist(),
                       "room": int(obs["room_label"][r]), "known": ans.known[r].tolist(),
                       "goal_room": int(ans.room_label[r]) if ans.known[r][1] else -1, "confirm": int(ans.confirm[r]),
                       "follow_up": int(ans.follow_up[r]), "hint_active": bool(ans.hint_active[r]),
                       "hint_progress": int(ans.hint_progress[r]), "hint_bearing": int(ans.hint_bearing[r]),
                       "blocked": obs["blocked"][r].tolist(),
                       "moved": float(obs["last_move"][r])}
            rec = self.es.records[ep.index]
            text = front = None
            if self.agent.observation == "text":  # the objects in sight, placed in front-view cells (Type-4 candidates)
                handles = obs["visible_handle"][r]
                cells = C.front_cells(self.sim, pose[r], self._centers[scene[r]][np.maximum(handles, 0)])
                front = ("projection", cells, handles, obs["visible_range"][r])
                text = observation_text(obs, r, self.categories, self.names, cells)
            last_kind = ep.calls[-1]["action"][0] if ep.calls and ep.calls[-1].get("action") else -1
            out.append({"row": r, "scene": int(scene[r]), "pose": pose[r].copy(), "front": front, "decision": dict(
                episode=rec["episode_id"], step=int(step[r]), max_steps=self.sim.max_steps,
                goal=vocab.category_display(rec["target_category"]), questions_left=int(qleft[r]),
                costs=self.costs, answers=tuple(ep.answers),
                last_move=last_move_text(obs, r, last_kind), hint_report=ep.progress,
                n_views=self.sim.n_views, view_fov=self.sim.view_hfov, observation=text, percept=percept,
                heading=compass_degrees(pose[r][2]), offset=tuple(float(v) for v in obs["odometry"][r][:2]))})
        return out

    def render(self, items: list[dict], slots) -> list[tuple[int, Decision]]:
        """``(row, Decision)`` of prepared ``items`` (render, compose and encode their panels)."""
        panels, v = [None] * len(items), None
        if self.agent.renders and items:
            from ignjax.sim.views.encode import encode_images

            v = self.renderer.render(np.asarray([it["scene"] for it in items]),
                                     np.stack([it["pose"] for it in items]))
            fmt = self.views.image_format
            data = encode_images(self.renderer.panels(v), fmt, self.views.quality)
            mime = "image/jpeg" if fmt == "jpeg" else "image/png"
            panels = [ImagePart(b, mime) for b in data]
            rgb = list(v.rgb) if self.agent.uses_views else [None] * len(items)
        else:
            rgb = [None] * len(items)
        out = []
        for i, (it, panel, views) in enumerate(zip(items, panels, rgb)):
            ep = slots[it["row"]]
            ep.front = ("segmentation", v.instance[i, 0], it["scene"]) if v is not None else it["front"]
            d = Decision(panel=panel, views=views, **it["decision"])
            if panel is not None and ep.index < self.save_images:
                ep.images.append((d.step, panel, "panel"))
            out.append((it["row"], d))
        return out

    # -- making it ---------------------------------------------------------------
    async def decide(self, client: ChatClient, ep: EpisodeState, d: Decision):
        """One decision (the agent's :meth:`~ignjax.agents.llm.agent.LLMAgent.decide`
        with a :class:`~ignjax.evaluate.context.DecisionContext`): ``("act", tuple)`` or ``("fail", reason)``."""
        try:
            d = await self._paraphrase(client, ep, d)
            ctx = DecisionContext(self, client, ep, d)
            first = len(ep.calls)
            act = tuple(int(x) for x in await self.agent.decide(ctx, ep.memory, d))
        except LLMRequestError as e:
            return "fail", str(e)
        if len(ep.calls) == first:  # decided by the agent's controller alone: no model call
            rule, text = ctx.rule or ("controller", "")
            ep.calls.append(A.controller_record(self.agent.name, d, act, rule, text))
        elif ctx.rule:
            ep.calls[-1]["rule"], ep.calls[-1]["text"] = ctx.rule
        ep.calls[-1]["action"] = list(act)
        if act[0] == ASK and self.agent.writes_questions:
            ep.calls[-1]["question"] = ctx.question
        if ctx.defaulted:
            ep.calls[-1]["error"] = "invalid replies: default action taken"
        return "act", act

    async def _paraphrase(self, client: ChatClient, ep: EpisodeState, d: Decision) -> Decision:
        """``d`` with the answers the agent has not read yet reworded by the model where the rewording passes
        the checks (:mod:`ignjax.evaluate.hostloop`'s docstring, ``llm.paraphrase``)."""
        if not ep.unread:
            return d
        for i in ep.unread:
            q, template = ep.answers[i]
            req = ChatRequest(messages=OT.paraphrase_messages(q, template), schema=OT.PARAPHRASE_SCHEMA,
                              schema_name="paraphrase", tag=d.episode)
            text = await self.query(client, ep, d, req, _paraphrase_reply, "paraphrase", 0)
            leaks = ["unusable reply"] if text is None else OT.paraphrase_leaks(q, text, template)
            if leaks:
                ep.acc["paraphrase_rejected"] += 1
                why = ep.calls[-1]["error"] if text is None else "; ".join(leaks)
                ep.calls[-1]["error"] = f"paraphrase refused, template used: {why}"
            else:
                ep.answers[i] = (q, text)
        ep.unread = []
        return dataclasses.replace(d, answers=tuple(ep.answers))

    async def query(self, client: ChatClient, ep: EpisodeState, d: Decision, req, parse, role: str, reasks: int):
        """One model call with its re-asks: ``parse(parsed, parse_error) -> (value, error)``;
        the value, or None when every reply was unusable (each counted invalid)."""
        earlier, res = [], None
        for attempt in range(reasks + 1):
            try:
                res = await client.complete(req)
            except LLMRequestError as e:
                A.count_failed_call(ep.acc, e)
                ep.calls.append(A.call_record(self.agent.name, d, req, None, None, earlier, str(e), role=role))
                raise
            A.count_reply(ep.acc, res)
            value, err = parse(res.parsed, res.parse_error)
            if value is not None:
                ep.calls.append(A.call_record(self.agent.name, d, req, res, None, earlier, None, role=role))
                return value
            A.count_unusable(ep.acc, err)
            earlier.append({"reply": res.text, "error": err, "request_hash": res.request_hash})
            if attempt < reasks:
                req = self.agent.correction(ep.memory, d, req, res.text, err)
        ep.calls.append(A.call_record(self.agent.name, d, req, res, None, earlier[:-1],
                                      f"invalid replies: {earlier[-1]['error']}", role=role))
        return None

    # -- the action it comes to ----------------------------------------------------
    def actions(self, ready: dict, slots):
        """The batch's :class:`~ignjax.sim.types.Action` from this round's replies ``ready`` (row ->
        ``("act", tuple)`` or ``("fail", reason)``; a failure is noted in its row's episode), with the Type-4
        candidates resolved (:mod:`ignjax.evaluate.candidates`):
        ``(action, acts (B, 5), candidates (B,), step_mask, fail_mask)``, B the rows of ``slots``."""
        B = len(slots)
        acts = np.zeros((B, 5), np.int32)
        acts[:, 3] = 1
        acts[:, 4] = 1
        cand = np.full(B, T.ANY_CANDIDATE, np.int32)
        step_mask, fail_mask = np.zeros(B, bool), np.zeros(B, bool)
        for r, (what, value) in ready.items():
            if what == "act":
                acts[r] = value
                step_mask[r] = True
                if acts[r, 0] == ASK and acts[r, 4] == 4:
                    cand[r] = self._candidate(slots[r], int(acts[r, 2]), int(acts[r, 3]))
            else:
                fail_mask[r] = True
                slots[r].failure = value
        action = T.Action(kind=jnp.asarray(acts[:, 0]), direction=jnp.asarray(acts[:, 1]), col=jnp.asarray(acts[:, 2]),
                          row=jnp.asarray(acts[:, 3]), question=jnp.asarray(acts[:, 4]), candidate=jnp.asarray(cand))
        return action, acts, cand, step_mask, fail_mask

    def _candidate(self, ep: EpisodeState, col: int, row: int) -> int:
        """The instance a Type-4 question about front-view cell ``(col, row)`` asks about, from what the
        decision was shown: the rendered segmentation, or the objects in sight placed in cells."""
        if ep.front is None:
            return T.NO_CANDIDATE
        if ep.front[0] == "segmentation":
            return C.segmented_candidate(ep.front[1], self._structural[ep.front[2]], col, row)
        return C.projected_candidate(*ep.front[1:], col, row)


def _paraphrase_reply(parsed, err):
    """A paraphrase reply's text, or ``(None, why)``."""
    text = parsed.get("text") if isinstance(parsed, dict) else None
    if not isinstance(text, str) or not text.strip():
        return None, err or "field 'text' must be a non-empty string"
    return " ".join(text.split()), None


__all__ = ["DecisionMaker"]
