"""A griffe extension for the API pages: ignjax's docstrings are written with
reStructuredText's cross-reference roles (``:func:`~ignjax.sim.env.step```)
and literal-block markers (``text::``), while mkdocstrings renders docstrings
as Markdown. Before rendering, each role becomes a code span that links to the
object's entry when the site documents it (an optional cross-reference: no
warning when it does not), and ``::`` ending a paragraph becomes ``:`` (the
indented block after it is already a Markdown code block).

Loaded by ``mkdocs.yml`` (``plugins: mkdocstrings: handlers: python:
options: extensions``); the package itself does not import it.
"""

from __future__ import annotations

import html
import re

import griffe

ROLE = re.compile(r":(?:py:)?(?:func|class|mod|data|attr|meth|exc|obj|const|any):`(?P<body>[^`]+)`")
EXPLICIT = re.compile(r"^(?P<title>.+?)\s*<(?P<target>[^<>]+)>$")
LITERAL = re.compile(r"(?m)(\S)::[ \t]*$")
LONE_LITERAL = re.compile(r"(?m)^[ \t]*::[ \t]*$")


def _target(obj: griffe.Object, name: str) -> str:
    """The full path ``name`` (as written in ``obj``'s docstring) most likely refers to."""
    name = name.lstrip(".")
    if name.startswith("ignjax.") or name == "ignjax":
        return name
    head, _, rest = name.partition(".")
    scope = obj if obj.is_module or obj.is_class else obj.parent or obj
    try:
        full = scope.resolve(head)
    except Exception:  # an unresolvable name: guess the object's own module
        full = f"{obj.module.path}.{head}"
    return f"{full}.{rest}" if rest else full


def convert(obj: griffe.Object, text: str) -> str:
    """``text`` with its roles as (optional) cross-references and its literal markers as colons."""

    def role(match: re.Match) -> str:
        body = match["body"].strip()
        explicit = EXPLICIT.match(body)
        if explicit:
            title, name = explicit["title"], explicit["target"]
        else:
            name = body.lstrip("~!")
            title = name.rsplit(".", 1)[-1] if body.startswith("~") else name.lstrip(".")
        target = _target(obj, name.lstrip("~!"))
        return (f'<autoref identifier="{html.escape(target)}" optional>'
                f"<code>{html.escape(title)}</code></autoref>")

    text = ROLE.sub(role, text)
    text = LONE_LITERAL.sub("", text)
    return LITERAL.sub(r"\1:", text)


class RestRoles(griffe.Extension):
    """Rewrites every docstring of the loaded package as :func:`convert` does."""

    def on_object(self, *, obj: griffe.Object, loader: griffe.GriffeLoader, **kwargs) -> None:
        if obj.docstring is not None:
            obj.docstring.value = convert(obj, obj.docstring.value)
