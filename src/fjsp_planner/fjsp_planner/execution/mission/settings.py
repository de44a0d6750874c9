"""How the planner runs missions: the settings the node gives the mission controller."""

from dataclasses import dataclass


@dataclass(frozen=True)
class Settings:
    """How the planner runs missions; the node refreshes them when its parameters change.

    A mission keeps the time limits, start delay, time scale and blocked timeout it started
    with (a goal may set them); the heartbeat, delay, robot wait and plan uptake thresholds
    are always the controller's current ones, so a change applies to the running mission."""

    time_limit: float = 10.0
    replan_time_limit: float = 1.0
    heartbeat_timeout: float = 1.0
    delay_threshold: float = 2.0
    robot_wait_timeout: float = 15.0
    start_delay: float = 0.5
    time_scale: float = 0.05
    blocked_timeout: float = 0.0
    """Seconds a mission may stay blocked before it fails; 0: it waits for the fleet."""
    plan_uptake_timeout: float = 10.0
    """Seconds a robot that reports may stay on an older plan revision than the latest before
    it is planned without, until it reports the latest."""
