"""A mission under way, as the planner runs it, without ROS (docs/model.md, "Re-planning").

- `tracking`: the robots' reports turned into facts (`MissionTracker`): done and running
  jobs, where each robot is, the executed timeline and what it breaks;
- `replan`: what remains of a mission posed as a smaller problem and solved (`repair`,
  `improve`, `replan`);
- `journal`: what a restarted planner needs that the fleet does not hold;
- `mission/`: the mission controller, which decides when to plan and re-plan and when a
  mission is over, and returns what the planner node must do.
"""
