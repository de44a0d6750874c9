"""Reinforcement learning on the scheduling problem (paper §V, §VI-B), kept out of the core.

Importing this package registers the environment with Gymnasium:
`gymnasium.make(ENV_ID, problem=problem)`.
"""

import gymnasium

ENV_ID = 'fjsp/Assembly-v0'

if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point='fjsp_planner.rl.env:AssemblyEnv')
