"""Rendered observations: the egocentric views as the executor sees them,
batched over episodes (:class:`ViewRenderer`), the Planner panel and the
Grounder image (:mod:`~ignjax.sim.views.compose`), and their encoding for
model requests (:mod:`~ignjax.sim.views.encode`). Backends: MuJoCo Warp
(:mod:`~ignjax.sim.views.warp`) and OpenGL (:mod:`~ignjax.sim.views.egl`),
chosen by :class:`ViewConfig`."""

from ignjax.sim.views.config import ViewConfig, resolve_backend
from ignjax.sim.views.renderer import ViewRenderer, Views

__all__ = ["ViewConfig", "ViewRenderer", "Views", "resolve_backend"]
