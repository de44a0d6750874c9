"""Mission execution as the planner sees it, from the robots' reports (no ROS).

Times are schedule units since the mission start. The tracker turns task events into the
facts re-planning needs (`execution_state`: done and running jobs, where each robot is and
when it is free), the executed timeline (`executed_schedule`, checkable by `validate`), a
projected makespan and the operations running late (`overruns`). Every report it cannot use
is classified and counted, never raised.

A plan revision either continues a job (it was under way) or starts it afresh: reports about
a job made under a revision older than the one that last started it no longer count.
"""

import math
from collections import Counter
from dataclasses import dataclass, field
from enum import StrEnum
from fractions import Fraction

from fjsp_common.vocabulary import EventKind, RobotMode
from fjsp_planner.core.problem import Problem
from fjsp_planner.core.replan import ExecutionState, RobotState
from fjsp_planner.core.schedule import JobAssignment, Schedule


class Ignored(StrEnum):
    """Why a report was not used."""

    STALE = 'stale'
    DUPLICATE = 'duplicate'
    UNKNOWN = 'unknown'


@dataclass
class JobRecord:
    """What has been reported about one job since the revision that last started it."""

    name: str
    since_revision: int = 0
    arrived: dict[str, float] = field(default_factory=dict)
    started: dict[str, float] = field(default_factory=dict)
    operation_done: dict[str, float] = field(default_factory=dict)
    end: float | None = None
    aborted: bool = False
    """A robot on it failed while working: it waits for a new revision to be redone."""
    done_as: JobAssignment | None = None
    """The plan and robots it was completed with."""

    @property
    def start(self) -> float | None:
        return min(self.started.values()) if self.started else None


@dataclass
class RobotRecord:
    name: str
    mode: RobotMode | None = None
    """None until it reports."""
    location: str = ''
    destination: str = ''
    busy_until: float = math.nan
    current_job: str = ''
    reported: bool = False

    @property
    def healthy(self) -> bool:
        """Failed or offline robots are not; one that has not reported yet is taken to be
        (it gets its tasks when it joins)."""
        return self.mode is None or self.mode.healthy


@dataclass(frozen=True)
class Outcome:
    """The result of one report: ignored (with why), or used; maybe completing a job."""

    ignored: Ignored | None = None
    reason: str = ''
    job_done: tuple[str, float] | None = None
    repeated: bool = False
    """Ignored for a reason already counted and logged (an unknown robot's heartbeats)."""


class MissionTracker:
    def __init__(self, problem: Problem):
        self.problem = problem
        self.plan: Schedule | None = None
        self.revision = 0
        self.jobs = {j.name: JobRecord(j.name) for j in problem.jobs}
        self.robots = {r.name: RobotRecord(r.name) for r in problem.robots}
        self.ignored = Counter()
        self._event_ids: set[str] = set()
        self._unknown_robots: set[str] = set()

    # --- plans -------------------------------------------------------------------------

    def set_plan(self, schedule: Schedule, revision: int, continued=frozenset()) -> None:
        """Follow a new plan revision.

        Its jobs not `continued` start afresh: what was reported about them is forgotten,
        and reports made under an older revision are ignored from now on. What was reported
        about jobs the revision leaves out (done before it) stays.
        """
        if revision <= self.revision:
            raise ValueError(f'plan revision {revision} is not newer than {self.revision}')
        unknown = sorted(set(continued) - set(schedule.jobs))
        if unknown:
            raise ValueError('continued job(s) not in the plan: ' + ', '.join(unknown))
        for name in schedule.jobs:
            if name not in continued:
                self.jobs[name] = JobRecord(name, since_revision=revision)
        self.plan, self.revision = schedule, revision

    def extend(self, problem: Problem) -> None:
        """The mission grew to `problem` (jobs added): its new jobs are tracked too."""
        self.problem = problem
        for job in problem.jobs:
            self.jobs.setdefault(job.name, JobRecord(job.name, since_revision=self.revision))

    def restore_done(self, assignment: JobAssignment) -> None:
        """A job declared done before the planner restarted, as its journal kept it."""
        record = self.jobs[assignment.job]
        record.started = dict.fromkeys(assignment.robots, float(assignment.start))
        record.operation_done = dict.fromkeys(assignment.robots, float(assignment.end))
        record.end, record.aborted, record.done_as = float(assignment.end), False, assignment

    # --- reports -----------------------------------------------------------------------

    def record_event(self, event_id: str, kind: EventKind, robot: str, job: str,
                     revision: int, time: float) -> Outcome:
        """Use one task event of an agent; classify it if it cannot be used."""
        outcome = self._check_event(event_id, robot, job, revision, time)
        if outcome is not None:
            self.ignored[outcome.ignored] += 1
            return outcome
        self._event_ids.add(event_id)
        record = self.jobs[job]
        facts = {EventKind.ARRIVED: record.arrived, EventKind.STARTED: record.started,
                 EventKind.OPERATION_DONE: record.operation_done}
        if kind == EventKind.ABORTED:
            if record.end is not None:
                return Outcome()
            self.jobs[job] = JobRecord(job, since_revision=record.since_revision, aborted=True)
            return Outcome()
        if robot in facts[kind] or record.end is not None:
            self.ignored[Ignored.DUPLICATE] += 1
            return Outcome(Ignored.DUPLICATE, f"'{robot}' already reported {kind} for job "
                                              f"'{job}' (event '{event_id}')")
        facts[kind][robot] = time
        if kind == EventKind.OPERATION_DONE:
            robots = self.plan.jobs[job].robots
            if all(r in record.operation_done for r in robots):
                record.end = max(record.operation_done[r] for r in robots)
                planned = self.plan.jobs[job]
                record.done_as = JobAssignment(job, planned.plan, Fraction(record.start),
                                               Fraction(record.end), dict(robots))
                return Outcome(job_done=(job, record.end))
        return Outcome()

    def _check_event(self, event_id, robot, job, revision, time) -> Outcome | None:
        if self.plan is None:
            return Outcome(Ignored.STALE, f"event '{event_id}' arrived before any plan")
        if event_id in self._event_ids:
            return Outcome(Ignored.DUPLICATE, f"event '{event_id}' was already received")
        if robot not in self.robots:
            return Outcome(Ignored.UNKNOWN, f"event '{event_id}' names unknown robot "
                                            f"'{robot}'")
        if job not in self.jobs:
            return Outcome(Ignored.UNKNOWN, f"event '{event_id}' names unknown job '{job}'")
        if revision > self.revision:
            return Outcome(Ignored.UNKNOWN, f"event '{event_id}' follows plan revision "
                                            f'{revision}, which was never published '
                                            f'(current: {self.revision})')
        if revision < self.jobs[job].since_revision:
            return Outcome(Ignored.STALE, f"event '{event_id}' follows plan revision "
                                          f"{revision}; revision "
                                          f'{self.jobs[job].since_revision} started '
                                          f"'{job}' afresh")
        if self.jobs[job].aborted:
            return Outcome(Ignored.STALE, f"event '{event_id}': job '{job}' was aborted and "
                                          'waits for a new revision to be redone')
        if job not in self.plan.jobs:
            return Outcome(Ignored.STALE, f"event '{event_id}': job '{job}' is not in plan "
                                          f'revision {self.revision}, it was done before')
        if robot not in self.plan.jobs[job].robots:
            if revision < self.revision:
                return Outcome(Ignored.STALE, f"event '{event_id}' follows plan revision "
                                              f'{revision}; in revision {self.revision} '
                                              f"'{robot}' has no part in job '{job}'")
            return Outcome(Ignored.UNKNOWN, f"event '{event_id}': robot '{robot}' has no "
                                            f"part in job '{job}'")
        if not math.isfinite(time) or time < 0:
            return Outcome(Ignored.UNKNOWN, f"event '{event_id}' has invalid time {time}")
        return None

    def record_robot_state(self, robot: str, mode: RobotMode, location: str, destination: str,
                           busy_until: float, current_job: str = '') -> Outcome:
        if robot not in self.robots:
            repeated = robot in self._unknown_robots
            if not repeated:
                self._unknown_robots.add(robot)
                self.ignored[Ignored.UNKNOWN] += 1
            return Outcome(Ignored.UNKNOWN, f"state of unknown robot '{robot}'",
                           repeated=repeated)
        self.robots[robot] = RobotRecord(robot, RobotMode(mode), location, destination, busy_until,
                                         current_job, True)
        return Outcome()

    def mark_offline(self, robot: str) -> None:
        """Its heartbeat was lost: treated as failed until it reports again."""
        self.robots[robot].mode = RobotMode.OFFLINE

    # --- what the reports add up to ------------------------------------------------------

    @property
    def missing_robots(self) -> list[str]:
        return [name for name, r in self.robots.items() if not r.reported]

    @property
    def done(self) -> frozenset[str]:
        return frozenset(name for name, r in self.jobs.items() if r.end is not None)

    @property
    def running(self) -> frozenset[str]:
        return frozenset(name for name, r in self.jobs.items()
                         if r.end is None and r.started)

    @property
    def aborted(self) -> frozenset[str]:
        return frozenset(name for name, r in self.jobs.items() if r.aborted)

    @property
    def healthy(self) -> frozenset[str]:
        return frozenset(name for name, r in self.robots.items() if r.healthy)

    @property
    def complete(self) -> bool:
        return all(r.end is not None for r in self.jobs.values())

    def _planned_length(self, job: str) -> Fraction:
        a = self.plan.jobs[job]
        return a.end - a.start

    def expected_ends(self, now: float) -> dict[str, Fraction]:
        """Every job's end: actual if done, else projected by shifting the rest of the plan.

        Jobs not started begin as soon as their predecessors complete and their robots are
        free and have travelled there, but not before `now`; each takes its planned length.
        """
        now = Fraction(max(now, 0.0))
        ends: dict[str, Fraction] = {}
        robot_free: dict[str, tuple[Fraction, str | None]] = {}
        for name in sorted(self.plan.jobs, key=lambda j: (self.plan.jobs[j].start,
                                                          self.plan.jobs[j].end, j)):
            a, record = self.plan.jobs[name], self.jobs[name]
            if record.end is not None:
                end = Fraction(record.end)
            elif record.start is not None:
                end = max(Fraction(record.start) + self._planned_length(name), now,
                          self._reported_end(name))
            else:
                start = now
                for before in self.problem.predecessors(name):
                    start = max(start, ends.get(before, now))
                here = self.problem.job(name).location
                for robot in a.robots:
                    free, there = robot_free.get(robot, (Fraction(0), None))
                    travel = Fraction(0) if there is None else self.problem.travel(
                        robot, there, here)
                    start = max(start, free + travel)
                end = start + self._planned_length(name)
            ends[name] = end
            for robot in a.robots:
                robot_free[robot] = (end, self.problem.job(name).location)
        return ends

    def _reported_end(self, job: str) -> Fraction:
        """The latest end its working robots expect for their operations (0: none said)."""
        ends = [Fraction(r.busy_until) for r in self.robots.values()
                if r.current_job == job and r.mode == RobotMode.WORKING
                and math.isfinite(r.busy_until) and r.name not in self.jobs[job].operation_done]
        return max(ends, default=Fraction(0))

    def projected_makespan(self, now: float) -> Fraction:
        ends = list(self.expected_ends(now).values())
        ends += [Fraction(r.end) for r in self.jobs.values() if r.end is not None]
        return max(ends, default=Fraction(0))

    def overruns(self, threshold: float) -> list[str]:
        """Running jobs whose robots expect to end more than `threshold` after the plan said.

        Only the robots' reported expected ends count: a clock running ahead of delayed
        messages is no overrun. The plan's end is taken from the job's actual start, so a job
        that merely started late is not overrunning; a re-plan makes the expected end the
        planned one.
        """
        late = []
        for name in sorted(self.running):
            record = self.jobs[name]
            planned = max(self.plan.jobs[name].end,
                          Fraction(record.start) + self._planned_length(name))
            expected = self._reported_end(name)
            if expected - planned > threshold:
                late.append(f"job '{name}' is expected to end at {float(expected):.2f}, "
                            f'{float(expected - planned):.2f} after its plan')
        return late

    def executed_schedule(self) -> Schedule:
        """The jobs completed so far, as executed: for `validate` and Gantt charts."""
        jobs = {name: self.jobs[name].done_as for name in self.done}
        sequences = {r.name: tuple(sorted((j for j, a in jobs.items() if r.name in a.robots),
                                          key=lambda j: jobs[j].start))
                     for r in self.problem.robots}
        return Schedule(jobs, sequences)

    def execution_state(self, now: float) -> ExecutionState:
        """The state re-planning starts from (`fjsp_planner.core.replan`)."""
        now_f = Fraction(max(now, 0.0))
        ends = self.expected_ends(now)
        running = {}
        for name in self.running:
            planned = self.plan.jobs[name]
            running[name] = JobAssignment(name, planned.plan, Fraction(self.jobs[name].start),
                                          ends[name], dict(planned.robots))
        robots = {}
        for name, r in self.robots.items():
            on = [j for j, a in running.items() if name in a.robots]
            if on:
                location, free_at = self.problem.job(on[0]).location, running[on[0]].end
            elif r.mode == RobotMode.TRAVELLING and r.destination:
                arrival = r.busy_until if math.isfinite(r.busy_until) else now
                location, free_at = r.destination, max(Fraction(arrival), now_f)
            else:
                location, free_at = r.location or None, now_f
            robots[name] = RobotState(name, r.healthy, location, free_at)
        return ExecutionState(now_f, self.done, running, robots)
