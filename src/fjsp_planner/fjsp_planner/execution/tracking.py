"""Mission execution as the planner sees it, from the robots' reports (no ROS).

Times are schedule units since the mission start. The tracker turns task events into the
facts re-planning needs (`execution_state`: done and running jobs, where each robot is and
when it is free, when it last failed), the executed timeline (`executed_schedule`, and what
it breaks: `violations`), a projected makespan and the operations running late (`overruns`),
and which robots failed, even briefly, since a plan revision (`failed_since`). Every report it
cannot use (malformed, out of order, naming what does not exist) is classified and counted,
never raised: a message must not crash the planner.

A plan revision either continues a job (it was under way) or starts it afresh: reports about
a job made under a revision older than the one that last started it no longer count.
"""

import dataclasses
import math
import numbers
from collections import Counter
from dataclasses import dataclass, field
from enum import StrEnum
from fractions import Fraction

from fjsp_common.decimals import decimal, decimals
from fjsp_common.revisions import void
from fjsp_common.vocabulary import EventKind, RobotMode
from fjsp_planner.execution.replan import ExecutionState, RobotSituation, Waypoint
from fjsp_planner.model.limits import shown
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import JobAssignment, Schedule
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.bounds.geometry import location_distance


class Ignored(StrEnum):
    """Why a report was not used."""

    STALE = 'stale'
    DUPLICATE = 'duplicate'
    UNKNOWN = 'unknown'


UNHEALTHY_MODES = frozenset({RobotMode.FAILED, RobotMode.OFFLINE})
ROBOT_EVENTS = frozenset(EventKind) - {EventKind.JOB_DONE}
"""What robots report; only the planner declares a job done."""

MAX_REPORTED_TIME = 1e12
"""No mission within docs/scenario-format.md's limits lasts longer (1000 jobs, each at most
1e6 units of work and 1e6 of travel, delayed up to 1000 times): a later time is a bad report,
and would overflow the solvers when re-planning from it."""


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
    voided_end: float | None = None
    """When its first completion ended, if a re-plan voided it since (a jig job whose hold
    was lost is redone): what followed that completion started after it, rightly."""

    @property
    def start(self) -> float | None:
        return min(self.started.values()) if self.started else None

    @property
    def begun(self) -> bool:
        """A robot started it, or it is done."""
        return bool(self.started) or self.end is not None


@dataclass
class RobotRecord:
    name: str
    mode: str = ''
    location: str = ''
    destination: str = ''
    busy_until: float = math.nan
    progress: float = math.nan
    """Share of the leg from `location` to `destination` behind it (NaN: not said)."""
    current_job: str = ''
    reported: bool = False
    failures: int = 0
    """Transitions from healthy to failed or offline, however brief."""
    last_failure_at: float | None = None
    """When it last became failed or offline (schedule units); None if it never did."""

    @property
    def healthy(self) -> bool:
        """Failed or offline robots are not; one that has not reported yet is taken to be
        (it gets its tasks when it joins)."""
        return self.mode not in UNHEALTHY_MODES


@dataclass(frozen=True)
class Verdict:
    """What became of one report: ignored (with why), or used; maybe completing a job."""

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
        self._repeated: set[str] = set()
        """Reasons of robot states already counted: heartbeats repeat them every period."""
        self._latest = 0.0
        """The latest time any event used reported: dates failures reported without one."""
        self._failures_at: dict[int, dict[str, int]] = {}
        """Plan revision -> each robot's failure count when it was set."""
        self._locations = frozenset(problem.locations())

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
                before = self.jobs.get(name)
                self.jobs[name] = JobRecord(name, since_revision=revision,
                                            voided_end=_first_end(before))
        self.plan, self.revision = schedule, revision
        self._failures_at[revision] = {name: r.failures for name, r in self.robots.items()}

    def failed_since(self, revision: int) -> frozenset[str]:
        """Robots that became failed or offline at least once since plan `revision` was set,
        whether or not they are healthy again. A revision never set (0: before the first
        plan) counts every failure since the tracker began."""
        before = self._failures_at.get(revision, {})
        return frozenset(name for name, r in self.robots.items()
                         if r.failures > before.get(name, 0))

    def extend(self, problem: Problem) -> None:
        """The mission grew to `problem` (jobs added): its new jobs are tracked too."""
        self.problem = problem
        self._locations = set(problem.locations())
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
                     revision: int, time: float) -> Verdict:
        """Use one task event of an agent; classify it if it cannot be used. Never raises,
        whatever the arguments."""
        outcome = self._check_event(event_id, kind, robot, job, revision, time)
        if outcome is None:
            kind = EventKind(kind)
            outcome = self._check_order(event_id, kind, robot, job, time)
        if outcome is not None:
            self.ignored[outcome.ignored] += 1
            return outcome
        self._event_ids.add(event_id)
        self._latest = max(self._latest, time)
        record = self.jobs[job]
        facts = {EventKind.ARRIVED: record.arrived, EventKind.STARTED: record.started,
                 EventKind.OPERATION_DONE: record.operation_done}
        if kind == EventKind.ABORTED:
            if record.end is not None:
                return Verdict()
            self.jobs[job] = JobRecord(job, since_revision=record.since_revision, aborted=True,
                                       voided_end=record.voided_end)
            return Verdict()
        if robot in facts[kind] or record.end is not None:
            self.ignored[Ignored.DUPLICATE] += 1
            return Verdict(Ignored.DUPLICATE, f"'{robot}' already reported {kind} for job "
                                              f"'{job}' (event {shown(event_id)})")
        facts[kind][robot] = time
        if kind == EventKind.OPERATION_DONE:
            robots = self.plan.jobs[job].robots
            if all(r in record.operation_done for r in robots):
                record.end = max(record.operation_done[r] for r in robots)
                planned = self.plan.jobs[job]
                record.done_as = JobAssignment(job, planned.plan, Fraction(record.start),
                                               Fraction(record.end), dict(robots))
                return Verdict(job_done=(job, record.end))
        return Verdict()

    def _check_event(self, event_id, kind, robot, job, revision, time) -> Verdict | None:
        if not isinstance(event_id, str):
            return Verdict(Ignored.UNKNOWN, f'invalid event id {shown(event_id)}')
        what = f'event {shown(event_id)}'      # an id of a megabyte is not logged whole
        if self.plan is None:
            return Verdict(Ignored.STALE, f'{what} arrived before any plan')
        if event_id in self._event_ids:
            return Verdict(Ignored.DUPLICATE, f'{what} was already received')
        if not isinstance(kind, str) or kind not in ROBOT_EVENTS:
            return Verdict(Ignored.UNKNOWN, f'{what} has unknown event kind '
                                            f'{shown(kind)}')
        if not isinstance(robot, str) or robot not in self.robots:
            return Verdict(Ignored.UNKNOWN, f'{what} names unknown robot '
                                            f'{shown(robot)}')
        if not isinstance(job, str) or job not in self.jobs:
            return Verdict(Ignored.UNKNOWN, f'{what} names unknown job '
                                            f'{shown(job)}')
        if isinstance(revision, bool) or not isinstance(revision, int):
            return Verdict(Ignored.UNKNOWN, f'{what} has invalid plan revision '
                                            f'{shown(revision)}')
        if revision > self.revision:
            return Verdict(Ignored.UNKNOWN, f'{what} follows plan revision '
                                            f'{revision}, which was never published '
                                            f'(current: {self.revision})')
        if void(revision, self.jobs[job].since_revision):
            return Verdict(Ignored.STALE, f"{what} follows plan revision "
                                          f"{revision}; revision "
                                          f'{self.jobs[job].since_revision} started '
                                          f"'{job}' afresh")
        if self.jobs[job].aborted:
            return Verdict(Ignored.STALE, f"{what}: job '{job}' was aborted and "
                                          'waits for a new revision to be redone')
        if job not in self.plan.jobs:
            return Verdict(Ignored.STALE, f"{what}: job '{job}' is not in plan "
                                          f'revision {self.revision}, it was done before')
        if robot not in self.plan.jobs[job].robots:
            if revision < self.revision:
                return Verdict(Ignored.STALE, f"{what} follows plan revision "
                                              f'{revision}; in revision {self.revision} '
                                              f"'{robot}' has no part in job '{job}'")
            return Verdict(Ignored.UNKNOWN, f"{what}: robot '{robot}' has no "
                                            f"part in job '{job}'")
        if not _time_ok(time):
            return Verdict(Ignored.UNKNOWN, f'{what} has invalid time '
                                            f'{shown(time)}')
        return None

    def _check_order(self, event_id, kind, robot, job, time) -> Verdict | None:
        """An operation reported done must have been reported started, and not later: the
        job's timeline is built from both (a forged event, or the history of an earlier
        planner arriving after this one's first plan, can break this)."""
        if kind != EventKind.OPERATION_DONE:
            return None
        what = f'event {shown(event_id)}'
        started = self.jobs[job].started.get(robot)
        if started is None:
            return Verdict(Ignored.UNKNOWN, f"{what}: '{robot}' reports "
                                            f"operation_done for job '{job}' without having "
                                            'reported started')
        if time < started:
            return Verdict(Ignored.UNKNOWN, f"{what}: '{robot}' reports "
                                            'operation_done at t={} before it started at '
                                            "t={} (job '{}')".format(*decimals(time, started),
                                                                     job))
        return None

    def record_robot_state(self, robot: str, mode: str, location: str, destination: str,
                           busy_until: float, current_job: str = '',
                           at: float | None = None, progress: float = math.nan) -> Verdict:
        """Use a robot's state report (or heartbeat) observed at schedule time `at`.

        A report that turns a healthy robot failed or offline counts a failure at `at` (by
        default: the latest time any event reported). A `busy_until` that is not a finite
        non-negative number, or a `progress` not within [0, 1], reads as NaN (not said). A
        report naming an unknown robot or place is ignored, and counted once however often it
        repeats. Never raises.
        """
        problem = self._state_problem(robot, mode, location, destination, current_job)
        if problem is not None:
            repeated = problem in self._repeated
            if not repeated:
                self._repeated.add(problem)
                self.ignored[Ignored.UNKNOWN] += 1
            return Verdict(Ignored.UNKNOWN, problem, repeated=repeated)
        record = self.robots[robot]
        was_healthy = record.healthy
        # A robot does not leave its place by restarting its agent, whose new process
        # reports no location until its first leg: the last one reported still holds.
        record.mode, record.destination = mode, destination
        record.location = location or record.location
        record.busy_until = busy_until if _time_ok(busy_until) else math.nan
        record.progress = progress if _share_ok(progress) else math.nan
        record.current_job, record.reported = current_job, True
        self._count_failure(record, was_healthy, at)
        return Verdict()

    def _state_problem(self, robot, mode, location, destination, current_job) -> str | None:
        if not isinstance(robot, str) or robot not in self.robots:
            return f'state of unknown robot {shown(robot)}'
        fields = {'mode': mode, 'location': location, 'destination': destination,
                  'current job': current_job}
        for what, value in fields.items():
            if not isinstance(value, str):
                return f"'{robot}' reports a {what} that is not text: {shown(value)}"
        for what, value in (('location', location), ('destination', destination)):
            if value and value not in self._locations:
                return f"'{robot}' reports unknown {what} {shown(value)}"
        return None

    def mark_offline(self, robot: str, at: float | None = None) -> Verdict:
        """Its heartbeat was lost (observed at schedule time `at`): treated as failed until it
        reports again. Counts a failure like `record_robot_state`."""
        if not isinstance(robot, str) or robot not in self.robots:
            return Verdict(Ignored.UNKNOWN, f'heartbeat loss of unknown robot {shown(robot)}')
        record = self.robots[robot]
        was_healthy = record.healthy
        record.mode = RobotMode.OFFLINE
        self._count_failure(record, was_healthy, at)
        return Verdict()

    def agent_restarted(self, robot: str, at: float | None = None) -> list[str]:
        """The robot's agent restarted (observed at schedule time `at`): the operations its
        previous process had not finished are lost, like a failure's. Those jobs are aborted
        (reports about them wait for a new revision), a hold it kept is lost (a failure is
        counted), and the aborted jobs are returned. Never raises."""
        if not isinstance(robot, str) or robot not in self.robots or self.plan is None:
            return []
        lost = sorted(name for name in self.running
                      if robot in self.plan.jobs[name].robots
                      and robot not in self.jobs[name].operation_done)
        for name in lost:
            self.jobs[name] = JobRecord(name, since_revision=self.jobs[name].since_revision,
                                        aborted=True, voided_end=self.jobs[name].voided_end)
        record = self.robots[robot]
        record.failures += 1
        record.last_failure_at = at if _time_ok(at) else self._latest
        return lost

    def _count_failure(self, record: RobotRecord, was_healthy: bool, at) -> None:
        if was_healthy and not record.healthy:
            record.failures += 1
            record.last_failure_at = at if _time_ok(at) else self._latest

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

    def due_start(self, job: str) -> float | None:
        """When the robots of a job not begun start it, by the reports so far: every robot
        the plan gives it has arrived and every predecessor has completed. None otherwise.
        The robots start it on the same reports, so they may have started it before the
        planner hears of it."""
        record = self.jobs[job]
        planned = self.plan.jobs.get(job) if self.plan is not None else None
        if planned is None or record.begun or record.aborted:
            return None
        if any(robot not in record.arrived for robot in planned.robots):
            return None
        ends = [self.jobs[before].end for before in self.problem.predecessors(job)]
        if None in ends:
            return None
        return max([record.arrived[robot] for robot in planned.robots] + ends)

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
        """Every job of the current plan's end: actual if done, else projected.

        The projection is the plan shifted by what happened (docs/ros-interfaces.md,
        `projected_makespan`). A running job ends at its start plus its planned length, or
        when its robots expect, and not before `now`. A job not begun starts at its planned
        start at the earliest, and not before its predecessors end, nor before each of its
        robots gets there: from its previous job in the plan's order for it (a holder goes
        straight on), or, for its first, from where it is or is going and not before its
        release time, each leg taking its travel time; nor before `now`, unless the reports
        already fix its start. It takes its planned length. So it equals the plan's ends
        while everything runs as planned, and never reads earlier than the plan allows.
        """
        now = Fraction(max(now, 0.0))
        ends: dict[str, Fraction] = {}
        ready = self._robots_free()
        """robot -> (when it is free, where) for its next job of the plan."""
        first = set(self.robots)
        """Robots whose first job of the plan not done is still to come."""
        for name in sorted(self.plan.jobs, key=lambda j: (self.plan.jobs[j].start,
                                                          self.plan.jobs[j].end, j)):
            a, record = self.plan.jobs[name], self.jobs[name]
            here = self.problem.job(name).location
            if record.end is not None:
                end = Fraction(record.end)
            elif record.start is not None:
                end = max(Fraction(record.start) + self._planned_length(name), now,
                          self._reported_end(name))
            else:
                start = self.due_start(name)
                if start is None:
                    arrivals = [self._arrival(robot, ready[robot], name, robot in first)
                                for robot in a.robots]
                    befores = [self._end_of(before, ends)
                               for before in self.problem.predecessors(name)]
                    start = max([now] + arrivals + befores)
                end = max(Fraction(start), a.start) + self._planned_length(name)
            ends[name] = end
            for robot in a.robots:
                ready[robot] = (end, here)
                if record.end is None:
                    first.discard(robot)
        return ends

    def _end_of(self, job: str, projected: dict[str, Fraction]) -> Fraction:
        """A predecessor's end: projected, or as the plan has it until it is, or as it was
        done before the plan; 0 for a job added but not planned yet (it holds nothing up
        that the plan knows of)."""
        if job in projected:
            return projected[job]
        if job in self.plan.jobs:
            return self.plan.jobs[job].end
        end = self.jobs[job].end
        return Fraction(0) if end is None else Fraction(end)

    def _robots_free(self) -> dict[str, tuple[Fraction, str | None]]:
        """When and where each robot is free for the first job the plan gives it: after the
        last job it completed, and not before its release time; where it reported being,
        else where that job or the mission placed it."""
        free = {name: self.problem.robot(name).release_time for name in self.robots}
        for name in self.done:
            a = self.jobs[name].done_as
            for robot in a.robots if a is not None else ():
                free[robot] = max(free[robot], Fraction(self.jobs[name].end))
        return {name: (free[name], r.location or self._last_place(name))
                for name, r in self.robots.items()}

    def _arrival(self, robot: str, ready: tuple[Fraction, str | None], job: str,
                 first: bool) -> Fraction:
        """When `robot` gets to `job`: as it reported, or leaving when and where `ready`
        says. On its way to its first job of the plan not done, it arrives no earlier than
        the leg under way ends, going on from there."""
        record = self.jobs[job]
        if robot in record.arrived:
            return Fraction(record.arrived[robot])
        here = self.problem.job(job).location
        free, there = ready
        arrival = free + (Fraction(0) if there is None
                          else self.problem.travel(robot, there, here))
        state = self.robots[robot]
        if first and state.mode == RobotMode.TRAVELLING and state.destination \
                and math.isfinite(state.busy_until):
            arrival = max(arrival, Fraction(state.busy_until)
                          + self.problem.travel(robot, state.destination, here))
        return arrival

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
                late.append(f"job '{name}' is expected to end at {decimal(expected)}, "
                            f'{decimal(expected - planned)} after its plan')
        return late

    def executed_schedule(self) -> Schedule:
        """The jobs completed so far, as executed: for `validate` and Gantt charts."""
        jobs = {name: self.jobs[name].done_as for name in self.done}
        sequences = {r.name: tuple(sorted((j for j, a in jobs.items() if r.name in a.robots),
                                          key=lambda j: jobs[j].start))
                     for r in self.problem.robots}
        return Schedule(jobs, sequences)

    def execution_state(self, now: float) -> ExecutionState:
        """The state re-planning starts from (`fjsp_planner.execution.replan`)."""
        now_f = Fraction(max(now, 0.0))
        ends = self.expected_ends(now)
        running = {}
        for name in self.running:
            planned = self.plan.jobs[name]
            running[name] = JobAssignment(name, planned.plan, Fraction(self.jobs[name].start),
                                          ends[name], dict(planned.robots))
        robots = {}
        for name, r in self.robots.items():
            robot = self.problem.robot(name)
            on = [j for j, a in running.items() if name in a.robots]
            on_way = None
            if on:
                location, free_at = self.problem.job(on[0]).location, running[on[0]].end
            elif r.mode == RobotMode.TRAVELLING and r.destination:
                arrival = r.busy_until if math.isfinite(r.busy_until) else now
                location, free_at = r.destination, max(Fraction(arrival), now_f)
                on_way = self._on_way(r)
            elif r.healthy and r.location and r.destination:
                # Stopped on a leg (a new plan no longer needed it, or it failed there):
                # it would take the rest of the leg to its destination.
                on_way = self._on_way(r)
                share = on_way.share if on_way is not None else Fraction(0)
                location = r.destination
                free_at = now_f + (1 - share) * self.problem.travel(name, r.location,
                                                                   r.destination)
            else:
                # An agent reports no location until its first leg places it: until then
                # it is where its last job left it (an agent restarted under a planner
                # restarted too), else where the mission starts it.
                location, free_at = r.location or self._last_place(name), now_f
            # Nor is it free before its release time, however idle it looks.
            free_at = max(free_at, Fraction(robot.release_time))
            failed_at = None if r.last_failure_at is None else Fraction(r.last_failure_at)
            robots[name] = RobotSituation(name, r.healthy, location, free_at, failed_at,
                                          on_way)
        done_as = {name: self.jobs[name].done_as for name in self.done
                   if self.jobs[name].done_as is not None}
        return ExecutionState(now_f, self.done, running, robots, done_as)

    @staticmethod
    def _on_way(r: RobotRecord) -> Waypoint | None:
        """The point of its leg a robot has reached, by its last report (None: not said)."""
        if not (r.location and r.destination and r.location != r.destination
                and math.isfinite(r.progress)):
            return None
        return Waypoint.reached(r.location, r.destination, r.progress)

    def _last_place(self, robot: str) -> str | None:
        """Where the last job the robot completed is, else where the mission starts it."""
        done = [a for name in self.done if (a := self.jobs[name].done_as) is not None
                and robot in a.robots]
        if not done:
            return self.problem.robot(robot).start_location
        return self.problem.job(max(done, key=lambda a: a.end).job).location

    def violations(self) -> list[str]:
        """Every way the executed timeline (the jobs done so far, as they ran) breaks the
        mission's problem: precedence, holding arcs, staffing (plans, distinct able robots),
        robots on two jobs at once, travel and release times. Empty: it is valid.

        A mission run across several plan revisions is checked against the problem as
        posed, with two allowances for what execution legitimately changes: operations last
        as long as the agents reported (delay faults lengthen or shorten them), and travel
        between two consecutive jobs of a robot is held to the shortest route between their
        locations, since the robot may have passed through the location of a job that was
        aborted or left out of a new revision on its way.
        """
        executed = self.executed_schedule()
        done = set(executed.jobs)
        messages = []
        for before, after in self.problem.precedence:
            if after in done and before not in done:
                messages.append(f"job '{after}' is done but '{before}', which must complete "
                                'before it, is not')
        for source, target, _ in self.problem.holding:
            if target in done and source not in done:
                messages.append(f"job '{target}' is done but '{source}', which holds into "
                                'it, is not')
        voided = {name: record.voided_end for name, record in self.jobs.items()
                  if record.voided_end is not None}
        return messages + validate(met_before(self._as_executed(executed), executed, voided),
                                   executed)

    def _as_executed(self, executed: Schedule) -> Problem:
        """The problem restricted to the executed jobs, operations free of duration and
        distances relaxed to shortest routes where the direct one does not fit."""
        p = without_durations(self.problem)
        done = set(executed.jobs)
        return dataclasses.replace(
            p, jobs=tuple(j for j in p.jobs if j.name in done),
            precedence=tuple((a, b) for a, b in p.precedence if a in done and b in done),
            holding=tuple((a, b, q) for a, b, q in p.holding if a in done and b in done),
            distances=relaxed_distances(p, executed), fixed={}, panels=(),
            name=f'{p.name} as executed')


def _first_end(record: JobRecord | None) -> float | None:
    """When the job's first completion ended, if it was completed (before being started
    afresh by a new revision, which only a voided job is once done)."""
    if record is None:
        return None
    return record.voided_end if record.voided_end is not None else record.end


def met_before(problem: Problem, executed: Schedule, voided_ends) -> Problem:
    """`problem` without the precedence arcs (a, b) that a voided completion of a met: b
    started no earlier than that completion ended (`voided_ends`: job -> its end), and
    relied on it. A jig job whose hold was lost is redone for the job it holds into, not for
    what already followed it."""
    return dataclasses.replace(problem, precedence=tuple(
        (a, b) for a, b in problem.precedence
        if not (a in voided_ends and b in executed.jobs
                and executed.jobs[b].start >= Fraction(voided_ends[a]))))


def without_durations(problem: Problem) -> Problem:
    """`problem` with every operation free of duration: how a timeline whose operations
    lasted as long as the robots took is judged. Each robot's operations are overridden with
    0 (those of the locomote type too, as the paper's moves are), while travel, which reads
    the robot type's efficiency, keeps its time."""
    return dataclasses.replace(problem, time_overrides={
        **dict.fromkeys(problem.time_overrides, Fraction(0)),
        **{(r.name, q): Fraction(0) for r in problem.robots
           for q in problem.robot_types.get(r.type, {})}})


def relaxed_distances(problem: Problem, executed: Schedule) -> dict:
    """The problem's distances, with the shortest route in place of the direct one between
    two consecutive jobs of a robot that it went between faster than directly: on its way it
    may have passed through the location of a job that was aborted or left out of a new
    revision (a robot withdrawn from a job waits at its location)."""
    legs = set()
    for robot in problem.robots:
        jobs = [executed.jobs[j] for j in executed.sequences.get(robot.name, ())]
        where = robot.start_location
        free = robot.release_time
        for a in jobs:
            here = problem.job(a.job).location
            if where is not None and a.start < free + problem.travel(robot.name, where, here):
                legs.add((where, here))
            where, free = here, a.end
    distances = dict(problem.distances)
    for a, b in legs:
        distances[a, b] = distances[b, a] = location_distance(problem, a, b)
    return distances


def _share_ok(value) -> bool:
    return (isinstance(value, numbers.Real) and not isinstance(value, bool)
            and 0 <= value <= 1)


def _time_ok(value) -> bool:
    """A reported time: a number within [0, MAX_REPORTED_TIME] (not NaN, not infinite)."""
    return (isinstance(value, numbers.Real) and not isinstance(value, bool)
            and 0 <= value <= MAX_REPORTED_TIME)
