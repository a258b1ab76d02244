"""A topological graph of the places an agent has been, built from its own
odometry: the GTA-style memory (``memory_style="graph"`` of
:class:`~ignjax.agents.llm.tandem.Tandem`).

GTA (Li et al., 2026, "One Agent to Guide Them All"; its method's
interactive metric world representation, the topological graph
abstraction beside the volumetric map) keeps a graph
whose nodes hold a metric position and a visit count: a new position within
:data:`MERGE_M` of a node is that node (spatial clustering), and a node whose
visit count exceeds :data:`LOOP_VISITS` is a detected loop that calls for
re-planning. Here:

* a position is the agent's own offset from its start
  (:attr:`~ignjax.agents.llm.agent.Decision.offset`, metres east and north),
  taken once per decision; nothing of the scene (rooms, targets, the true
  map) enters the graph;
* a position joins the nearest node within :data:`MERGE_M` (the node keeps the
  position it was created at, so nodes do not drift into each other); else it
  founds a new node;
* a node's visit count is the number of times the agent *entered* it: from
  another node, or when it was founded. Decisions that stay in the node (a
  question, a blocked move) are not visits;
* an edge joins the nodes of two consecutive decisions when they differ;
* the loop alert holds while the current node's visit count exceeds
  :data:`LOOP_VISITS`.

:func:`graph_text` renders the graph for the Planner prompt, in metres of the
agent's own odometry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ignjax.agents.llm.agent import offset_words

MERGE_M = 0.8
"""GTA's merge radius (delta_merge, m): a position this close to a node is that node."""
LOOP_VISITS = 2
"""Loop threshold (tau_loop): the alert holds when the current node's visit count exceeds it. GTA names the
threshold without a value in the text we read; 2 (a third entry into one place) is our choice."""
NODES_SHOWN = 12
"""Nodes listed in the prompt at most (the current one and the most recently entered others)."""


@dataclass
class PlaceGraph:
    """Nodes (metric positions, visit counts), edges and the node of each decision."""

    positions: list = field(default_factory=list)  # (east, north) m per node, where it was founded
    visits: list = field(default_factory=list)  # entries per node
    last_entered: list = field(default_factory=list)  # decision index of each node's latest entry
    edges: set = field(default_factory=set)  # (i, j), i < j
    path: list = field(default_factory=list)  # node index per decision

    @property
    def current(self) -> int | None:
        """The node the agent is at (None before the first position)."""
        return self.path[-1] if self.path else None

    def nearest(self, pos) -> int | None:
        """The node within :data:`MERGE_M` of ``pos`` nearest to it, or None."""
        best, best_d = None, MERGE_M
        for i, q in enumerate(self.positions):
            dist = math.dist(pos, q)
            if dist <= best_d:
                best, best_d = i, dist
        return best

    def visit(self, pos) -> int:
        """Record the agent at ``pos`` (its own offset from the start, m) for one decision; returns its node."""
        pos = (float(pos[0]), float(pos[1]))
        node = self.nearest(pos)
        if node is None:
            node = len(self.positions)
            self.positions.append(pos)
            self.visits.append(0)
            self.last_entered.append(0)
        prev = self.current
        if prev != node:  # entered (or founded): one visit, and an edge from where it came
            self.visits[node] += 1
            self.last_entered[node] = len(self.path)
            if prev is not None:
                self.edges.add((min(prev, node), max(prev, node)))
        self.path.append(node)
        return node

    def neighbours(self, i: int) -> list[int]:
        return sorted(j for e in self.edges if i in e for j in e if j != i)

    @property
    def loop(self) -> bool:
        """The loop alert: the current node's visit count exceeds :data:`LOOP_VISITS`."""
        return self.current is not None and self.visits[self.current] > LOOP_VISITS


def _where(pos) -> str:
    return ", ".join(offset_words(*pos))


def graph_text(g: PlaceGraph) -> str:
    """The graph in words for the Planner: places as P1, P2, ... with their position from the start, visit count
    and links, the current place marked, and the loop alert when it holds."""
    if g.current is None:
        return "Place graph: (empty)"
    cur = g.current
    shown = sorted(sorted(range(len(g.positions)), key=lambda i: (i != cur, -g.last_entered[i]))[:NODES_SHOWN])
    lines = [f"Place graph (from your own odometry; places within {MERGE_M:g} m of each other are one place; "
             f"{len(g.positions)} places, {len(g.edges)} links):"]
    for i in shown:
        links = ", ".join(f"P{j + 1}" for j in g.neighbours(i)) or "none"
        here = "  <- you are here" if i == cur else ""
        lines.append(f"- P{i + 1}: {_where(g.positions[i])} of your start; visits {g.visits[i]}; links {links}{here}")
    if len(shown) < len(g.positions):
        lines.append(f"- ({len(g.positions) - len(shown)} earlier places not listed)")
    if g.loop:
        lines.append(f"Loop alert: you have entered P{cur + 1} {g.visits[cur]} times (more than {LOOP_VISITS}). You "
                     "are going in circles: re-plan, and prefer a way that leads to a place you have not been.")
    return "\n".join(lines)


__all__ = ["LOOP_VISITS", "MERGE_M", "NODES_SHOWN", "PlaceGraph", "graph_text"]
