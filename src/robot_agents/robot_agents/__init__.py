"""robot_agents: the robot side of the fleet (docs/robot-drivers.md).

- `execution`: how one robot follows its plan revisions, in schedule time (no ROS);
- `drivers`: what the agent asks of its robot (travel, operate, stop), and the timed
  `MockDriver` (no ROS);
- `action_driver`: the robot's legs and operations as goals to its own action servers;
- `agent_node`: the generic agent node, one per robot (`robot_agent` and its per-type aliases);
- `reports`: an agent's task events kept on disk for the agent after it;
- `simulation`: a simulated robot's durations, failures and moves (no ROS), served by
  `sim_robot` as the robot's action servers.
"""
