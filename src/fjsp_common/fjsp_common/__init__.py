"""The fleet's shared contract: what the planner, the robot agents and any monitor agree on.

`vocabulary` (no ROS) names robot modes, event kinds and mission states once; `contract` maps
them to the message constants and fixes topic names and QoS; `running` is how every node reads
its parameters and runs. `ros2cli` is the workspace's `ros2` front end (node, param, service,
action, topic and interface verbs), a stand-in for ros2cli where it is not installed.
"""
