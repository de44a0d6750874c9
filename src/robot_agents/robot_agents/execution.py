"""How one robot works through its task sequence, in schedule time, without ROS.

The robot keeps logical time: an operation started at `s` ends at `s + duration`, a leg left
at `d` arrives at `d + leg`, and a job starts when its last robot arrived and its last
predecessor completed. Everyone derives those instants from the same reported facts, so the
robots of a job start at the same schedule time even though each learns of the last arrival a
few milliseconds apart. Wall-clock lateness shows up as a robot acting later than its logical
time, never as a timeline that breaks the schedule's constraints.
"""

import math
from dataclasses import dataclass
from enum import StrEnum

# Reported ends are rounded up onto this grid (schedule units) so that float rounding never
# makes an operation or a leg look shorter than it is when checked in exact arithmetic.
GRID = 1e-6


def later(t: float) -> float:
    """The first grid point at least half a grid step after t."""
    return math.ceil(t / GRID + 0.5) * GRID


class Mode(StrEnum):
    IDLE = 'idle'
    TRAVELLING = 'travelling'
    WAITING = 'waiting'
    WORKING = 'working'
    HOLDING = 'holding'


class EventKind(StrEnum):
    ARRIVED = 'arrived'
    STARTED = 'started'
    OPERATION_DONE = 'operation_done'
    ABORTED = 'aborted'


@dataclass(frozen=True)
class Task:
    """One entry of the robot's sequence, as the plan gives it (schedule units)."""

    job: str
    operation_type: int
    location: str
    travel_start: float
    arrival: float
    start: float
    operation_end: float
    end: float
    co_workers: tuple[str, ...] = ()
    predecessors: tuple[str, ...] = ()
    held_into_next: bool = False

    @property
    def duration(self) -> float:
        return self.operation_end - self.start

    @property
    def leg(self) -> float:
        return self.arrival - self.travel_start


@dataclass(frozen=True)
class Event:
    kind: EventKind
    job: str
    time: float
    attempt: int
    """How many times this robot has begun this job: 1, then 2 if it is redone."""
    reason: str = ''


class _Phase(StrEnum):
    NEXT = 'next'          # choose the next task
    TRAVEL = 'travel'
    WAIT = 'wait'          # at the job, waiting for predecessors and co-workers
    WORK = 'work'
    FINISH = 'finish'      # own operation done, the job's other operations still running
    DONE = 'done'          # sequence exhausted


class RobotExecution:
    """A robot following the latest plan revision it was given.

    Feed it plans (`set_plan`) and the facts other robots and the planner report
    (`arrived`, `operation_done`, `job_done`, `aborted`); `step(now)` moves it as far as
    `now` allows and returns the events it produced.
    """

    def __init__(self, robot: str):
        self.robot = robot
        self.revision = 0
        self.tasks: tuple[Task, ...] = ()
        self.location = ''
        self.destination = ''
        self._phase = _Phase.DONE
        self._index = 0
        self._free_at = 0.0
        self._phase_start = math.nan
        self._phase_end = math.nan
        self._holding = False
        self._job_robots: dict[str, frozenset[str]] = {}
        self._arrived: dict[tuple[str, str], float] = {}
        self._operation_done: dict[tuple[str, str], float] = {}
        self._job_done: dict[str, float] = {}
        self._own_done: set[str] = set()
        self._attempts: dict[str, int] = {}

    # --- what the robot is doing -------------------------------------------------------

    @property
    def task(self) -> Task | None:
        if self._phase in (_Phase.TRAVEL, _Phase.WAIT, _Phase.WORK, _Phase.FINISH):
            return self.tasks[self._index]
        return None

    @property
    def current_job(self) -> str:
        task = self.task
        return task.job if task else ''

    @property
    def mode(self) -> Mode:
        if self._phase == _Phase.TRAVEL:
            return Mode.TRAVELLING
        if self._phase == _Phase.WORK:
            return Mode.WORKING
        if self._phase == _Phase.FINISH:
            return Mode.HOLDING if self.task.held_into_next else Mode.WAITING
        if self._phase == _Phase.WAIT:
            return Mode.HOLDING if self._holding else Mode.WAITING
        return Mode.IDLE

    @property
    def busy_until(self) -> float:
        """When the current leg or operation ends (NaN when waiting or idle)."""
        if self._phase in (_Phase.TRAVEL, _Phase.WORK):
            return self._phase_end
        return math.nan

    def progress(self, now: float) -> float:
        if self._phase not in (_Phase.TRAVEL, _Phase.WORK):
            return 0.0
        span = self._phase_end - self._phase_start
        if span <= 0:
            return 1.0
        return min(1.0, max(0.0, (now - self._phase_start) / span))

    @property
    def finished(self) -> bool:
        return self._phase == _Phase.DONE and self.revision > 0

    # --- inputs ----------------------------------------------------------------------

    def set_plan(self, revision: int, tasks, job_robots, now: float) -> list[Event]:
        """Follow a newer revision from `now`; returns the events it causes (an abort, if any).

        The job the robot is on continues if the new plan still gives it to this robot;
        otherwise the robot leaves it and follows the new sequence from where it is.
        Raises `ValueError` for a revision that is not newer than the one followed.
        """
        if revision <= self.revision:
            raise ValueError(f'plan revision {revision} is not newer than revision '
                             f'{self.revision} already followed')
        tasks = tuple(tasks)
        events = []
        current = self.task
        if self.revision == 0:
            # A robot that joins a running mission cannot have done anything before it did.
            self._free_at = max(self._free_at, now)
        self.revision = revision
        self._job_robots = {job: frozenset(robots) for job, robots in job_robots.items()}
        jobs = [t.job for t in tasks]
        if current is not None and current.job in jobs:
            self.tasks = tasks
            self._index = jobs.index(current.job)
            return events
        if current is not None:
            if self._phase == _Phase.TRAVEL:
                # It cannot vanish mid-leg: it ends the leg, then goes on from there.
                self.location = self.destination
                self._free_at = self._phase_end
            else:
                self._free_at = max(self._free_at, now)
                if self._phase == _Phase.WORK:
                    events.append(Event(EventKind.ABORTED, current.job, now,
                                        self._attempts[current.job],
                                        f'not in plan revision {revision}'))
            self.destination = ''
            self._holding = False
        self.tasks = tasks
        self._index = 0
        self._phase = _Phase.NEXT
        return events

    def arrived(self, robot: str, job: str, time: float) -> None:
        self._arrived.setdefault((robot, job), time)

    def operation_done(self, robot: str, job: str, time: float) -> None:
        self._operation_done.setdefault((robot, job), time)

    def job_done(self, job: str, time: float) -> None:
        self._job_done.setdefault(job, time)

    def aborted(self, job: str) -> None:
        """The job will be redone from scratch: what was reported about it no longer holds."""
        for facts in (self._arrived, self._operation_done):
            for key in [k for k in facts if k[1] == job]:
                del facts[key]
        self._job_done.pop(job, None)
        self._own_done.discard(job)

    # --- stepping --------------------------------------------------------------------

    def step(self, now: float) -> list[Event]:
        """Advance through every transition due by `now` (schedule units)."""
        events = []
        while self._advance(now, events):
            pass
        return events

    def _advance(self, now: float, events: list[Event]) -> bool:
        if self._phase == _Phase.NEXT:
            return self._next()
        if self._phase == _Phase.TRAVEL and now >= self._phase_end:
            task = self.task
            self.location, self.destination = task.location, ''
            self._phase = _Phase.WAIT
            self._arrived.setdefault((self.robot, task.job), self._phase_end)
            events.append(Event(EventKind.ARRIVED, task.job, self._phase_end,
                                self._attempts[task.job]))
            return True
        if self._phase == _Phase.WAIT:
            start = self._start_time(self.task)
            if start is None or now < start:
                return False
            task = self.task
            self._phase, self._holding = _Phase.WORK, False
            self._phase_start, self._phase_end = start, later(start + task.duration)
            events.append(Event(EventKind.STARTED, task.job, start, self._attempts[task.job]))
            return True
        if self._phase == _Phase.WORK and now >= self._phase_end:
            task = self.task
            self._operation_done.setdefault((self.robot, task.job), self._phase_end)
            self._own_done.add(task.job)
            self._phase = _Phase.FINISH
            events.append(Event(EventKind.OPERATION_DONE, task.job, self._phase_end,
                                self._attempts[task.job]))
            return True
        if self._phase == _Phase.FINISH:
            end = self._job_end(self.task.job)
            if end is None or now < end:
                return False
            self._free_at = end
            self._holding = self.task.held_into_next
            self._index += 1
            self._phase = _Phase.NEXT
            return True
        return False

    def _next(self) -> bool:
        while self._index < len(self.tasks) and self._finished(self.tasks[self._index].job):
            self._index += 1
        if self._index >= len(self.tasks):
            self._phase, self._holding = _Phase.DONE, False
            return False
        task = self.tasks[self._index]
        self._attempts[task.job] = self._attempts.get(task.job, 0) + 1
        departure = max(self._free_at, 0.0)
        leg = 0.0 if self._holding or not self.location else max(task.leg, 0.0)
        self._phase = _Phase.TRAVEL
        self._phase_start = departure
        self._phase_end = later(departure + leg) if leg > 0 else departure
        self.destination = task.location
        return True

    def _finished(self, job: str) -> bool:
        return job in self._own_done or job in self._job_done

    def _start_time(self, task: Task) -> float | None:
        """When the job can start: its last robot arrived and last predecessor completed."""
        times = []
        for robot in self._job_robots.get(task.job, frozenset({self.robot})) | {self.robot}:
            if (robot, task.job) not in self._arrived:
                return None
            times.append(self._arrived[robot, task.job])
        for job in task.predecessors:
            end = self._job_end(job)
            if end is None:
                return None
            times.append(end)
        return max(times)

    def _job_end(self, job: str) -> float | None:
        """A job is complete when the planner says so or every robot on it reported done."""
        if job in self._job_done:
            return self._job_done[job]
        robots = self._job_robots.get(job)
        if not robots or any((r, job) not in self._operation_done for r in robots):
            return None
        return max(self._operation_done[r, job] for r in robots)
