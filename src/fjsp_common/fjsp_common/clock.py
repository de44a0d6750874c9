"""One mission's clock: wall seconds and schedule units, as every node of the fleet reads them.

A plan says when schedule time 0 is (`Plan.mission_start`, wall seconds) and how many wall
seconds a schedule unit lasts (`Plan.time_scale`). The planner judges reports, the agents act,
and monitors, recordings and tests place what they hear on the schedule by this one clock.
Free of ROS: wall seconds are plain floats here, converted from stamps by the caller.
"""

from dataclasses import dataclass


def seconds(stamp) -> float:
    """A `builtin_interfaces/Time` (anything with `sec` and `nanosec`) as wall seconds."""
    return stamp.sec + stamp.nanosec * 1e-9


@dataclass(frozen=True)
class ScheduleClock:
    mission_start: float
    """Wall seconds of schedule time 0."""
    time_scale: float
    """Wall seconds per schedule unit (positive)."""

    def units(self, wall: float) -> float:
        """Schedule time at wall time `wall` (negative before the mission start)."""
        return (wall - self.mission_start) / self.time_scale

    def wall(self, units: float) -> float:
        """Wall time at schedule time `units`."""
        return self.mission_start + units * self.time_scale
