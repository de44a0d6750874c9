"""What every node of a fleet agrees on besides its topics: node names and shared defaults.

Free of ROS, so the launcher, the test harness and the domain core read them too.
"""

PLANNER_NODE = 'planner'
"""The planner's node name, and the sender name it signs with: the only sender whose plans
and job completions count."""

MONITOR_NODE = 'monitor'
"""The monitor's node name, and the sender name it signs with."""

RECORDER_NODE = 'recorder'


def agent_node_name(robot: str) -> str:
    """The node of a robot's agent: one per robot, so no two nodes of a fleet share a name.
    An agent signs with its robot's name."""
    return f'agent_{robot}'


def sim_robot_node_name(robot: str) -> str:
    """The node of a simulated robot (`sim_robot`), serving the robot's actions to its agent."""
    return f'sim_{robot}'


HEARTBEAT_PERIOD = 0.2
"""Seconds between the robot states an agent publishes as its heartbeat."""

HEARTBEAT_TIMEOUT = 1.0
"""Seconds without a robot state after which the robot is offline, to the planner, the
monitor and a replay alike."""

DIAGNOSTICS_PERIOD = 1.0
"""Seconds between health reports on /diagnostics."""

LATE_THRESHOLD = 2.0
"""Schedule units an operation may run past its plan before its robot's diagnostic is WARN."""
