"""The mission as the planner runs it, without ROS: what to plan, when to re-plan, when a
mission is over.

The planner node feeds a `MissionController` what it hears (robot states, task events:
`reports`), what it is asked (submit or cancel a mission, add jobs) and the passing of time
(`tick`), and carries out the `effects` each call returns: run a solve off the executor,
publish a plan, declare a job done, tell the story of the mission (`Note`). All times in are
wall seconds of one clock (the ROS clock); schedule time is derived from the mission start and
the time scale.

One mission runs at a time; missions submitted meanwhile wait in a bounded queue, and the
next starts at the first tick after the running one ended, from where the robots are.

Which robots it plans for is `liveness`'s judgement: a robot takes part while it is available.
The plan records, for each robot it counted on, the agent incarnation and failure count it
saw; a robot that fails and recovers between two ticks, or whose agent restarts, lost its
tasks even though it looks healthy, and is re-planned in. Which jobs a new revision lets go on
is `continuation`'s; a mission rebuilt after a planner restart comes from `resume`.
"""

import math
from collections import Counter
from dataclasses import dataclass, field, replace
from fractions import Fraction

from fjsp_common.clock import ScheduleClock
from fjsp_common.decimals import decimal, decimals
from fjsp_common.vocabulary import EventKind, MissionEventKind, MissionState, RobotMode
from fjsp_planner.execution.journal import Record
from fjsp_planner.execution.mission import continuation
from fjsp_planner.execution.mission.effects import (
    Effect,
    JobDone,
    LeftQueue,
    Note,
    PublishPlan,
    Solve,
    SolveKind,
    StatusView,
)
from fjsp_planner.execution.mission.liveness import Liveness
from fjsp_planner.execution.mission.reports import EventReport, RobotReport
from fjsp_planner.execution.mission.resume import restarted_while_down, restore, started_where
from fjsp_planner.execution.mission.settings import Settings
from fjsp_planner.execution.mission.states import INITIAL, check_transition
from fjsp_planner.execution.replan import ExecutionState, Replan, RobotSituation, residual_problem
from fjsp_planner.execution.tracking import Ignored, MissionTracker
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Schedule, Status
from fjsp_planner.model.validate import validate

REPAIR_LIMIT = 0.5
"""Seconds the repair of a plan may take: a valid plan of what remains without search (a few
hundred ms on 5 panels), published at once; the search for a better one follows."""

LONGEST_SEARCH = 16
"""The longest search for a better plan, in `replan_time_limit`s: searches that find nothing
better double in length up to it (1, 2, 4, 8, 16 s by default), then stop."""

IMPROVE_REACH = 0.5
"""Seconds beyond a search's time limit until its plan reaches the robots (the solver's
overrun, publishing, the agents taking it): what they do by then is kept in it."""

RETRY_FAILED_REPLAN = 1.0
"""Seconds after which a re-plan that failed is tried again, if no new report came first."""


# --- what the controller keeps ---------------------------------------------------------

@dataclass
class Solving:
    token: int
    kind: SolveKind
    problem: Problem
    """What was posed: for a first plan, the problem the schedule will be of."""
    fleet: dict[str, tuple[int, int]]
    """The available robots it plans for: (incarnation, failures) as seen when posed."""
    reasons: tuple[str, ...]
    state: ExecutionState | None = None
    time_limit: float = 0.0
    """For a search for a better plan: its time limit."""
    published: Replan | None = None
    """For a search for a better plan: the published plan it searches from."""


@dataclass
class Mission:
    id: str
    problem: Problem
    settings: Settings
    tracker: MissionTracker
    accepted: float
    """Wall seconds when the mission was accepted."""
    _state: MissionState = INITIAL
    start: float | None = None
    """Wall seconds of schedule time 0, fixed when revision 1 is published."""
    schedule: Schedule | None = None
    planned_makespan: float = math.nan
    planned: dict[str, tuple[int, int]] = field(default_factory=dict)
    """The robots the current plan (or blocked verdict) counts on: (incarnation, failures)."""
    solving: Solving | None = None
    replan_reasons: tuple[str, ...] = ()
    blocked: tuple[str, ...] = ()
    failure: tuple[str, ...] = ()
    blocked_since: float | None = None
    foreign: set[str] = field(default_factory=set)
    """Other missions whose events arrived: each is logged once."""
    warned: set[str] = field(default_factory=set)
    pending: tuple[str, ...] = ()
    """Reasons of a re-plan still to make (one discarded or failed, jobs added, a restart)."""
    improving: Solving | None = None
    """The search for a better plan than the repaired one in force, if any."""
    reports: int = 0
    """Task events used so far."""
    retry: tuple[int, float] | None = None
    """After a failed re-plan: the reports used and the wall time when it failed; the
    pending re-plan waits for a new report or RETRY_FAILED_REPLAN seconds."""
    blocked_too_long: bool = False
    resumed: bool = False
    """Rebuilt after a planner restart: re-planned once every robot's event history, as far
    as its latest state says, has arrived."""
    journaled: dict[str, int] = field(default_factory=dict)
    """Rebuilt after a planner restart: the agent incarnation each robot's tasks were planned
    for, as the journal has them."""
    published_at: float | None = None
    """Wall seconds when the latest revision was published (or, resumed, when the mission
    was rebuilt)."""
    resent: tuple[int, float] | None = None
    """The latest revision published again for a robot that had not taken it, and the wall
    time it was last published again."""
    missed: dict[str, int] = field(default_factory=dict)
    """Robot -> the revision it did not take within `plan_uptake_timeout`: it is planned
    without until it reports the latest revision."""

    @property
    def state(self) -> MissionState:
        return self._state

    @property
    def clock(self) -> ScheduleClock | None:
        """The mission's schedule time, once revision 1 fixed its start (None before)."""
        return None if self.start is None else ScheduleClock(self.start,
                                                             self.settings.time_scale)

    def enter(self, state: MissionState) -> None:
        """Move the mission to `state`, as `states.TRANSITIONS` allows (else it raises)."""
        self._state = check_transition(self._state, state)


class MissionController:
    def __init__(self, settings: Settings | None = None):
        self.settings = settings if settings is not None else Settings()
        self.liveness = Liveness()
        self.mission: Mission | None = None
        """The running mission, or the last one that ran."""
        self.queue: list[Mission] = []
        """The missions waiting their turn, the next first."""
        self._tokens = 0

    # --- commands ------------------------------------------------------------------------

    @property
    def busy(self) -> bool:
        """A mission runs, or waits its turn."""
        return bool(self.queue) or (self.mission is not None and not self.mission.state.ended)

    def start(self, problem: Problem, mission_id: str, wall: float,
              settings: Settings | None = None) -> list[Effect]:
        """Accept a mission; raises ValueError while another one runs or waits."""
        if self.busy:
            raise ValueError(self._one_at_a_time())
        return self._begin(Mission(mission_id, problem, settings or self.settings,
                                   MissionTracker(problem), wall), wall)

    def submit(self, problem: Problem, mission_id: str, wall: float,
               settings: Settings | None = None, queue: bool = True
               ) -> tuple[int, list[Effect]]:
        """Accept a mission: at once if none runs (position 0), else at the end of the
        queue (its position there, 1 for the next to run) unless `queue` is False.
        ValueError saying why if it cannot be taken: the queue is full, or not wanted."""
        if not self.busy:
            return 0, self.start(problem, mission_id, wall, settings)
        limit = self.settings.queue_limit
        if not queue or limit == 0:
            raise ValueError(self._one_at_a_time()
                             + ('' if queue else ' (the goal asked not to be queued)'))
        if len(self.queue) >= limit:
            raise ValueError(f'the queue is full: {len(self.queue)} missions wait their turn '
                             f'(queue_limit {limit})')
        return self.requeue(problem, mission_id, wall, settings), []

    def requeue(self, problem: Problem, mission_id: str, wall: float,
                settings: Settings | None = None) -> int:
        """Put a mission at the end of the queue, whatever its limit (a restarted planner
        rebuilds its queue so); its position."""
        self.queue.append(Mission(mission_id, problem, settings or self.settings,
                                  MissionTracker(problem), wall, _state=MissionState.QUEUED))
        return len(self.queue)

    def _one_at_a_time(self) -> str:
        running = self.mission if self.mission is not None and not self.mission.state.ended \
            else self.queue[0]
        return f"mission '{running.id}' is {running.state}: one mission per fleet at a time"

    def _begin(self, mission: Mission, wall: float) -> list[Effect]:
        self.mission = mission
        problem = mission.problem
        robots = ', '.join(r.name for r in problem.robots)
        effects = [Note(MissionEventKind.MISSION_STARTED,
                        (f"scenario '{problem.name}': {len(problem.jobs)} jobs, robots "
                         f'{robots}',))]
        return effects + self.tick(wall)

    def _start_next(self, wall: float) -> list[Effect]:
        """The first mission of the queue starts, its robot wait counted from now."""
        mission = self.queue.pop(0)
        mission.enter(MissionState.WAITING_FOR_ROBOTS)
        mission.accepted = wall
        return self._begin(mission, wall)

    def running(self, mission_id: str) -> Mission:
        """The running mission, which `mission_id` must name; ValueError saying why not."""
        mission = self.mission
        if mission is not None and mission_id == mission.id and not mission.state.ended:
            return mission
        raise ValueError(self._not_running(mission_id))

    def position(self, mission_id: str) -> int:
        """Where `mission_id` waits in the queue: 1 for the next to run; 0 if it does not."""
        ids = [waiting.id for waiting in self.queue]
        return ids.index(mission_id) + 1 if mission_id in ids else 0

    def waiting(self, mission_id: str) -> Mission | None:
        """The queued mission `mission_id`, if it waits."""
        position = self.position(mission_id)
        return self.queue[position - 1] if position else None

    def _not_running(self, mission_id: str) -> str:
        mission = self.mission
        running = f" (running: '{mission.id}')" if mission is not None \
            and not mission.state.ended else ''
        if not mission_id:
            return 'name the mission: the request has no mission id' + running
        shown = mission_id[:80]  # as the request gave it: any length
        position = self.position(mission_id)
        if position:
            return (f"mission '{shown}' waits in the queue (position {position}): it is not "
                    'running yet' + running)
        if mission is not None and mission_id == mission.id:
            return f"mission '{shown}' has ended: {mission.state}"
        return f"no mission '{shown}' is running or waits in the queue" + running

    def cancel(self, mission_id: str, reason: str, wall: float) -> list[Effect]:
        """Stop mission `mission_id`: if it runs, the robots are told to drop their tasks;
        if it waits in the queue, it leaves the queue. ValueError if it does neither."""
        position = self.position(mission_id)
        if position:
            waiting = self.queue.pop(position - 1)
            waiting.enter(MissionState.CANCELLED)
            waiting.failure = (reason,)
            return [LeftQueue(waiting.id, MissionState.CANCELLED, (reason,))]
        mission = self.running(mission_id)
        mission.solving = mission.improving = None
        mission.enter(MissionState.CANCELLED)
        mission.failure = (reason,)
        effects: list[Effect] = [Note(MissionEventKind.MISSION_CANCELLED, (reason,))]
        if mission.start is not None:
            revision = self._next_revision(mission)
            mission.tracker.revision = revision
            effects.insert(0, PublishPlan(revision, mission.problem, None, frozenset(),
                                          (reason,), mission.start, cancelled=True))
        return effects

    def stand_down(self, reason: str) -> list[Effect]:
        """Another planner is in charge: the running mission fails and the queued ones leave
        the queue failed, with `reason`. No plan goes out: the robots follow the other."""
        effects: list[Effect] = []
        mission = self.mission
        if mission is not None and not mission.state.ended:
            mission.solving = mission.improving = None
            effects += self._fail(mission, (reason,))
        for waiting in self.queue:
            waiting.enter(MissionState.FAILED)
            waiting.failure = (reason,)
            effects.append(LeftQueue(waiting.id, MissionState.FAILED, (reason,)))
        self.queue = []
        return effects

    def add_jobs(self, problem: Problem, jobs: tuple[str, ...], wall: float) -> list[Effect]:
        """The running mission grows to `problem`, which adds `jobs` (checked by
        `core.extension.extend`); they are planned in like any re-plan."""
        mission = self.mission
        if mission is None or mission.state.ended:
            raise ValueError('no mission is running')
        mission.problem = problem
        mission.tracker.extend(problem)
        reason = 'jobs added: ' + ', '.join(jobs)
        effects: list[Effect] = [Note(MissionEventKind.JOBS_ADDED, job=', '.join(jobs))]
        mission.improving = None
        if mission.solving is not None:
            # Whatever is being solved leaves the new jobs out.
            mission.solving = None
            mission.enter(MissionState.WAITING_FOR_ROBOTS if mission.schedule is None
                          else MissionState.EXECUTING)
        if mission.schedule is not None:
            mission.pending += (reason,)
        return effects + self.tick(wall)

    def resume(self, mission_id: str, problem: Problem, settings: Settings, accepted: float,
               records: list[Record], wall: float) -> list[Effect]:
        """Rebuild a mission a previous planner process ran, from its journal's plan and
        done records; it is re-planned from where the robots are once every robot has
        reported and its event history has arrived (or the robot wait is over)."""
        if self.mission is not None and not self.mission.state.ended:
            raise ValueError(f"mission '{self.mission.id}' is {self.mission.state}")
        problem = started_where(problem, records)
        mission = Mission(mission_id, problem, settings, MissionTracker(problem), wall,
                          resumed=True)
        restore(mission, records, wall)
        tracker = mission.tracker
        self.mission = mission
        where = (f'at plan revision {tracker.revision}, {len(tracker.done)}/'
                 f'{len(tracker.jobs)} jobs done' if mission.schedule is not None
                 else 'before its first plan')
        return [Note(MissionEventKind.MISSION_STARTED,
                     (f'resumed after a planner restart {where}',))] + self.tick(wall)

    def forget(self) -> 'Mission':
        """Drop the running mission from memory, as a planner process that dies drops it
        (its journal and the robots' histories bring it back: `resume`); the mission
        dropped."""
        mission, self.mission = self.mission, None
        return mission

    def _resume_when_caught_up(self, mission, wall) -> list[Effect]:
        """Re-plan a resumed mission once what the robots did while no planner ran is known:
        every robot heard has had the latest task event it says it published received (a
        fixed wait after discovery was too short for a loaded machine, and the re-plan
        redid what the robots had done meanwhile). A robot whose history does not arrive
        is waited for at most `robot_wait_timeout`."""
        if mission.schedule is None:
            mission.resumed = False
            return self._plan(mission, wall)
        waited = wall - mission.accepted
        behind = [r.name for r in mission.problem.robots
                  if not self.liveness.caught_up(r.name)]
        if behind and waited < self.settings.robot_wait_timeout:
            return []
        mission.resumed = False
        effects = restarted_while_down(mission, self.liveness, self._units(mission, wall))
        mission.planned = self._fleet(mission, wall)
        mission.enter(MissionState.EXECUTING)
        mission.pending = ('planner restarted: what remains is re-planned from where the '
                           'robots are',)
        return effects

    # --- what the fleet reports ----------------------------------------------------------

    def robot_state(self, report: RobotReport, wall: float) -> list[Effect]:
        restarted = self.liveness.hear(report, wall)
        agent = self.liveness.agents[report.robot]
        mission = self.mission
        if mission is None:
            return []
        effects: list[Effect] = []
        if restarted and report.robot in mission.tracker.robots \
                and mission.tracker.plan is not None:
            # The operation its previous process was running died with it; the new one
            # would do it again from scratch, alone, under the revision it finds latched.
            effects += [Note(MissionEventKind.JOB_ABORTED,
                             (f"robot '{report.robot}' restarted: its agent lost the "
                              'operation',), job=job)
                        for job in mission.tracker.agent_restarted(
                            report.robot, at=self._units(mission, wall))]
        if report.robot not in mission.tracker.robots:
            verdict = mission.tracker.record_robot_state(report.robot, report.mode, '', '',
                                                         math.nan)
            if verdict.repeated:
                return []
            return [Note(MissionEventKind.WARNING, (self._unknown(report.robot),),
                         robot=report.robot)]
        if agent.offline_since is not None:
            return effects  # the tracker hears it again once it counts again
        return effects + self._record(mission, report, wall)

    def unverified_state(self, robot: str, why: str, wall: float) -> None:
        """A state about `robot` of the mission that does not verify with the fleet key
        (`why`): not a heartbeat, but the reason its robot is named as silent."""
        if self.mission is not None and robot in self.mission.tracker.robots:
            self.liveness.refuse(robot, why, wall)

    def _record(self, mission: Mission, report: RobotReport, wall: float) -> list[Effect]:
        """Give the tracker a robot's report; the story of what changed."""
        effects: list[Effect] = []
        before = mission.tracker.robots[report.robot].mode
        mission.tracker.record_robot_state(report.robot, report.mode, report.location,
                                           report.destination, report.busy_until,
                                           report.current_job, at=self._units(mission, wall),
                                           progress=report.progress)
        if report.mode == RobotMode.FAILED and before != RobotMode.FAILED:
            effects.append(Note(MissionEventKind.ROBOT_FAILED, robot=report.robot))
        elif before == RobotMode.FAILED and report.mode != RobotMode.FAILED:
            effects.append(Note(MissionEventKind.ROBOT_BACK, ('recovered',), robot=report.robot))
        if report.refusal and report.refusal not in mission.warned:
            mission.warned.add(report.refusal)
            effects.append(Note(MissionEventKind.WARNING,
                                (f"robot '{report.robot}' refuses its plan: {report.refusal}",),
                                robot=report.robot))
        return effects

    def task_event(self, event: EventReport, wall: float) -> tuple[list[Effect], str]:
        """Use one agent's event; the second item says why it was ignored ('' if used)."""
        mission = self.mission
        if event.robot in self.liveness.agents or (mission is not None
                                                    and event.robot in mission.tracker.robots):
            self.liveness.hear_event(event.robot, event.event_id)
        if mission is None:
            return [], ''
        tracker = mission.tracker
        if event.mission_id != mission.id:
            tracker.ignored[Ignored.STALE] += 1
            if event.mission_id in mission.foreign:
                return [], ''
            mission.foreign.add(event.mission_id)
            return [], (f"events of mission '{event.mission_id}': this planner runs mission "
                        f"'{mission.id}'")
        if event.kind == EventKind.JOB_DONE:
            tracker.ignored[Ignored.UNKNOWN] += 1
            return [], (f"job-done event '{event.event_id}': only the planner declares jobs "
                        'done')
        aborted_before = event.job in tracker.aborted
        verdict = tracker.record_event(event.event_id, event.kind, event.robot, event.job,
                                       event.revision, event.time)
        if verdict.ignored:
            return [], f'{verdict.ignored} event: {verdict.reason}'
        mission.reports += 1
        effects: list[Effect] = []
        if event.kind == EventKind.ABORTED and not aborted_before \
                and event.job in tracker.aborted:
            effects.append(Note(MissionEventKind.JOB_ABORTED,
                                (f"robot '{event.robot}' aborted it",), job=event.job))
        if verdict.job_done is not None:
            job, end = verdict.job_done
            effects.append(JobDone(job, end, tracker.revision, tracker.jobs[job].done_as))
            if tracker.complete and not mission.state.ended:
                effects += self._complete(mission)
        return effects, ''

    # --- time passing --------------------------------------------------------------------

    def tick(self, wall: float, subscribers: int | None = None,
             refused: int | None = None) -> list[Effect]:
        """Judge heartbeats, start what is due. `subscribers` counts the plan topic's
        matched readers: the first plan waits until every robot can hear it. `refused` counts
        the messages the node has refused as unauthenticated so far: a flood of them slows
        the judgment of heartbeats."""
        if refused is not None:
            self.liveness.count_refused(refused, wall)
        starved = self.liveness.starved(wall)
        effects: list[Effect] = []
        if not starved:
            effects += self._check_heartbeats(wall)
        if self.queue and (self.mission is None or self.mission.state.ended):
            return effects + self._start_next(wall)
        mission = self.mission
        if mission is None or mission.state.ended or mission.solving is not None:
            return effects
        if mission.state == MissionState.WAITING_FOR_ROBOTS:
            waited = wall - mission.accepted
            heard = all(self.liveness.heard(r.name) for r in mission.problem.robots)
            unmatched = subscribers is not None and subscribers < len(mission.problem.robots)
            if (not heard or unmatched) and waited < self.settings.robot_wait_timeout:
                return effects
            if not mission.resumed:
                return effects + self._plan(mission, wall)
            return effects + self._resume_when_caught_up(mission, wall)
        if mission.state in (MissionState.EXECUTING, MissionState.BLOCKED):
            if not starved:
                effects += self.liveness.check_uptake(mission, wall,
                                                      self.settings.plan_uptake_timeout)
            reasons = self._replan_reasons(mission, wall)
            if mission.pending and (reasons or self._may_retry(mission, wall)):
                reasons, mission.pending = list(mission.pending) + reasons, ()
                mission.retry = None
            if reasons and mission.schedule is None:
                # Blocked before the first plan: plan afresh once the fleet changes.
                return effects + self._plan(mission, wall)
            if reasons:
                return effects + self._replan(mission, wall, tuple(reasons))
            timeout = mission.settings.blocked_timeout
            if mission.state == MissionState.BLOCKED and timeout > 0 \
                    and wall - mission.blocked_since >= timeout:
                mission.blocked_too_long = True
                effects += self._fail(mission, (f'blocked for {timeout:g} s: '
                                                + '; '.join(mission.blocked),))
        return effects

    @staticmethod
    def _may_retry(mission: Mission, wall: float) -> bool:
        if mission.retry is None:
            return True
        reports, failed_at = mission.retry
        return mission.reports != reports or wall - failed_at >= RETRY_FAILED_REPLAN

    def _check_heartbeats(self, wall: float) -> list[Effect]:
        effects = []
        mission = self.mission
        for change in self.liveness.check_heartbeats(wall, self.settings.heartbeat_timeout):
            if mission is None or change.robot not in mission.tracker.robots:
                continue
            if not change.back:
                mission.tracker.mark_offline(change.robot, at=self._units(mission, wall))
                unverified = self.liveness.silenced(change.robot)
                flood = (f' under a flood of {self.liveness.refused_rate(wall):,.0f} '
                         'unauthenticated messages a second'
                         if self.liveness.flooded(wall) else '')
                effects.append(Note(MissionEventKind.ROBOT_OFFLINE, (
                    f'no state that verifies for {change.silent:.1f} s{flood}: {unverified}'
                    if unverified else f'no state for {change.silent:.1f} s{flood}',),
                    robot=change.robot))
            else:
                report = self.liveness.agents[change.robot].report
                effects.append(Note(MissionEventKind.ROBOT_BACK,
                                    (f'reporting again ({report.mode})',), robot=change.robot))
                effects += self._record(mission, report, wall)
        return effects

    # --- solving ---------------------------------------------------------------------------

    def _unavailable(self, mission: Mission, wall: float) -> dict[str, str]:
        """Robot -> why it cannot take part in planning now ('' if it can)."""
        return self.liveness.unavailable(mission, wall, self.settings.plan_uptake_timeout)

    def _fleet(self, mission: Mission, wall: float) -> dict[str, tuple[int, int]]:
        """The robots available now: (incarnation, failures)."""
        return self.liveness.fleet(self._unavailable(mission, wall))

    def _plan(self, mission: Mission, wall: float) -> list[Effect]:
        """The first plan of the mission, for the robots available now, from where they are."""
        unavailable = self._unavailable(mission, wall)
        fleet = self.liveness.fleet(unavailable)
        problem = mission.problem
        state = self._initial_state(mission, fleet)
        if state is None:
            posed = problem
        else:
            residual = residual_problem(problem, state)
            if residual.blocked:
                mission.planned = fleet
                return self._block(mission, wall, tuple(residual.blocked)
                                   + self._missing(unavailable))
            posed = residual.problem
        mission.enter(MissionState.PLANNING)
        return [self._solve(mission, SolveKind.PLAN, fleet, (), posed,
                            mission.settings.time_limit)]

    def _initial_state(self, mission: Mission, fleet) -> ExecutionState | None:
        """Where the robots are at the mission start, when that is not simply what the
        scenario says: some robots are out, or the last mission left them somewhere the
        scenario knows."""
        problem = mission.problem
        locations = set(problem.locations())
        robots, moved = {}, False
        for robot in problem.robots:
            agent = self.liveness.agents.get(robot.name)
            at = agent.report.destination or agent.report.location if agent else ''
            location = robot.start_location
            if robot.name in fleet and at in locations and at != location:
                location, moved = at, True
            robots[robot.name] = RobotSituation(robot.name, robot.name in fleet, location,
                                            robot.release_time)
        if not moved and len(fleet) == len(problem.robots):
            return None
        return ExecutionState(Fraction(0), frozenset(), {}, robots)

    def _replan(self, mission: Mission, wall: float, reasons: tuple[str, ...]
                ) -> list[Effect]:
        fleet = self._fleet(mission, wall)
        try:
            state = mission.tracker.execution_state(self._units(mission, wall))
        except ValueError as error:
            mission.planned = fleet
            return self._block(mission, wall, (f'cannot tell the execution state: {error}',))
        # The tracker knows failed and offline robots; refusing and silent ones are out too.
        state = replace(state, robots={name: replace(robot, healthy=name in fleet)
                                       for name, robot in state.robots.items()})
        mission.enter(MissionState.REPLANNING)
        mission.improving = None  # a search from an older state would only be discarded
        limit = min(REPAIR_LIMIT, mission.settings.replan_time_limit)
        return [self._solve(mission, SolveKind.REPAIR, fleet, reasons, mission.problem, limit,
                            mission.schedule, state)]

    def _solve(self, mission, kind, fleet, reasons, problem, time_limit, previous=None,
               state=None) -> Solve:
        self._tokens += 1
        mission.solving = Solving(self._tokens, kind, problem, fleet, reasons, state)
        return Solve(self._tokens, kind, problem, time_limit, previous, state, reasons)

    def _improve(self, mission, solving: Solving, published: Replan, wall: float,
                 time_limit: float | None = None) -> Solve:
        """Search for a better plan from the one just published, while it is followed: the
        robots go on with what it has them do until the search's plan can reach them."""
        self._tokens += 1
        limit = time_limit or mission.settings.replan_time_limit
        mission.improving = replace(solving, token=self._tokens, kind=SolveKind.IMPROVE,
                                    time_limit=limit, published=published)
        # Robots start a job as soon as its robots and predecessors are ready, so they may
        # be ahead of the plan: what they started is kept too.
        started = frozenset(name for name, record in mission.tracker.jobs.items()
                            if record.begun)
        return Solve(self._tokens, SolveKind.IMPROVE, published.residual.problem, limit,
                     state=solving.state, reasons=solving.reasons, published=published,
                     frozen_until=self._units(mission, wall + limit + IMPROVE_REACH),
                     started=started)

    def solved(self, token: int, outcome, wall: float) -> list[Effect]:
        """The outcome of `Solve` `token` (what its `SolveKind` says), or the ValueError the
        solver raised. Outcomes of superseded solves are dropped."""
        mission = self.mission
        if mission is not None and mission.improving is not None \
                and mission.improving.token == token:
            improving, mission.improving = mission.improving, None
            return self._improved(mission, improving, outcome, wall)
        if mission is None or mission.solving is None or mission.solving.token != token:
            return []
        solving, mission.solving = mission.solving, None
        if mission.state.ended:
            return []
        fleet_now = self._fleet(mission, wall)
        if solving.kind == SolveKind.PLAN:
            return self._first_plan(mission, solving, outcome, wall, fleet_now)
        return self._new_revision(mission, solving, outcome, wall, fleet_now)

    def _first_plan(self, mission, solving, outcome, wall, fleet_now) -> list[Effect]:
        limit = mission.settings.time_limit
        if isinstance(outcome, Exception):
            return self._fail(mission, (f'solver: {outcome}',))
        result: Result = outcome
        if result.schedule is None:
            return self._fail(mission, (f"no plan: solver '{result.solver}' answered "
                                        f'{result.status} within {limit:g} s',))
        posed = solving.problem
        problems = validate(posed, result.schedule)
        if problems:
            return self._fail(mission, tuple(f'solver returned an invalid schedule: {p}'
                                             for p in problems))
        mission.planned = solving.fleet
        mission.start = wall + mission.settings.start_delay
        if posed is not mission.problem:
            # The mission starts where the robots are: its executed timeline is judged so.
            starts = {r.name: r.start_location for r in posed.robots}
            problem = replace(mission.problem, robots=tuple(
                replace(r, start_location=starts.get(r.name, r.start_location))
                for r in mission.problem.robots))
            mission.problem = problem
            mission.tracker.extend(problem)
        return self._publish(mission, posed, result, frozenset(), (), wall)

    def _new_revision(self, mission, solving, outcome, wall, fleet_now) -> list[Effect]:
        tracker = mission.tracker
        if tracker.complete:
            return []
        if fleet_now != solving.fleet:
            # The fleet changed while solving: this plan would give work to a robot that is
            # out, or leave out one that is back. The next tick re-plans from the new state,
            # for what this re-plan was for too.
            mission.enter(MissionState.EXECUTING)
            mission.pending = solving.reasons
            return [Note(MissionEventKind.WARNING,
                         ('re-plan discarded: the fleet changed while it was solved',))]
        mission.planned = solving.fleet
        if isinstance(outcome, Exception):
            # The state it was posed from may contradict itself for a while: after a network
            # partition every robot's state is back at once, but each one's event history
            # only when its writer resends it, so a job can look started by one robot while
            # its crew's previous job does not look finished yet. Try again once more is
            # known, rather than stay blocked until the fleet changes.
            mission.pending, mission.retry = solving.reasons, (mission.reports, wall)
            return self._block(mission, wall, (f're-planning failed: {outcome}',))
        replanned: Replan = outcome
        residual = replanned.residual
        if residual.complete:
            mission.enter(MissionState.EXECUTING)
            return []
        if residual.blocked:
            return self._block(mission, wall, tuple(residual.blocked))
        result = replanned.result
        if result.schedule is None:
            return self._block(mission, wall, (
                f"no plan for what remains: solver '{result.solver}' answered "
                f'{result.status} within {mission.settings.replan_time_limit:g} s',))
        if replanned.problems:
            return self._block(mission, wall, tuple(f're-planned schedule is invalid: {p}'
                                                    for p in replanned.problems))
        completed = continuation.completed_after_all(mission.tracker, residual.problem,
                                                     solving.state)
        if completed:
            return self._discard(mission, solving, completed, 'completed')
        continued = frozenset(residual.problem.fixed)
        progressed = self._progressed(mission, solving, residual.problem, wall)
        if progressed and not continuation.goes_on(mission.tracker, result.schedule, progressed,
                                                   continued):
            return self._discard(mission, solving, progressed, 'progressed')
        notes = [Note(MissionEventKind.JOB_VOIDED, ('its hold was lost',), job=job,
                      revision=mission.tracker.revision) for job in residual.voided]
        mission.blocked, mission.blocked_since = (), None
        continued |= frozenset(progressed)
        continued |= continuation.unchanged(mission.tracker, result.schedule, continued)
        published = self._publish(mission, residual.problem, result, continued,
                                  solving.reasons, wall)
        if result.status == Status.OPTIMAL:
            return notes + published
        return notes + published + [self._improve(mission, solving, replanned, wall)]

    @staticmethod
    def _discard(mission, solving: Solving, jobs, how: str) -> list[Effect]:
        """Drop a re-plan that would redo work done meanwhile: plan again from now."""
        mission.enter(MissionState.EXECUTING)
        mission.pending = solving.reasons
        return [Note(MissionEventKind.WARNING,
                     ('re-plan discarded: ' + ', '.join(f"job '{j}'" for j in jobs)
                      + f' {how} while it was solved',))]

    def _improved(self, mission, solving: Solving, outcome, wall: float) -> list[Effect]:
        """A better plan than the repaired one, published as the next revision if it beats
        it by the improvement margin, nothing changed in the fleet meanwhile, and what the
        robots did since goes on as it is in it; then searched from again. A search that
        finds nothing better by the margin is followed by one twice as long, up to
        LONGEST_SEARCH times `replan_time_limit`, unless it proved its plan optimal: on 5
        panels a search of a second rarely betters a repaired plan, one of ten seconds gets
        within 3 % of a minute's cold solve (docs/solver.md, "Re-planning"). Each revision
        is shorter by the margin, so agents do not thrash."""
        if isinstance(outcome, Exception) or mission.state != MissionState.EXECUTING:
            return []
        if self._fleet(mission, wall) != solving.fleet:
            return []
        if not outcome.improved:
            kept = outcome.replan.result
            if kept.lower_bound is not None and kept.lower_bound >= kept.makespan:
                return []
            return self._search_longer(mission, solving, outcome.replan, wall)
        better = outcome.replan
        continued = frozenset(better.residual.problem.fixed)
        progressed = self._progressed(mission, solving, better.residual.problem, wall)
        if progressed and not continuation.goes_on(mission.tracker, better.schedule,
                                                   progressed, continued):
            # The robots got further than the search kept: the plan cannot be followed.
            dropped = Note(MissionEventKind.WARNING, (
                f'a better plan (makespan {decimal(better.result.makespan)}) dropped: '
                + ', '.join(f"job '{j}'" for j in progressed)
                + ' progressed while it was searched for',))
            return [dropped] + self._search_longer(mission, solving, solving.published, wall)
        reason = 'a better plan: makespan {} -> {}'.format(
            *decimals(mission.planned_makespan, better.result.makespan))
        continued |= frozenset(progressed)
        continued |= continuation.unchanged(mission.tracker, better.schedule, continued)
        published = self._publish(mission, better.residual.problem, better.result, continued,
                                  (reason,), wall)
        if better.result.status == Status.OPTIMAL:
            return published
        return published + [self._improve(mission, solving, better, wall,
                                          solving.time_limit)]

    def _search_longer(self, mission, solving: Solving, published: Replan, wall: float
                       ) -> list[Effect]:
        """After a search that gave no plan to publish: one twice as long from `published`,
        up to LONGEST_SEARCH times `replan_time_limit`."""
        longer = 2 * solving.time_limit
        if longer > LONGEST_SEARCH * mission.settings.replan_time_limit:
            return []
        return [self._improve(mission, solving, published, wall, longer)]

    def _progressed(self, mission, solving: Solving, posed: Problem, wall: float
                    ) -> list[str]:
        """`continuation.progressed` for the plan `solving` gave."""
        return continuation.progressed(mission.tracker, posed, solving.state, solving.fleet,
                                       self._units(mission, wall), mission.settings.time_scale)

    def _publish(self, mission, posed, result, continued, reasons, wall) -> list[Effect]:
        tracker = mission.tracker
        mission.published_at = wall
        revision = self._next_revision(mission)
        tracker.set_plan(result.schedule, revision, continued)
        mission.schedule = result.schedule
        mission.planned_makespan = float(result.makespan)
        mission.replan_reasons = reasons
        mission.enter(MissionState.EXECUTING)
        starts = {r.name: r.start_location for r in mission.problem.robots}
        incarnations = {name: planned[0] for name, planned in mission.planned.items()}
        restarted_in = {job: tracker.jobs[job].since_revision for job in result.schedule.jobs}
        return [PublishPlan(revision, posed, result, continued, reasons, mission.start,
                            restarted_in=restarted_in, incarnations=incarnations,
                            starts=starts),
                Note(MissionEventKind.PLAN_PUBLISHED, reasons)]

    def _next_revision(self, mission: Mission) -> int:
        """Above any revision a robot follows: after a restart, the journal may lag them."""
        followed = [a.report.revision for a in self.liveness.agents.values()
                    if a.report.mission_id == mission.id]
        return max([mission.tracker.revision, *followed]) + 1

    def _replan_reasons(self, mission: Mission, wall: float) -> list[str]:
        """Why the current plan (or blocked verdict) no longer fits the fleet; empty if it
        does. Late and aborted operations count only while executing: a blocked mission
        waits for a robot to come back."""
        reasons = []
        for name, why in self._unavailable(mission, wall).items():
            planned = mission.planned.get(name)
            if planned is not None and why:
                reasons.append(f"robot '{name}' {why}")
            elif planned is None and not why:
                reasons.append(f"robot '{name}' available")
            elif planned is not None:
                report = self.liveness.agents[name].report
                if report.incarnation != planned[0]:
                    reasons.append(f"robot '{name}' restarted: its agent lost its tasks")
                elif report.failures != planned[1]:
                    reasons.append(f"robot '{name}' failed and recovered")
        if mission.state == MissionState.EXECUTING:
            tracker = mission.tracker
            reasons += [f"job '{j}' aborted" for j in sorted(tracker.aborted)]
            reasons += tracker.overruns(self.settings.delay_threshold)
            reasons += self._drift(mission, wall)
        return reasons

    def _drift(self, mission: Mission, wall: float) -> list[str]:
        """The projected makespan past the plan's by more than `drift_threshold` (a share; 0:
        never): robots running late (or short) enough that the rest may be better planned
        afresh from where they are. Each revision resets the plan's makespan."""
        share, planned = self.settings.drift_threshold, mission.planned_makespan
        if share <= 0 or not math.isfinite(planned) or planned <= 0:
            return []
        projected = float(mission.tracker.projected_makespan(self._units(mission, wall)))
        if projected <= planned * (1 + share):
            return []
        return [f'projected makespan {projected:.2f} is {projected / planned - 1:.1%} past '
                f"the plan's {planned:.2f}"]

    # --- ends ------------------------------------------------------------------------------

    def _block(self, mission, wall, reasons) -> list[Effect]:
        """Nothing can be planned until the fleet changes; the current plan stays, so the
        robots finish what they can of it."""
        mission.enter(MissionState.BLOCKED)
        if mission.blocked_since is None:
            mission.blocked_since = wall
        effects = []
        if reasons != mission.blocked:
            effects.append(Note(MissionEventKind.BLOCKED, reasons))
        mission.blocked = reasons
        return effects

    def _missing(self, unavailable) -> tuple[str, ...]:
        return tuple(f"robot '{name}' {why}" for name, why in unavailable.items() if why)

    def _fail(self, mission, reasons) -> list[Effect]:
        mission.enter(MissionState.FAILED)
        mission.failure = reasons
        return [Note(MissionEventKind.MISSION_FAILED, reasons)]

    def _complete(self, mission) -> list[Effect]:
        """Every job reported done: the mission is complete if what was executed is a valid
        schedule, and failed otherwise."""
        violations = mission.tracker.violations()
        if violations:
            return self._fail(mission, tuple(f'executed timeline: {v}' for v in violations))
        mission.enter(MissionState.COMPLETE)
        # A mission blocked for want of robots can still complete on the plan it had.
        mission.blocked, mission.blocked_since = (), None
        executed = mission.tracker.projected_makespan(0)
        return [Note(MissionEventKind.MISSION_COMPLETE,
                     ('executed makespan {}, planned {}'.format(
                         *decimals(executed, mission.planned_makespan)),))]

    # --- views -----------------------------------------------------------------------------

    @staticmethod
    def _units(mission: Mission, wall: float) -> float:
        """Schedule time at `wall` (negative before the mission start, 0 without a plan)."""
        clock = mission.clock
        return 0.0 if clock is None else clock.units(wall)

    def now_units(self, wall: float) -> float:
        """The running mission's schedule time at `wall` (0 without a mission or a plan)."""
        return 0.0 if self.mission is None else self._units(self.mission, wall)

    def _unknown(self, robot: str) -> str:
        return (f"agent of robot '{robot}' is running, but scenario "
                f"'{self.mission.problem.name}' has no such robot")

    def warnings(self, wall: float) -> tuple[str, ...]:
        mission = self.mission
        if mission is None:
            return ()
        warnings = []
        for name, why in self._unavailable(mission, wall).items():
            if why and mission.state != MissionState.WAITING_FOR_ROBOTS:
                warnings.append(f"robot '{name}' {why}")
        timeout = self.settings.heartbeat_timeout
        for name, agent in sorted(self.liveness.agents.items()):
            if name not in mission.tracker.robots and wall - agent.heard <= timeout:
                warnings.append(self._unknown(name))
        return tuple(warnings)

    def status(self, wall: float) -> StatusView | None:
        mission = self.mission
        if mission is None:
            return None
        tracker = mission.tracker
        now_units = self._units(mission, wall)
        blocked = mission.blocked
        if mission.state == MissionState.WAITING_FOR_ROBOTS:
            blocked = tuple(f"waiting for robot '{r.name}' to report"
                            + (f': its states do not verify: {unverified}'
                               if (unverified := self.liveness.silenced(r.name)) else '')
                            for r in mission.problem.robots
                            if not self.liveness.heard(r.name))
        elif mission.state in (MissionState.FAILED, MissionState.CANCELLED):
            blocked = mission.failure
        projected = float(tracker.projected_makespan(now_units)) if tracker.plan else math.nan
        return StatusView(
            mission.id, mission.problem.name, mission.state, tracker.revision,
            len(tracker.done), len(tracker.running), len(tracker.jobs),
            mission.planned_makespan, projected, max(now_units, 0.0), blocked,
            mission.replan_reasons, self.warnings(wall), Counter(tracker.ignored),
            mission.blocked_too_long, tuple(waiting.id for waiting in self.queue))

