"""The RL environment's discrete actions and their mask: :mod:`ignjax.agents.learned.actions`.

They are defined with the agents (layer 3) so that the ``learned`` agent,
which decodes a policy's choice inside the evaluation's rollouts, and the
environment share one action table; this module keeps its name in
:mod:`ignjax.rl`.
"""

from ignjax.agents.learned.actions import (  # the one definition
    LONG_DISTANCE, SHORT_DISTANCE, action_mask, action_names, action_table, decode, move_cells, n_actions,
)

__all__ = ["LONG_DISTANCE", "SHORT_DISTANCE", "action_mask", "action_names", "action_table", "decode", "move_cells",
           "n_actions"]
