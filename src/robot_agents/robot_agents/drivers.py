"""The physical part of a robot, behind its agent: travel to a place, perform an operation,
stop (docs/robot-drivers.md). No ROS.

The agent (`execution.RobotExecution`) keeps the plan's semantics: which task comes next,
when a job may start, who holds what. It hands each leg and each operation to its driver and
asks it, as time passes, whether it has ended and how long it took. A driver reports
durations, not instants: the agent places a duration at the leg's or operation's start in
schedule time, as the robots of a job agree on it, so that every robot derives the same
instants from the same reports, and a robot that learns of something late acts late but never
reports a timeline that breaks the plan's constraints.

`MockDriver` is the timed robot every agent had before drivers: each leg and operation takes
exactly the time the plan gives it. `robot_agents.action_driver` sends them to the robot's own
ROS 2 action servers instead.
"""

import math
from dataclasses import dataclass
from typing import Protocol

GRID = 1e-6
"""Reported ends are rounded up onto this grid (schedule units) so that float rounding never
makes an operation or a leg look shorter than it is when checked in exact arithmetic."""


def later(t: float) -> float:
    """The first grid point at least half a grid step after t; t itself where t is not finite
    or too large for the grid to mean anything. Never raises."""
    scaled = t / GRID + 0.5
    if not math.isfinite(scaled):
        return t
    return max(t, math.ceil(scaled) * GRID)


@dataclass(frozen=True)
class Leg:
    """A leg of the robot's way, as the plan gives it (schedule units)."""

    job: str
    """The job it goes to."""
    origin: str
    """The place it leaves ('' for a robot no leg has placed yet)."""
    destination: str
    duration: float
    """The plan's travel time."""


@dataclass(frozen=True)
class Operation:
    """The robot's operation in a job, as the plan gives it (schedule units)."""

    job: str
    operation_type: int
    operation_name: str
    location: str
    co_workers: tuple[str, ...]
    duration: float
    """The plan's time for it, times any delay injected."""


@dataclass(frozen=True)
class Ending:
    """How the leg or operation under way ended."""

    end: float
    """Schedule time it ended: its start plus the time the robot took (grid-rounded up)."""
    failure: str = ''
    """Why the robot cannot go on ('' when it arrived or the operation is done)."""
    share: float = 1.0
    """Share of it done: of a leg, how far the robot got before it failed."""


class Driver(Protocol):
    """What the agent asks of the robot. Times are schedule units.

    One leg or operation at a time: `begin` it, poll `ending` until it says how it ended,
    or `stop` it first (then it never ends). `start` is when it begins in schedule time: the
    instant the plan's semantics give it (a leg's departure, a job's start), never after the
    call."""

    ends_when_expected: bool
    """True when every leg and operation ends at `expected_end()` (the agent sleeps until
    then); False when only `ending` can tell (the agent polls it)."""

    def begin(self, work: Leg | Operation, start: float) -> None:
        """Set off on a leg, or begin an operation."""

    def ending(self, now: float) -> Ending | None:
        """How the leg or operation begun last ended, once it has by `now`; None while it
        goes on (and after `stop`)."""

    def stop(self, now: float) -> float:
        """Stop the leg or operation under way at once, where the robot is; the share of it
        done (0..1)."""

    def progress(self, now: float) -> float:
        """Share (0..1) of the leg or operation under way done by `now`."""

    def expected_end(self) -> float:
        """When the leg or operation under way is expected to end (schedule time)."""

    def retime(self, duration: float, now: float) -> bool:
        """The operation under way is to last `duration` from its start, ending no earlier
        than `now` (a delay fault). False when the robot decides how long its operations
        take: the fault is refused."""


class MockDriver:
    """A robot that takes exactly the planned time for every leg and operation, and never
    fails of itself (faults are injected into the agent)."""

    ends_when_expected = True

    def __init__(self):
        self._start = math.nan
        self._end = math.nan
        self._active = False

    def begin(self, work: Leg | Operation, start: float) -> None:
        self._start, self._end, self._active = start, later(start + work.duration), True

    def ending(self, now: float) -> Ending | None:
        if not self._active or now < self._end:
            return None
        self._active = False
        return Ending(self._end)

    def stop(self, now: float) -> float:
        share = self.progress(now)
        self._active = False
        return share

    def progress(self, now: float) -> float:
        span = self._end - self._start
        if span <= 0:
            return 1.0
        return min(1.0, max(0.0, (now - self._start) / span))

    def expected_end(self) -> float:
        return self._end

    def retime(self, duration: float, now: float) -> bool:
        self._end = later(max(self._start + duration, now))
        return True
