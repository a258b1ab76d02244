"""The RL environment's observation vector: :mod:`ignjax.agents.learned.obs`.

It is defined with the agents (layer 3) so that the ``learned`` agent, which
builds the same vector inside the evaluation's rollouts, and the environment
share one function; this module keeps its name in :mod:`ignjax.rl`.
"""

from ignjax.agents.learned.obs import (  # the one definition
    COSTS_SOURCE, HOME_SCALE, SLOT_FEATURES, Slice, encode, obs_bounds, obs_layout, obs_size,
)

__all__ = ["COSTS_SOURCE", "HOME_SCALE", "SLOT_FEATURES", "Slice", "encode", "obs_bounds", "obs_layout", "obs_size"]
