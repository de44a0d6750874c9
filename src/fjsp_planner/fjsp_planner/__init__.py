"""fjsp_planner: plans which robot does what, when and in what order, and runs the plan.

The packages read in the order a mission flows through them (docs/architecture.md):

- `model`: the problem (scenario files, `.fjs` files, limits), schedules and the independent
  validator. No ROS, no solver.
- `solving`: `solve()` and its backends (CP-SAT, greedy, tabu, MIP, stitched panels) with
  the lower bounds that make gaps honest. No ROS.
- `execution`: a mission under way: tracking the robots' reports, re-planning what remains,
  the journal, and the mission controller that decides when to plan. No ROS.
- `nodes`: the planner, monitor and recorder nodes: ROS plumbing around the above.
- `observe`: what happened in a mission, from the fleet's topics (history, story, charts, the
  live page, MCAP recordings). No ROS.
- `launcher`: one fleet's processes from start-up to the end of its mission.

Tools for users: `cli` (`fjsp-solve`), `missions` (`MissionClient`, `ros2 run fjsp_planner
mission`), `faults` (`inject_fault`), `testing` (a pytest harness over real processes).
`rl` holds the paper's Q-learning baseline.
"""
