"""What the planner node hears from the fleet, as the mission controller takes it."""

import math
from dataclasses import dataclass

from fjsp_common.vocabulary import EventKind, RobotMode


@dataclass(frozen=True)
class RobotReport:
    """One RobotState as the controller needs it."""

    robot: str
    mode: RobotMode
    incarnation: int = 0
    mission_id: str = ''
    revision: int = 0
    refusal: str = ''
    failures: int = 0
    robot_type: str = ''
    location: str = ''
    destination: str = ''
    busy_until: float = math.nan
    progress: float = math.nan
    current_job: str = ''
    last_event: str = ''
    """The id of the latest task event the agent published ('' if none)."""
    refused: int = 0
    """Messages the agent's process has refused as unauthenticated so far."""


@dataclass(frozen=True)
class EventReport:
    """One TaskEvent of an agent."""

    event_id: str
    mission_id: str
    kind: EventKind
    robot: str
    job: str
    revision: int
    time: float
