"""What running an MLLM agent would send at most, before sending anything
(``python -m ignjax.evaluate --dry-run``)."""

from __future__ import annotations

import dataclasses
import json

from ignjax.agents.llm.agent import Decision, LLMAgent
from ignjax.agents.llm.caption import CAPTION_CHARS, caption_request
from ignjax.agents.llm.messages import ChatRequest, ImagePart
from ignjax.agents.llm.config import LLMConfig
from ignjax.protocol import LOCKED_COSTS
from ignjax.sim import oracle_text as OT
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig

IMAGE_TOKEN_PX = 28
"""Side of the image patch one vision token covers in the dry-run estimate (Qwen2-VL-style models: 14 px patches
merged 2x2); other models count differently, so the figure is an estimate."""


def dry_run(agent: LLMAgent, n_episodes: int, *, sim: T.SimConfig = T.SimConfig(), views: ViewConfig = ViewConfig(),
            llm: LLMConfig | None = None, costs=LOCKED_COSTS) -> dict:
    """What running ``agent`` on ``n_episodes`` episodes would send at most,
    before sending anything: requests (every decision a Planner call, every
    decision a move or a Type-4 candidate for two-stage agents, every decision one caption call per view for agents
    that read captions; with ``self_questions`` one self-check per decision; with ``llm.paraphrase`` one
    paraphrase per question, as many questions as the budget allows; re-asks and the Planner's correction after a
    self-check not counted), images, and
    an estimate of prompt tokens (text at 4 characters a token, images at one
    token per :data:`IMAGE_TOKEN_PX` square) and of completion tokens
    (``llm.max_tokens`` per request, the cap). The prompts are built from a
    first decision of an episode with no answers yet."""
    from ignjax.sim.views.compose import panel_layout

    from ignjax.agents.llm.catalog import sim_overrides

    sim = dataclasses.replace(sim, **sim_overrides(agent, llm))
    two_stage = bool(getattr(agent, "two_stage", False)) and agent.observation == "panel"
    self_check = bool(getattr(agent, "self_questions", False)) and agent.observation == "panel"
    img = ImagePart(b"\xff\xd8\xff\xd9") if agent.observation == "panel" else None
    captions = agent.observation == "caption"
    d = Decision(episode="dry-run", step=0, max_steps=sim.max_steps, goal="object", questions_left=sim.max_questions,
                 costs=tuple(costs), answers=(), last_move="", n_views=sim.n_views, view_fov=sim.view_hfov, panel=img,
                 observation=None if img is not None else _placeholder_observation(agent, sim.n_views),
                 percept={})
    memory = agent.start("dry-run")
    req = agent.planner_request(memory, d) if hasattr(agent, "planner_request") else agent.request(memory, d)

    def text_tokens(r) -> int:
        chars = sum(len(p) if isinstance(p, str) else len(p.get("text", "")) if isinstance(p, dict) else 0
                    for m in r.messages for p in ([m["content"]] if isinstance(m["content"], str) else m["content"]))
        return chars // 4 + len(json.dumps(r.schema or {})) // 4

    rows, cols, _ = panel_layout(sim.n_views)
    panel_tokens = (rows * views.size // IMAGE_TOKEN_PX) * (cols * views.size // IMAGE_TOKEN_PX)
    view_tokens = (views.size // IMAGE_TOKEN_PX) ** 2
    decisions = n_episodes * sim.max_steps
    planner_tokens = text_tokens(req) + (panel_tokens if img is not None else 0)
    out = {"agent": agent.name, "episodes": n_episodes, "decisions_at_most": decisions,
           "planner_requests": decisions, "grounder_requests": decisions if two_stage else 0,
           "self_questioner_requests": decisions if self_check else 0,
           "caption_requests": decisions * sim.n_views if captions else 0,
           "images": (decisions if img is not None else 0) + (decisions if two_stage else 0)
           + (decisions if self_check else 0) + (decisions * sim.n_views if captions else 0),
           "prompt_tokens_per_planner_request": planner_tokens}
    caption_tokens = 0
    if captions:
        caption_tokens = text_tokens(caption_request(ImagePart(b"\xff\xd8\xff\xd9"))) + view_tokens
        out["prompt_tokens_per_caption_request"] = caption_tokens
    grounder_tokens = 0
    if two_stage:
        g = agent.grounder_request(d, ImagePart(b"\xff\xd8\xff\xd9"), "the centre of the open doorway", "")
        grounder_tokens = text_tokens(g) + view_tokens
        out["prompt_tokens_per_grounder_request"] = grounder_tokens
    self_check_tokens = 0
    if self_check:
        from ignjax.agents.llm.self_questioner import request as self_check_request

        self_check_tokens = text_tokens(self_check_request(d, ImagePart(b"\xff\xd8\xff\xd9"), "the object")) + view_tokens
        out["prompt_tokens_per_self_questioner_request"] = self_check_tokens
    paraphrase_tokens = 0
    if llm is not None and llm.paraphrase and agent.may_ask:  # one per answer; a question per decision at most
        out["paraphrase_requests"] = n_episodes * (min(sim.max_questions, sim.max_steps) if sim.question_budget
                                                   else sim.max_steps)
        route = OT.route_text(0, 2, -1, False, ())
        paraphrase_tokens = text_tokens(ChatRequest(messages=OT.paraphrase_messages(3, route),
                                                    schema=OT.PARAPHRASE_SCHEMA))
        out["prompt_tokens_per_paraphrase_request"] = paraphrase_tokens
    out["requests"] = (out["planner_requests"] + out["grounder_requests"] + out["self_questioner_requests"]
                       + out["caption_requests"] + out.get("paraphrase_requests", 0))
    out["prompt_tokens"] = (decisions * planner_tokens + out["grounder_requests"] * grounder_tokens
                            + out["self_questioner_requests"] * self_check_tokens
                            + out["caption_requests"] * caption_tokens
                            + out.get("paraphrase_requests", 0) * paraphrase_tokens)
    max_tokens = (llm.max_tokens if llm is not None else LLMConfig().max_tokens)
    out["completion_tokens_at_most"] = out["requests"] * max_tokens
    return out


def _placeholder_observation(agent: LLMAgent, n_views: int) -> str:
    """A stand-in for a text-reading agent's "What you see" lines: captions as long as the captioner may write
    (:data:`~ignjax.agents.llm.caption.CAPTION_CHARS`), or the ground-truth text of views with nothing in sight."""
    if agent.observation == "caption":
        return "\n".join(f"- view {k}: " + "x" * CAPTION_CHARS for k in range(n_views))
    return "\n".join(f"- view {k}: open floor for about 2.0 m; nothing of note" for k in range(n_views))


__all__ = ["IMAGE_TOKEN_PX", "dry_run"]
