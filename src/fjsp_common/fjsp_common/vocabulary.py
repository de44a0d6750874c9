"""The fleet's words, defined once and free of ROS so the domain core can use them too.

Each enum member has a message constant of the same name (`RobotState.MODE_<NAME>`,
`TaskEvent.KIND_<NAME>`, `MissionStatus.STATE_<NAME>`, `MissionEvent.KIND_<NAME>`);
`fjsp_common.contract` pairs them by name, so no order has to match anywhere.
"""

from enum import StrEnum

MIN_DELAY_FACTOR = 1e-3
MAX_DELAY_FACTOR = 1e3
"""Bounds of one delay fault's factor, and of the product of the factors applied to one
operation: durations are at most 1e6 units (docs/scenario-format.md), so a delayed operation
stays within 1e9, where floats still resolve the agents' 1e-6 time grid. Agents refuse beyond
them; fault tools refuse before sending."""


class RobotMode(StrEnum):
    IDLE = 'idle'
    TRAVELLING = 'travelling'
    WAITING = 'waiting'
    """At the job's location, waiting for predecessors or co-workers."""
    WORKING = 'working'
    HOLDING = 'holding'
    """Keeps holding a part into its next job."""
    FAILED = 'failed'
    OFFLINE = 'offline'
    """Heartbeat lost; set by observers, never by the robot itself."""

    @property
    def healthy(self) -> bool:
        return self not in (RobotMode.FAILED, RobotMode.OFFLINE)


class EventKind(StrEnum):
    """What happened to a job: robots report the first four, the planner JOB_DONE."""

    ARRIVED = 'arrived'
    STARTED = 'started'
    OPERATION_DONE = 'operation_done'
    JOB_DONE = 'job_done'
    ABORTED = 'aborted'


class MissionState(StrEnum):
    """Where a mission is, as `mission_status` says; the moves between states are one table,
    `fjsp_planner.execution.mission.states.TRANSITIONS`."""

    IDLE = 'idle'
    """No mission: the planner waits for one."""
    QUEUED = 'queued'
    """Accepted while another mission runs: waits in the planner's queue for its turn."""
    WAITING_FOR_ROBOTS = 'waiting for robots'
    """Accepted: waits until every robot reported (at most `robot_wait_timeout`)."""
    PLANNING = 'planning'
    """Computing the first plan."""
    EXECUTING = 'executing'
    """The robots follow the current plan."""
    REPLANNING = 'replanning'
    """Computing a plan of what remains; the robots go on with the current one."""
    BLOCKED = 'blocked'
    """The robots available cannot do what remains; waits for the fleet to change."""
    COMPLETE = 'complete'
    """Ended: every job done, and the timeline the robots ran is valid."""
    CANCELLED = 'cancelled'
    """Ended by a cancel request: the robots dropped their tasks."""
    FAILED = 'failed'
    """Ended without completing: no valid plan, an invalid executed timeline, or blocked
    longer than the mission's `blocked_timeout`."""

    @property
    def ended(self) -> bool:
        return self in (MissionState.COMPLETE, MissionState.CANCELLED, MissionState.FAILED)


class MissionEventKind(StrEnum):
    """What the planner decided or noticed: the story of a mission."""

    MISSION_STARTED = 'mission started'
    PLAN_PUBLISHED = 'plan published'
    ROBOT_FAILED = 'robot failed'
    ROBOT_OFFLINE = 'robot offline'
    ROBOT_BACK = 'robot back'
    JOB_ABORTED = 'job aborted'
    JOB_VOIDED = 'job voided'
    BLOCKED = 'blocked'
    WARNING = 'warning'
    JOBS_ADDED = 'jobs added'
    MISSION_COMPLETE = 'mission complete'
    MISSION_CANCELLED = 'mission cancelled'
    MISSION_FAILED = 'mission failed'
