"""How one robot works through its task sequence, in schedule time, without ROS.

The physical part (travel, operations, stopping) goes to a driver (`drivers`): the timed
`MockDriver` by default, or the robot's own actions. The robot keeps logical time: a leg left
at `d` that the driver says took `t` arrives at `d + t`, an operation started at `s` that took
`T` ends at `s + T`, and a job starts when its last robot arrived and its last predecessor
completed (for a predecessor done by other robots only, once the planner declared it done, so
that no robot acts on a completion the planner missed). Everyone derives those instants from
the same reported facts, so the robots of a job start at the same schedule time even though
each learns of the last arrival a few milliseconds apart. Wall-clock lateness shows up as a
robot acting later than its logical time, never as a timeline that breaks the schedule's
constraints. What the robot learns at `now` (a new plan, a recovery) cannot make it act before
`now`.

A leg no task needs any more (a new revision sends the robot elsewhere, or it failed on the
way) is stopped where the robot is: it then stands between two places, reported as its
`location` (where the leg began), `destination` and `progress` (the share of the leg behind
it), and leaves from there with the leg the next plan gives it, which the planner computed
from that point (docs/robot-drivers.md, "Stopping mid-leg").

Every fact carries the plan revision it was reported under. A revision that restarts a job
(its task is not `continued`) voids what older revisions reported about it: the job is redone
from scratch, so its old arrivals and completions must not start or end the new attempt. Each
task also names the revision that last restarted its job (`restarted_in`), so a robot that
missed that revision, and gets a later one continuing the job, voids the same facts.
"""

import math
from dataclasses import dataclass, field
from enum import StrEnum

from fjsp_common.revisions import Restarts, void
from fjsp_common.vocabulary import MAX_DELAY_FACTOR, MIN_DELAY_FACTOR, EventKind, RobotMode
from robot_agents.drivers import Driver, Ending, Leg, MockDriver, Operation


def _within_delay_bounds(factor: float) -> bool:
    return MIN_DELAY_FACTOR <= factor <= MAX_DELAY_FACTOR


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
    operation_name: str = ''

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


@dataclass(frozen=True)
class FaultResult:
    """The answer to an injected fault: refused faults change nothing."""

    accepted: bool
    message: str
    """What happened, or why not; names the robot and the fault."""
    events: list[Event] = field(default_factory=list)
    """Events due by the fault's time, then the fault's own (an abort)."""


@dataclass(frozen=True)
class _Fact:
    time: float
    revision: int
    """The plan revision it was reported under."""


class _Phase(StrEnum):
    NEXT = 'next'          # choose the next task
    TRAVEL = 'travel'      # to the current task's location
    TRANSIT = 'transit'    # ending a leg whose end is still needed, though not for its task
    WAIT = 'wait'          # at the job, waiting for predecessors and co-workers
    WORK = 'work'
    FINISH = 'finish'      # own operation done, the job's other operations still running
    DONE = 'done'          # sequence exhausted
    FAILED = 'failed'


class RobotExecution:
    """A robot following the latest plan revision it was given.

    Feed it plans (`set_plan`), the facts other robots and the planner report (`arrived`,
    `operation_done`, `job_done`, `aborted`) and faults (`fail`, `recover`, `delay`);
    `step(now)` moves it as far as `now` and its driver allow and returns the events it
    produced. A failure its driver reports (`Ending.failure`) fails the robot as an injected
    one does; `failures()` hands out the messages of those.
    """

    def __init__(self, robot: str, driver: Driver | None = None):
        self.robot = robot
        self.driver = driver if driver is not None else MockDriver()
        self.revision = 0
        self.tasks: tuple[Task, ...] = ()
        self.location = ''
        self.destination = ''
        self._phase = _Phase.DONE
        self._index = 0
        self._free_at = 0.0
        self._not_before = 0.0
        """When the latest plan arrived: nothing it orders can begin earlier."""
        self._departed = False
        """Whether it has set off for its first job of the mission (its departure came)."""
        self._phase_start = math.nan
        """When the leg or operation under way began, or the leg is to begin."""
        self._leg: Leg | None = None
        """The leg under way (None: a leg of no length, or none)."""
        self._begun = False
        """Whether the driver has the leg or operation under way."""
        self._stopped: tuple[Leg, float] | None = None
        """The leg it stopped on (failed, or no longer needed) and the share of it behind it:
        it stands between `location` and `destination`."""
        self._holding = ''
        """The done jig job whose part the robot holds into its next job ('' if none)."""
        self._finishing = ''
        """The job whose operation it has done while others still work on it ('' if none):
        it stays there until the job completes, even when a fault or a new plan takes the job
        off its sequence, as the planner plans it free only at the job's end."""
        self._factor = 1.0
        """Duration factor of the next operation the robot begins (delay faults)."""
        self._work_factor = 1.0
        self._driver_failures: list[str] = []
        self._job_robots: dict[str, frozenset[str]] = {}
        self._arrived: dict[tuple[str, str], _Fact] = {}
        self._operation_done: dict[tuple[str, str], _Fact] = {}
        self._job_done: dict[str, _Fact] = {}
        self._restarts = Restarts()
        """The latest revision that restarted each job: older reports about it are void."""
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
        if task is not None:
            return task.job
        return self._finishing if self._phase == _Phase.NEXT else ''

    @property
    def mode(self) -> RobotMode:
        if self._phase == _Phase.FAILED:
            return RobotMode.FAILED
        if self._phase in (_Phase.TRAVEL, _Phase.TRANSIT):
            return RobotMode.TRAVELLING
        if self._phase == _Phase.WORK:
            return RobotMode.WORKING
        if self._phase == _Phase.FINISH:
            return RobotMode.HOLDING if self.task.held_into_next else RobotMode.WAITING
        if self._phase == _Phase.WAIT:
            return RobotMode.HOLDING if self._holding else RobotMode.WAITING
        if self._phase == _Phase.NEXT and self._finishing:
            return RobotMode.WAITING
        return RobotMode.IDLE

    @property
    def busy_until(self) -> float:
        """When the current leg or operation ends (NaN when waiting, idle or failed)."""
        if self._phase in (_Phase.TRAVEL, _Phase.TRANSIT, _Phase.WORK):
            if self._begun:
                return self.driver.expected_end()
            return self._phase_start + (self._leg.duration if self._leg else 0.0)
        return math.nan

    def due(self) -> float | None:
        """The schedule time at which `step` next has something to do by itself: a departure,
        the end of the leg or operation under way, a job's start or end as the reported facts
        fix it; `math.inf` when only a new plan, fact or fault can move the robot; None while
        only its driver can tell when the work under way ends (`step` must be polled)."""
        phase = self._phase
        if phase in (_Phase.TRAVEL, _Phase.TRANSIT, _Phase.WORK):
            if not self._begun:
                return self._phase_start
            return self.driver.expected_end() if self.driver.ends_when_expected else None
        if phase == _Phase.WAIT:
            when = self._start_time(self.task)
        elif phase == _Phase.FINISH:
            when = self._job_end(self.task.job)
        else:
            return math.inf
        return math.inf if when is None else when

    def progress(self, now: float) -> float:
        """0..1 of the current leg or operation; of the leg it stopped on, if it stands
        between two places."""
        if self._stopped is not None:
            return self._stopped[1]
        if self._phase in (_Phase.TRAVEL, _Phase.TRANSIT, _Phase.WORK) and self._begun:
            return self.driver.progress(now)
        return 0.0

    @property
    def finished(self) -> bool:
        return self._phase == _Phase.DONE and self.revision > 0

    def failures(self) -> list[str]:
        """What the driver reported as robot failures since the last call, one message each
        (the robot is FAILED since the first)."""
        reported, self._driver_failures = self._driver_failures, []
        return reported

    # --- plans -----------------------------------------------------------------------

    def set_plan(self, revision: int, tasks, job_robots, now: float, *, restarted_in,
                 start_location: str = '') -> None:
        """Follow a newer revision from `now`.

        `start_location` is where the plan has the robot before its first task ('' if it may
        start anywhere): a robot no leg has placed yet is there, one placed stays where its
        own legs took it.

        `job_robots` maps every job of the plan to its robots; `restarted_in` maps a job to
        the revision that last started it afresh: an older one for a job that goes on as it
        is (continued), `revision` itself (the default) for a job that starts afresh. What
        revisions older than that one reported about a job is dropped, and later reports of
        theirs are ignored, whichever revisions in between this robot missed (it then redoes
        its part of a job restarted in one of them).
        The robot goes on with its current job only if that job is continued and
        is the first unfinished task of its new sequence. Otherwise it abandons the job it was
        on without an event (the planner ordered it), stopping an operation under way, and
        follows the new sequence: on a leg to where its new first task is, it ends the leg;
        on any other leg it stops where it is, and leaves from there. A failed robot takes
        the revision but does nothing.
        Raises `ValueError` for a revision that is not newer than the one followed.
        """
        if revision <= self.revision:
            raise ValueError(f'plan revision {revision} is not newer than revision '
                             f'{self.revision} already followed')
        tasks = tuple(tasks)
        if not self.location and not self._on_a_leg:
            self.location = start_location
        current = self.task
        previous, self.revision = self.revision, revision
        self._job_robots = {job: frozenset(robots) for job, robots in job_robots.items()}
        self._not_before = max(self._not_before, now)
        continued = set()
        for job in set(self._job_robots) | {t.job for t in tasks}:
            since = min(restarted_in.get(job, revision), revision)
            if since <= previous:  # else restarted in a revision this robot missed
                continued.add(job)
            self._restart(job, since)
        self.tasks = tasks
        if self._phase == _Phase.FAILED:
            self._index = 0
            return
        index = self._continued_index(current, continued)
        if index is not None:
            self._index = index
            return
        if not self._still_holding():
            self._holding = ''
        self._index = 0
        if self._on_a_leg:
            first = next((t for t in tasks if not self._finished(t.job)), None)
            if first is not None and first.location == self.destination:
                self._phase = _Phase.TRANSIT
            else:
                self._stop(now)
            return
        if self._phase == _Phase.WORK and self._begun:
            self.driver.stop(now)
            self._free_at = now
        if self._stopped is None:
            self.destination = ''
        self._phase = _Phase.NEXT

    @property
    def _on_a_leg(self) -> bool:
        """Under way between two places (a leg of no length, or not begun yet, is not)."""
        return self._phase in (_Phase.TRAVEL, _Phase.TRANSIT) and self._begun

    def _stop(self, now: float) -> None:
        """Stop the leg under way where the robot is; it is free from `now`."""
        share = self.driver.stop(now)
        if share > 0:
            self._stopped = (self._leg, share)
        else:
            self.destination = ''
        self._begun, self._free_at, self._phase = False, now, _Phase.NEXT

    def _continued_index(self, current: Task | None, continued) -> int | None:
        """Where the current job is in the new sequence, if the robot goes on with it."""
        if current is None or current.job not in continued:
            return None
        for i, task in enumerate(self.tasks):
            if task.job == current.job:
                return i
            if not self._finished(task.job):
                return None
        return None

    def _still_holding(self) -> bool:
        """The new sequence keeps the held jig job, done, right before its first open task."""
        for before, task in zip((None, *self.tasks), self.tasks, strict=False):
            if not self._finished(task.job):
                return (before is not None and before.job == self._holding
                        and before.held_into_next)
        return False

    def _restart(self, job: str, revision: int) -> None:
        if self._restarts.restart(job, revision):
            self._forget(job, lambda fact: void(fact.revision, revision))

    def _forget(self, job: str, stale) -> None:
        """Drop the facts about `job` for which `stale(fact)` holds."""
        for facts in (self._arrived, self._operation_done):
            for key in [k for k, fact in facts.items() if k[1] == job and stale(fact)]:
                del facts[key]
        if job in self._job_done and stale(self._job_done[job]):
            del self._job_done[job]

    # --- facts reported by the others ------------------------------------------------

    def arrived(self, robot: str, job: str, time: float, revision: int) -> bool:
        """Record a report; False if it was ignored as a report about a restarted job."""
        return self._record(self._arrived, (robot, job), job, time, revision)

    def operation_done(self, robot: str, job: str, time: float, revision: int) -> bool:
        return self._record(self._operation_done, (robot, job), job, time, revision)

    def job_done(self, job: str, time: float, revision: int) -> bool:
        return self._record(self._job_done, job, job, time, revision)

    def aborted(self, job: str, revision: int) -> bool:
        """The job will be redone from scratch: what was reported about it no longer holds."""
        if self._restarts.void(job, revision):
            return False
        self._forget(job, lambda fact: fact.revision <= revision)
        return True

    def _record(self, facts, key, job: str, time: float, revision: int) -> bool:
        if self._restarts.void(job, revision):
            return False
        # Of two reports of the same fact the first counts, unless the other one comes from a
        # newer revision (a robot redoing a restarted job may report before this robot
        # learns of the restart).
        known = facts.get(key)
        if known is None or revision > known.revision:
            facts[key] = _Fact(time, revision)
        return True

    # --- faults ----------------------------------------------------------------------

    def fail(self, now: float) -> FaultResult:
        """Stop at `now`: abort the operation under way; a leg stops where the robot is."""
        if self._phase == _Phase.FAILED:
            return self._refuse('fail', 'has already failed')
        events = self.step(now)
        if self._phase == _Phase.FAILED:        # its driver reported a failure meanwhile
            return self._refuse('fail', 'has already failed', events)
        message = self._fail(now, f"robot '{self.robot}' failed", events)
        return FaultResult(True, f"robot '{self.robot}' failed at t={now:.2f}{message}",
                           events)

    def _fail(self, now: float, reason: str, events: list[Event]) -> str:
        """Go FAILED at `now`; what it dropped, for a message."""
        message = ''
        if self._phase in (_Phase.WORK, _Phase.WAIT):
            # At a job not begun yet, its arrival would let its co-workers start without it.
            job = self.task.job
            events.append(Event(EventKind.ABORTED, job, now, self._attempts[job], reason))
            self.aborted(job, self.revision)
            message = (f", aborting its operation of job '{job}'" if self._phase == _Phase.WORK
                       else f", withdrawing from job '{job}' it was waiting for")
        if self._on_a_leg:
            self._stop(now)
        elif self._phase == _Phase.WORK and self._begun:
            self.driver.stop(now)
        if self._stopped is not None:
            message += (f" on its way from '{self.location}' to '{self.destination}' "
                        f'({self._stopped[1]:.0%} done)')
        else:
            self.destination = ''
            message += f" at '{self.location}'" if self.location else ''
        self._phase, self._holding = _Phase.FAILED, ''
        self._begun = False
        return message

    def recover(self, now: float) -> FaultResult:
        """Back in service at `now` where it stopped (on a leg too), its old tasks dropped."""
        if self._phase != _Phase.FAILED:
            return self._refuse('recover', 'has not failed')
        # The planner re-plans on a recovery; until then the robot has nothing to do.
        self.tasks, self._index, self._free_at = (), 0, now
        self._phase = _Phase.NEXT
        message = f"robot '{self.robot}' recovered at t={now:.2f}"
        if self._stopped is not None:
            message += (f" on its way from '{self.location}' to '{self.destination}' "
                        f'({self._stopped[1]:.0%} done)')
        elif self.location:
            message += f" at '{self.location}'"
        return FaultResult(True, message)

    def delay(self, factor: float, now: float) -> FaultResult:
        """Multiply the duration of the operation under way, or else of the next one.

        The factor, and the product of the factors on one operation, must lie within
        [MIN_DELAY_FACTOR, MAX_DELAY_FACTOR]; beyond, the delay is refused, as is one of the
        operation under way when its driver cannot be told (the robot decides).
        """
        if not _within_delay_bounds(factor):       # NaN fails every comparison
            return self._refuse('delay', f'a delay factor must be within '
                                         f'[{MIN_DELAY_FACTOR:g}, {MAX_DELAY_FACTOR:g}], '
                                         f'got {factor:g}')
        if self._phase == _Phase.FAILED:
            return self._refuse('delay', 'has failed')
        events = self.step(now)
        if self._phase == _Phase.FAILED:
            return self._refuse('delay', 'has failed', events)
        working = self._phase == _Phase.WORK
        if not working and not self._work_left():
            return self._refuse('delay', 'has no operation left to do', events)
        product = (self._work_factor if working else self._factor) * factor
        if not _within_delay_bounds(product):
            return self._refuse('delay', f'would make its operation take {product:g} times '
                                         'its duration; the factors on one operation must '
                                         f'multiply to within [{MIN_DELAY_FACTOR:g}, '
                                         f'{MAX_DELAY_FACTOR:g}]', events)
        if working:
            # A speed-up cannot end the operation before it was ordered.
            if not self.driver.retime(self.task.duration * product, now):
                return self._refuse('delay', 'runs its operation on its own timing: the '
                                             'operation under way cannot be retimed', events)
            self._work_factor = product
            return FaultResult(True, f"robot '{self.robot}': operation of job "
                                     f"'{self.task.job}' now ends at t={self.busy_until:.2f}",
                               events)
        self._factor = product
        return FaultResult(True, f"robot '{self.robot}': the next operation it begins takes "
                                 f'{self._factor:g} times its duration', events)

    def _refuse(self, fault: str, why: str, events=()) -> FaultResult:
        return FaultResult(False, f"{fault} refused: robot '{self.robot}' {why}", list(events))

    def _work_left(self) -> bool:
        after = self._index + 1 if self._phase == _Phase.FINISH else self._index
        return any(not self._finished(t.job) for t in self.tasks[after:])

    # --- missions --------------------------------------------------------------------

    def cancel(self, now: float, reason: str) -> list[Event]:
        """The mission was cancelled at `now`: every task is dropped and a hold released; a
        job the robot is at (waiting, working or finishing) is reported ABORTED with `reason`,
        its operation stopped. A leg under way is finished first, as a robot cannot vanish
        mid-leg."""
        events = self.step(now)
        task = self.task
        if task is not None and self._phase in (_Phase.WAIT, _Phase.WORK, _Phase.FINISH):
            events.append(Event(EventKind.ABORTED, task.job, now, self._attempts[task.job],
                                reason))
        if self._phase == _Phase.WORK and self._begun:
            self.driver.stop(now)
            self._begun = False
        self.tasks, self._index, self._holding, self._finishing = (), 0, '', ''
        if self._on_a_leg:
            self._phase = _Phase.TRANSIT
        elif self._phase != _Phase.FAILED:
            self._phase, self._free_at = _Phase.DONE, now
            if self._stopped is None:
                self.destination = ''
        return events

    def start_mission(self) -> None:
        """Forget the previous mission (its plans, facts and clock), keeping the driver,
        where the robot is and whether it has failed. A leg still under way, or stopped,
        counts as arrived, and a robot failed mid-leg stays where the leg began: the new
        mission plans from there."""
        failed = self._phase == _Phase.FAILED
        here = self.location
        if not failed and (self._on_a_leg or self._stopped is not None) and self.destination:
            here = self.destination
        self.__init__(self.robot, self.driver)
        self.location = here
        if failed:
            self._phase = _Phase.FAILED

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
        if self._phase in (_Phase.TRAVEL, _Phase.TRANSIT):
            arrival = self._arrival(now, events)
            if arrival is None:
                return False
            self.location, self.destination, self._leg = self.destination, '', None
            if self._phase == _Phase.TRANSIT:
                self._free_at = arrival
                self._phase = _Phase.NEXT
                return True
            task = self.task
            self._phase = _Phase.WAIT
            self._record(self._arrived, (self.robot, task.job), task.job, arrival,
                         self.revision)
            events.append(Event(EventKind.ARRIVED, task.job, arrival,
                                self._attempts[task.job]))
            return True
        if self._phase == _Phase.WAIT:
            start = self._start_time(self.task)
            if start is None or now < start:
                return False
            task = self.task
            self._phase, self._holding = _Phase.WORK, ''
            self._work_factor, self._factor = self._factor, 1.0
            self._phase_start = start
            self.driver.begin(Operation(task.job, task.operation_type, task.operation_name,
                                        task.location, task.co_workers,
                                        task.duration * self._work_factor), start)
            self._begun = True
            events.append(Event(EventKind.STARTED, task.job, start, self._attempts[task.job]))
            return True
        if self._phase == _Phase.WORK:
            ending = self.driver.ending(now)
            if ending is None:
                return False
            self._begun = False
            if ending.failure:
                return self._driver_failed(ending, events)
            task = self.task
            end = max(ending.end, self._phase_start)
            self._record(self._operation_done, (self.robot, task.job), task.job, end,
                         self.revision)
            self._phase, self._finishing = _Phase.FINISH, task.job
            events.append(Event(EventKind.OPERATION_DONE, task.job, end,
                                self._attempts[task.job]))
            return True
        if self._phase == _Phase.FINISH:
            end = self._job_end(self.task.job)
            if end is None or now < end:
                return False
            self._free_at, self._finishing = end, ''
            self._holding = self.task.job if self.task.held_into_next else ''
            self._index += 1
            self._phase = _Phase.NEXT
            return True
        return False

    def _arrival(self, now: float, events: list[Event]) -> float | None:
        """When the leg under way arrived, once it has by `now`; sets the leg off when due."""
        if not self._begun:
            if now < self._phase_start:
                return None
            # Left only now: a robot failed before its departure (before its release, say)
            # still leaves no earlier than the plan that brings it back has it leave.
            self._departed = True
            if self._leg is None:
                return self._phase_start
            self.driver.begin(self._leg, self._phase_start)
            self._begun = True
        ending = self.driver.ending(now)
        if ending is None:
            return None
        if ending.failure:
            self._begun = False
            self._driver_failed(ending, events)
            return None
        self._begun = False
        return max(ending.end, self._phase_start)

    def _driver_failed(self, ending: Ending, events: list[Event]) -> bool:
        """The robot cannot go on: it fails as an injected failure makes it, where the
        driver left it."""
        if self._phase in (_Phase.TRAVEL, _Phase.TRANSIT):
            # The robot stands where the driver says it stopped.
            if ending.share > 0:
                self._stopped = (self._leg, min(ending.share, 1.0))
            else:
                self.destination = ''
        message = self._fail(ending.end, f"robot '{self.robot}' failed: {ending.failure}",
                             events)
        self._driver_failures.append(f"robot '{self.robot}' failed at t={ending.end:.2f} "
                                     f'({ending.failure}){message}')
        return False

    def _next(self) -> bool:
        while self._index < len(self.tasks) and self._finished(self.tasks[self._index].job):
            self._index += 1
        if not self._left_finished_job():
            return False
        if self._index >= len(self.tasks):
            self._phase, self._holding = _Phase.DONE, ''
            return False
        task = self.tasks[self._index]
        self._attempts[task.job] = self._attempts.get(task.job, 0) + 1
        departure = max(self._free_at, self._not_before)
        # Not placed yet, it leaves from where the plan starts it (the scenario's start
        # location; a robot that may start anywhere has no first leg). Placed or not, its
        # first leg of a mission leaves no earlier than the plan has it leave: its release
        # time (or the job's start for a robot not placed), which only the plan knows.
        # A holder carries the held part along its leg. A robot already at the job's place
        # (a leg it ended under an older revision took it there) has no way left to go; one
        # standing on a leg has the plan's way from there, and at least what remains of the
        # leg to either of its ends.
        leg = max(task.leg, 0.0)
        if self._stopped is None and self.location == task.location:
            leg = 0.0
        elif self._stopped is not None:
            stopped, share = self._stopped
            if task.location == stopped.destination:
                leg = max(leg, (1 - share) * stopped.duration)
            elif task.location == stopped.origin:
                leg = max(leg, share * stopped.duration)
        if not self._departed:
            departure = max(departure, task.travel_start)
        self._phase = _Phase.TRAVEL
        self._phase_start = departure
        self._stopped = None
        self._leg = Leg(task.job, self.location, task.location, leg) if leg > 0 else None
        self._begun = False
        self.destination = task.location
        return True

    def _left_finished_job(self) -> bool:
        """Whether the robot is free of the job it did its part of (advancing `_free_at` to
        that job's end): once the job completes, or when a restart voided its part. A job the
        plan leaves out was complete when planned, at its last reported operation's end."""
        job = self._finishing
        if not job:
            return True
        if (self.robot, job) in self._operation_done:
            end = self._job_end(job)
            if end is None and job not in self._job_robots:
                end = self._latest_operation_end(job)
            if end is None:
                return False
            self._free_at = max(self._free_at, end)
        self._finishing = ''
        return True

    def _finished(self, job: str) -> bool:
        return (self.robot, job) in self._operation_done or job in self._job_done

    def _start_time(self, task: Task) -> float | None:
        """When the job can start: its last robot arrived and last predecessor completed.
        A predecessor the revision leaves out was complete when it was planned: what was
        reported of its end counts (a job that goes on from an older revision may have
        robots there since before it ended), and if nothing was, it holds nothing up."""
        times = []
        for robot in self._job_robots.get(task.job, frozenset({self.robot})) | {self.robot}:
            if (robot, task.job) not in self._arrived:
                return None
            times.append(self._arrived[robot, task.job].time)
        for job in task.predecessors:
            end = self._predecessor_end(job)
            if end is None and job not in self._job_robots:
                end = self._latest_operation_end(job)
                if end is None:
                    continue
            if end is None:
                return None
            times.append(end)
        return max(times)

    def _latest_operation_end(self, job: str) -> float | None:
        """The latest end reported of the job's operations (None if none was): the end of a
        job the revision leaves out, which was complete when it was planned."""
        return max((fact.time for (_, done), fact in self._operation_done.items()
                    if done == job), default=None)

    def _predecessor_end(self, job: str) -> float | None:
        """When a predecessor completed, as far as this robot may act on it: a job it took
        part in when every robot on it reported done, another robot's job only when the
        planner declared it done. A report that reached this robot but never the planner
        (its robot killed before its writer was matched to the planner's reader) would
        otherwise start this job on a completion the planner does not know of: it re-plans
        the predecessor, and its record of the mission has this job starting first."""
        if self.robot in self._job_robots.get(job, ()):
            return self._job_end(job)
        return self._job_done[job].time if job in self._job_done else None

    def _job_end(self, job: str) -> float | None:
        """A job is complete when the planner says so or every robot on it reported done."""
        if job in self._job_done:
            return self._job_done[job].time
        robots = self._job_robots.get(job)
        if not robots or any((r, job) not in self._operation_done for r in robots):
            return None
        return max(self._operation_done[r, job].time for r in robots)
