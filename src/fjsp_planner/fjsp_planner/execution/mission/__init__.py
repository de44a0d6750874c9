"""The mission controller: what the planner node decides, without ROS.

- `controller`: `MissionController`, fed what the node hears, is asked and the passing of
  time; it decides when to plan and re-plan and when a mission is over;
- `reports`: what the node hears, as the controller takes it (`RobotReport`, `EventReport`);
- `effects`: what the controller returns for the node to carry out (solve, publish a plan,
  declare a job done, tell the story) and the mission's `StatusView`;
- `settings`: `Settings`, how the planner runs missions;
- `states`: the one table of moves between mission states, which the controller cannot
  leave;
- `liveness`: which robots' agents are live and follow the plan (heartbeats, availability,
  plan uptake);
- `continuation`: which jobs a new plan revision lets go on rather than start afresh;
- `resume`: a mission a restarted planner rebuilds from its journal;
- `charge`: which planner of a ROS domain is in charge, and which stand by.
"""
