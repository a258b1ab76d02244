"""Perception through a captioner: each rendered view described in words by
the model itself (the ``"caption"`` observation of
:class:`~ignjax.agents.llm.tandem.Tandem`, which ``navgpt`` and
``navgpt-naive`` use).

NavGPT's planner is a language model that reads what a captioner wrote
about each view, never the images. Here the captioner is the same model
behind the same endpoints: before a Planner request, one captioning request
per view (:func:`caption_request`: the view's image alone, without the
Grounder's grid, and a prompt of ours asking for what is visible: objects
with their colours and materials, openings, the kind of room as the
captioner judges it; no measurements). The requests go through the host
loop's ``ctx.query`` with role ``"caption"``, so they are cached by the
response cache (an identical view, from any direction or episode, reuses its
caption: the prompt does not name the direction), counted in the outcome's
accounting and written to the transcripts like every other call. They are
sent one after another, in view order, so an episode's transcript is the
same whatever order replies arrive in; with many episodes in flight the
server stays busy.

An unusable reply is not asked again (one request per view): the view reads
:data:`NO_CAPTION` and the reply counts as invalid. The Planner then reads
"What you see:" with one line per view name (:func:`describe_views`).
Nothing of the simulator's perception (instance ids, distances, the room
label) is in these lines: only what the model wrote about the image.
"""

from __future__ import annotations

from ignjax.agents.llm.messages import ChatRequest, ImagePart
from ignjax.agents.llm.controller import clip
from ignjax.sim.views.compose import view_names

CAPTION_CHARS = 300
"""Longest caption kept (characters); the schema asks for at most this."""

NO_CAPTION = "(no description: the captioner's reply could not be used)"
"""What a view reads when its caption reply is unusable."""

CAPTION_SCHEMA = {
    "type": "object",
    "properties": {"description": {"type": "string", "maxLength": CAPTION_CHARS}},
    "required": ["description"],
    "additionalProperties": False,
}
"""The captioner's reply: one JSON object with a short description."""

CAPTION_SYSTEM = (
    "You describe one photograph from the forward-facing camera of a robot inside a house, for a navigator that "
    "cannot see it. In one or two short sentences, say what is visible: the objects, each with its colour and "
    "material when you can tell them; openings such as doorways, corridors or passages, and on which side of the "
    "image they are; and what kind of room this looks like, if you can tell. Describe only what the image shows, "
    "in words: give no distances, sizes or other measurements. Reply with one JSON object: "
    '{"description": "<your description>"}.'
)


def caption_request(image: ImagePart, tag: str = "") -> ChatRequest:
    """The captioning request of one view's image (``tag``: the episode id)."""
    return ChatRequest(messages=[{"role": "system", "content": CAPTION_SYSTEM},
                                 {"role": "user", "content": ["Describe this view.", image]}],
                       schema=CAPTION_SCHEMA, schema_name="view_caption", tag=tag)


def caption_reply(parsed, err):
    """A caption reply's description, whitespace collapsed and clipped to
    :data:`CAPTION_CHARS`, or ``(None, why)``."""
    text = parsed.get("description") if isinstance(parsed, dict) else None
    if not isinstance(text, str) or not text.strip():
        return None, err or "field 'description' must be a non-empty string"
    return clip(text, CAPTION_CHARS), None


async def describe_views(ctx, d) -> str:
    """Every view of decision ``d`` captioned through ``ctx`` (one request
    per view, in view order; module docstring), as the Planner reads them:
    one line ``- <view name>: <caption>`` per view."""
    lines = []
    for k, name in enumerate(view_names(d.n_views)):
        got = await ctx.query(caption_request(ctx.view_image(k, grid=False), d.episode), caption_reply,
                              role="caption", reasks=0)
        lines.append(f"- {name}: {got if got is not None else NO_CAPTION}")
    return "\n".join(lines)


__all__ = ["CAPTION_CHARS", "CAPTION_SCHEMA", "CAPTION_SYSTEM", "NO_CAPTION", "caption_reply", "caption_request",
           "describe_views"]
