"""What an MLLM agent may use for one decision: :class:`DecisionContext`.

The host loop (:mod:`ignjax.evaluate.hostloop`) gives each decision's
:meth:`~ignjax.agents.llm.agent.LLMAgent.decide` one context: model calls
with re-asks, counted in the episode's accounting and transcript
(:meth:`~ignjax.evaluate.decisions.DecisionMaker.query`), the encoded
image of one rendered view (the Grounder's, the captioner's and the
self-check's), and notes the transcript keeps (the question's text, the
controller rule that decided, a default after unusable replies).
"""

from __future__ import annotations

from ignjax.agents.llm.agent import Decision
from ignjax.agents.llm.client import ChatClient
from ignjax.agents.llm.messages import ImagePart


class DecisionContext:
    """What an agent's :meth:`~ignjax.agents.llm.agent.LLMAgent.decide` may
    use for one decision: model calls with re-asks (:meth:`query`, counted
    in the episode's accounting and transcript) and the image of a view (:meth:`view_image`)."""

    def __init__(self, maker, client: ChatClient, ep, d: Decision):
        self._maker, self._client, self._ep, self._d = maker, client, ep, d
        self.defaulted = False
        self.question = ""
        self.rule: tuple[str, str] | None = None

    def note_question(self, text: str) -> None:
        """Record the text of the question this decision asks (agents that
        write their questions): the decision's transcript record carries it
        as ``question``. The oracle answers by type; the text is a record."""
        self.question = str(text)

    def note_rule(self, rule: str, text: str) -> None:
        """Record that the agent's controller decided (or changed) this decision by ``rule``, and what it did in
        words (``text``): the decision's transcript record carries both."""
        self.rule = (str(rule), str(text))

    async def query(self, request, parse, role: str = "planner", reasks: int | None = None):
        """Send ``request``; ``parse(parsed, parse_error) -> (value, error)``
        turns a reply into a value or an error, an error is answered with the
        agent's correction and asked again (``reasks``, default the agent's).
        Returns the value, or None when every reply was unusable.

        Raises:
            LLMRequestError: the request kept failing (the episode ends with
                stop reason ``model_failure``).
        """
        n = self._maker.agent.reasks if reasks is None else int(reasks)
        return await self._maker.query(self._client, self._ep, self._d, request, parse, role, n)

    def view_image(self, k: int, grid: bool = True) -> ImagePart:
        """View ``k`` of this decision, encoded: with the numbered 8x8 grid (the Grounder's image, kept with the
        episode's saved images), or without it (``grid=False``: the captioner's image, not kept)."""
        from ignjax.sim.views.compose import grounder_images
        from ignjax.sim.views.encode import encode_images

        rgb = self._d.views
        if rgb is None:
            raise ValueError("this decision carries no rendered views")
        if not 0 <= int(k) < rgb.shape[0]:
            raise ValueError(f"view {k} is outside the {rgb.shape[0]} views")
        fmt, one = self._maker.views.image_format, rgb[int(k)][None]
        data = encode_images(grounder_images(one) if grid else one, fmt, self._maker.views.quality)[0]
        img = ImagePart(data, "image/jpeg" if fmt == "jpeg" else "image/png")
        if grid and self._ep.index < self._maker.save_images:
            self._ep.images.append((self._d.step, img, "grounder"))
        return img

    def default(self, action):
        """Mark this decision's action as the default after unusable replies (returns ``action``)."""
        self.defaulted = True
        return action


__all__ = ["DecisionContext"]
