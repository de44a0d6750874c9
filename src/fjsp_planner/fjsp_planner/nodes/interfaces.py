"""Topic names and QoS shared by every node of the network (see docs/ros-interfaces.md).

Names are relative, so a whole mission can be pushed into a namespace with `-r __ns:=/x`.
"""

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

PLAN_TOPIC = 'plan'
ROBOT_STATES_TOPIC = 'robot_states'
JOB_STATES_TOPIC = 'job_states'
TASK_EVENTS_TOPIC = 'task_events'
MISSION_STATUS_TOPIC = 'mission_status'
INJECT_FAULT_SERVICE = 'inject_fault'
"""Served by each agent under its robot name: `<robot>/inject_fault`."""

LATCHED_QOS = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
)
"""The current plan and latest states: a node that joins late gets the last one of each writer."""

EVENTS_QOS = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    history=HistoryPolicy.KEEP_LAST,
    depth=1000,
)
"""Task events are facts nobody may miss: each writer keeps its mission's history for late
joiners (a robot produces 4 events per job, so 1000 covers 250 jobs per writer)."""
