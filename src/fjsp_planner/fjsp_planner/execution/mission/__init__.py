"""The mission controller: what the planner node decides, without ROS.

- `controller`: `MissionController`, fed what the node hears, is asked and the passing of
  time; it returns the effects the node carries out (solve, publish a plan, declare a job
  done, tell the story).
"""
