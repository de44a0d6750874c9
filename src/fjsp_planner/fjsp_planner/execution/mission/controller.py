"""The mission as the planner runs it, without ROS: what to plan, when to re-plan, when a
mission is over.

The planner node feeds a `MissionController` what it hears (robot states, task events), what
it is asked (start or cancel a mission) and the passing of time (`tick`), and carries out the
`Effect`s each call returns: run a solve off the executor, publish a plan, declare a job done,
tell the story of the mission (`Note`). All times in are wall seconds of one clock (the ROS
clock); schedule time is derived from the mission start and the time scale.

A robot takes part in planning only while it is *available*: it has reported, it is neither
failed nor offline, and it follows the plans it is given (an agent that refuses a plan, e.g.
for a robot type it cannot play, is left out and named in the warnings; so is one that keeps
reporting an older revision than the latest, which it may never have received, until it
reports the latest). The plan records, for
each robot it counted on, the agent incarnation and failure count it saw; a robot that fails
and recovers between two ticks, or whose agent restarts, lost its tasks even though it looks
healthy, and is re-planned in. A robot whose heartbeat is lost is offline until it has been
heard again for a full heartbeat timeout, so that one late heartbeat does not re-plan twice.
"""

import math
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from fractions import Fraction

from fjsp_common.vocabulary import EventKind, MissionEventKind, MissionState, RobotMode
from fjsp_planner.execution.journal import DoneRecord, PlanRecord, Record
from fjsp_planner.execution.replan import ExecutionState, Replan, RobotState, residual_problem
from fjsp_planner.execution.tracking import Ignored, MissionTracker
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import JobAssignment, Result, Schedule, Status
from fjsp_planner.model.validate import validate

REPAIR_LIMIT = 0.5
"""Seconds the repair of a plan may take: a valid plan of what remains without search (a few
hundred ms on 5 panels), published at once; the search for a better one follows."""

EVENTS_REMEMBERED = 10000
"""Ids of the latest task events remembered per robot, to tell when the event history a
robot reports having published has arrived: twice what an agent's writer keeps for late
joiners."""

LONGEST_SEARCH = 16
"""The longest search for a better plan, in `replan_time_limit`s: searches that find nothing
better double in length up to it (1, 2, 4, 8, 16 s by default), then stop."""

IMPROVE_REACH = 0.5
"""Seconds beyond a search's time limit until its plan reaches the robots (the solver's
overrun, publishing, the agents taking it): what they do by then is kept in it."""

DUE_GRACE = 1.0
"""Seconds after a job's start fell due (its robots arrived, its predecessors complete, by
the reports the planner has) during which its robots' start reports are expected on their
way: a new plan must let it go on as if it had been reported started. Longer, a report
must be missing, and the plan is not held back for it."""

RETRY_FAILED_REPLAN = 1.0
"""Seconds after which a re-plan that failed is tried again, if no new report came first."""

PLAN_RESEND_AFTER = 2.0
"""Seconds a robot that reports may stay on an older plan revision than the latest before
the plan is published again, on a new writer: a sample lost on a matched subscription is
resent by the reliable writer long before, so the robot's subscription is likely not matched
to the writer at all."""

STARVED = 0.25
"""Seconds between two ticks beyond which the node could not take messages for a while: the
heartbeats it has not processed yet come first, before any robot is judged silent."""


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
    current_job: str = ''
    last_event: str = ''
    """The id of the latest task event the agent published ('' if none)."""


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


# --- effects: what the node must do ----------------------------------------------------

@dataclass(frozen=True)
class Solve:
    """Run a solve off the executor and hand its outcome to `MissionController.solved`.

    kind 'plan': `solve(problem)`; kind 'repair': `repair(problem, previous, state)`, a valid
    plan of what remains at once, without search; kind 'improve': `improve(published)`, a
    search from the plan just published."""

    token: int
    kind: str
    problem: Problem
    time_limit: float
    previous: Schedule | None = None
    state: ExecutionState | None = None
    reasons: tuple[str, ...] = ()
    """Why a re-plan is needed."""
    published: Replan | None = None
    """For 'improve': the repaired plan to search from."""
    frozen_until: float | None = None
    """For 'improve': the schedule time by which its plan reaches the robots; what the
    published plan has them do until then is kept (`replan.frozen`)."""
    started: frozenset[str] = frozenset()
    """For 'improve': the jobs the robots have started or done; they are kept too."""


@dataclass(frozen=True)
class PublishPlan:
    revision: int
    posed: Problem
    """What was solved: the mission's problem, or what remained of it."""
    result: Result | None
    """None for the revision that cancels a mission."""
    continued: frozenset[str]
    reasons: tuple[str, ...]
    mission_start: float
    """Wall seconds of schedule time 0."""
    cancelled: bool = False
    restarted_in: Mapping[str, int] = field(default_factory=dict)
    """Per job of the plan, the revision that last started it afresh (this one for a job
    not continued): a robot that missed that revision still knows which reports are void."""
    incarnations: Mapping[str, int] = field(default_factory=dict)
    """The agent incarnation each robot's tasks are planned for: the one it reported."""
    starts: Mapping[str, str | None] = field(default_factory=dict)
    """Where each robot started the mission (None: anywhere), which need not be where the
    scenario starts it: journaled, so a resumed mission is judged from the same places."""


@dataclass(frozen=True)
class JobDone:
    job: str
    time: float
    revision: int
    assignment: JobAssignment
    """How it was done: its plan, robots and actual times."""


@dataclass(frozen=True)
class Note:
    """Something the mission's story must tell (a MissionEvent)."""

    kind: MissionEventKind
    reasons: tuple[str, ...] = ()
    robot: str = ''
    job: str = ''
    revision: int | None = None
    """The plan revision it is about, when not the one in force when it is told (a voided
    job: the revision its completion was reported under)."""


@dataclass(frozen=True)
class ResendPlan:
    """Publish the plan of `revision` again, on a new writer: a robot has not taken it."""

    revision: int


Effect = Solve | PublishPlan | JobDone | Note | ResendPlan


@dataclass(frozen=True)
class StatusView:
    mission_id: str
    scenario: str
    state: MissionState
    revision: int
    jobs_done: int
    jobs_running: int
    jobs_total: int
    planned_makespan: float
    projected_makespan: float
    elapsed: float
    blocked: tuple[str, ...]
    replan_reasons: tuple[str, ...]
    warnings: tuple[str, ...]
    ignored: Counter
    blocked_too_long: bool
    """The mission failed because it stayed blocked beyond its `blocked_timeout`."""


# --- what the controller keeps ---------------------------------------------------------

@dataclass
class _Agent:
    """What is known of one robot's agent, across missions."""

    report: RobotReport
    heard: float
    """Wall seconds of the latest state received."""
    offline_since: float | None = None
    back_since: float | None = None
    """First report after an offline spell: it counts again a heartbeat timeout later."""
    reachable_since: float = 0.0
    """Wall seconds since when its agent could have received the latest plan: its first
    report, its first after an offline spell or a restart."""


class _RecentEvents:
    """Ids of the latest task events received from one robot, oldest first."""

    def __init__(self):
        self._ids: dict[str, None] = {}

    def add(self, event_id: str) -> None:
        self._ids[event_id] = None
        if len(self._ids) > EVENTS_REMEMBERED:
            del self._ids[next(iter(self._ids))]

    def __contains__(self, event_id: str) -> bool:
        return event_id in self._ids


@dataclass
class _Solving:
    token: int
    kind: str
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
class _Mission:
    id: str
    problem: Problem
    settings: Settings
    tracker: MissionTracker
    accepted: float
    """Wall seconds when the mission was accepted."""
    state: MissionState = MissionState.WAITING_FOR_ROBOTS
    start: float | None = None
    """Wall seconds of schedule time 0, fixed when revision 1 is published."""
    schedule: Schedule | None = None
    planned_makespan: float = math.nan
    planned: dict[str, tuple[int, int]] = field(default_factory=dict)
    """The robots the current plan (or blocked verdict) counts on: (incarnation, failures)."""
    solving: _Solving | None = None
    replan_reasons: tuple[str, ...] = ()
    blocked: tuple[str, ...] = ()
    failure: tuple[str, ...] = ()
    blocked_since: float | None = None
    foreign: set[str] = field(default_factory=set)
    """Other missions whose events arrived: each is logged once."""
    warned: set[str] = field(default_factory=set)
    pending: tuple[str, ...] = ()
    """Reasons of a re-plan still to make (one discarded or failed, jobs added, a restart)."""
    improving: _Solving | None = None
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
    resent: int = 0
    """The latest revision published again for a robot that had not taken it."""
    missed: dict[str, int] = field(default_factory=dict)
    """Robot -> the revision it did not take within `plan_uptake_timeout`: it is planned
    without until it reports the latest revision."""


class MissionController:
    def __init__(self, settings: Settings = Settings()):
        self.settings = settings
        self.agents: dict[str, _Agent] = {}
        self.events_heard: dict[str, _RecentEvents] = {}
        """Per robot (of the mission, or heard from), the task events received from it."""
        self.mission: _Mission | None = None
        self._tokens = 0
        self._last_tick: float | None = None

    # --- commands ------------------------------------------------------------------------

    def start(self, problem: Problem, mission_id: str, wall: float,
              settings: Settings | None = None) -> list[Effect]:
        """Accept a mission; raises ValueError while another one runs."""
        if self.mission is not None and not self.mission.state.ended:
            raise ValueError(f"mission '{self.mission.id}' is {self.mission.state}: one "
                             'mission per fleet at a time')
        self.mission = _Mission(mission_id, problem, settings or self.settings,
                                MissionTracker(problem), wall)
        robots = ', '.join(r.name for r in problem.robots)
        effects = [Note(MissionEventKind.MISSION_STARTED,
                        (f"scenario '{problem.name}': {len(problem.jobs)} jobs, robots "
                         f'{robots}',))]
        return effects + self.tick(wall)

    def cancel(self, reason: str, wall: float) -> list[Effect]:
        """Stop the running mission: the robots are told to drop their tasks."""
        mission = self.mission
        if mission is None or mission.state.ended:
            raise ValueError('no mission is running')
        mission.solving = mission.improving = None
        mission.state = MissionState.CANCELLED
        mission.failure = (reason,)
        effects: list[Effect] = [Note(MissionEventKind.MISSION_CANCELLED, (reason,))]
        if mission.start is not None:
            revision = self._next_revision(mission)
            mission.tracker.revision = revision
            effects.insert(0, PublishPlan(revision, mission.problem, None, frozenset(),
                                          (reason,), mission.start, cancelled=True))
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
            mission.state = (MissionState.WAITING_FOR_ROBOTS if mission.schedule is None
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
        starts = next((r.starts for r in reversed(records)
                       if isinstance(r, PlanRecord) and r.starts), {})
        if starts:
            # The mission began where the robots were, not where the scenario starts them.
            problem = replace(problem, robots=tuple(
                replace(r, start_location=starts.get(r.name, r.start_location))
                for r in problem.robots))
        mission = _Mission(mission_id, problem, settings, MissionTracker(problem), wall,
                           resumed=True)
        tracker = mission.tracker
        for record in records:
            if isinstance(record, PlanRecord) and record.schedule is not None:
                tracker.set_plan(record.schedule, record.revision, record.continued)
                mission.schedule, mission.start = record.schedule, record.start
                mission.planned_makespan = float(record.schedule.makespan)
                mission.replan_reasons = record.reasons
                mission.journaled = dict(record.incarnations)
            elif isinstance(record, DoneRecord):
                tracker.restore_done(record.assignment)
        mission.published_at = wall
        self.mission = mission
        where = (f'at plan revision {tracker.revision}, {len(tracker.done)}/'
                 f'{len(tracker.jobs)} jobs done' if mission.schedule is not None
                 else 'before its first plan')
        return [Note(MissionEventKind.MISSION_STARTED,
                     (f'resumed after a planner restart {where}',))] + self.tick(wall)

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
        behind = [r.name for r in mission.problem.robots if not self._caught_up(r.name)]
        if behind and waited < self.settings.robot_wait_timeout:
            return []
        mission.resumed = False
        effects = self._restarted_while_down(mission, wall)
        mission.planned = self._fleet(mission, self._unavailable(mission, wall))
        mission.state = MissionState.EXECUTING
        mission.pending = ('planner restarted: what remains is re-planned from where the '
                           'robots are',)
        return effects

    def _restarted_while_down(self, mission: _Mission, wall: float) -> list[Effect]:
        """Agents that restarted while no planner ran: the operations their previous
        processes had under way died with them. Their co-workers may have begun those jobs
        with them, so the jobs are aborted and redone together, as when the planner sees a
        restart itself. Told once the histories have arrived, so that every job begun is
        known to have begun."""
        effects: list[Effect] = []
        for robot, planned in sorted(mission.journaled.items()):
            agent = self.agents.get(robot)
            if not planned or agent is None or agent.report.incarnation == planned:
                continue
            effects += [Note(MissionEventKind.JOB_ABORTED,
                             (f"robot '{robot}' restarted while the planner was down: its "
                              'agent lost the operation',), job=job)
                        for job in mission.tracker.agent_restarted(
                            robot, at=self._now(mission, wall))]
        mission.journaled = {}
        return effects

    def _caught_up(self, robot: str) -> bool:
        """Whether the latest event the robot says it published has been received (events
        of one writer arrive in order, so all before it have too); true for a robot not
        heard from."""
        agent = self.agents.get(robot)
        last = agent.report.last_event if agent is not None else ''
        return not last or last in self.events_heard.get(robot, ())

    # --- what the fleet reports ----------------------------------------------------------

    def robot_state(self, report: RobotReport, wall: float) -> list[Effect]:
        agent = self.agents.get(report.robot)
        restarted = False
        if agent is None:
            agent = self.agents[report.robot] = _Agent(report, wall, reachable_since=wall)
        else:
            if agent.offline_since is not None and agent.back_since is None:
                agent.back_since = agent.reachable_since = wall
            restarted = report.incarnation != agent.report.incarnation
            if restarted:
                agent.reachable_since = wall
            agent.report, agent.heard = report, wall
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
                            report.robot, at=self._now(mission, wall))]
        if report.robot not in mission.tracker.robots:
            outcome = mission.tracker.record_robot_state(report.robot, report.mode, '', '',
                                                         math.nan)
            if outcome.repeated:
                return []
            return [Note(MissionEventKind.WARNING, (self._unknown(report.robot),),
                         robot=report.robot)]
        if agent.offline_since is not None:
            return effects  # the tracker hears it again once it counts again
        return effects + self._record(mission, report, wall)

    def _record(self, mission: _Mission, report: RobotReport, wall: float) -> list[Effect]:
        """Give the tracker a robot's report; the story of what changed."""
        effects: list[Effect] = []
        before = mission.tracker.robots[report.robot].mode
        mission.tracker.record_robot_state(report.robot, report.mode, report.location,
                                           report.destination, report.busy_until,
                                           report.current_job, at=self._now(mission, wall))
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
        if event.robot in self.agents or (mission is not None
                                           and event.robot in mission.tracker.robots):
            self.events_heard.setdefault(event.robot, _RecentEvents()).add(event.event_id)
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
        outcome = tracker.record_event(event.event_id, event.kind, event.robot, event.job,
                                       event.revision, event.time)
        if outcome.ignored:
            return [], f'{outcome.ignored} event: {outcome.reason}'
        mission.reports += 1
        effects: list[Effect] = []
        if event.kind == EventKind.ABORTED and not aborted_before \
                and event.job in tracker.aborted:
            effects.append(Note(MissionEventKind.JOB_ABORTED,
                                (f"robot '{event.robot}' aborted it",), job=event.job))
        if outcome.job_done is not None:
            job, end = outcome.job_done
            effects.append(JobDone(job, end, tracker.revision, tracker.jobs[job].done_as))
            if tracker.complete and not mission.state.ended:
                effects += self._complete(mission)
        return effects, ''

    # --- time passing --------------------------------------------------------------------

    def tick(self, wall: float, subscribers: int | None = None) -> list[Effect]:
        """Judge heartbeats, start what is due. `subscribers` counts the plan topic's
        matched readers: the first plan waits until every robot can hear it."""
        starved = self._last_tick is not None and wall - self._last_tick > STARVED
        self._last_tick = wall
        effects: list[Effect] = []
        if not starved:
            effects += self._check_heartbeats(wall)
        mission = self.mission
        if mission is None or mission.state.ended or mission.solving is not None:
            return effects
        if mission.state == MissionState.WAITING_FOR_ROBOTS:
            waited = wall - mission.accepted
            heard = all(self._heard(r.name) for r in mission.problem.robots)
            unmatched = subscribers is not None and subscribers < len(mission.problem.robots)
            if (not heard or unmatched) and waited < self.settings.robot_wait_timeout:
                return effects
            if not mission.resumed:
                return effects + self._plan(mission, wall)
            return effects + self._resume_when_caught_up(mission, wall)
        if mission.state in (MissionState.EXECUTING, MissionState.BLOCKED):
            if not starved:
                effects += self._check_uptake(mission, wall)
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
    def _may_retry(mission: _Mission, wall: float) -> bool:
        if mission.retry is None:
            return True
        reports, failed_at = mission.retry
        return mission.reports != reports or wall - failed_at >= RETRY_FAILED_REPLAN

    def _check_heartbeats(self, wall: float) -> list[Effect]:
        effects = []
        timeout = self.settings.heartbeat_timeout
        for name, agent in self.agents.items():
            silent = wall - agent.heard
            if agent.offline_since is None and silent > timeout:
                agent.offline_since, agent.back_since = wall, None
                if self.mission is not None and name in self.mission.tracker.robots:
                    self.mission.tracker.mark_offline(name, at=self._now(self.mission, wall))
                    effects.append(Note(MissionEventKind.ROBOT_OFFLINE,
                                        (f'no state for {silent:.1f} s',), robot=name))
            elif agent.back_since is not None and silent <= timeout \
                    and wall - agent.back_since >= timeout:
                agent.offline_since = agent.back_since = None
                if self.mission is not None and name in self.mission.tracker.robots:
                    effects.append(Note(MissionEventKind.ROBOT_BACK,
                                        (f'reporting again ({agent.report.mode})',),
                                        robot=name))
                    effects += self._record(self.mission, agent.report, wall)
        return effects

    def _check_uptake(self, mission: _Mission, wall: float) -> list[Effect]:
        """Robots that report, but not the latest revision: the plan is published again
        after PLAN_RESEND_AFTER, and they are planned without after `plan_uptake_timeout`,
        until they report it."""
        if mission.schedule is None or mission.published_at is None:
            return []
        revision, effects = mission.tracker.revision, []
        for robot in mission.problem.robots:
            agent = self.agents.get(robot.name)
            if agent is None or agent.offline_since is not None:
                continue
            waited = wall - max(mission.published_at, agent.reachable_since)
            report = agent.report
            if report.refusal:
                continue  # it has the plan, and says why it does not follow it
            if report.mission_id == mission.id and report.revision >= revision:
                mission.missed.pop(robot.name, None)
                continue
            if waited < PLAN_RESEND_AFTER:
                continue
            told = f'uptake {robot.name} {revision}'
            if told not in mission.warned:
                mission.warned.add(told)
                effects.append(Note(MissionEventKind.WARNING, (
                    f"robot '{robot.name}' has not taken plan revision {revision} for "
                    f'{waited:.1f} s: published again',), robot=robot.name))
            if mission.resent < revision:
                mission.resent = revision
                effects.append(ResendPlan(revision))
            if waited >= self.settings.plan_uptake_timeout:
                mission.missed.setdefault(robot.name, revision)
        return effects

    def _heard(self, robot: str) -> bool:
        agent = self.agents.get(robot)
        return agent is not None and agent.offline_since is None

    # --- solving ---------------------------------------------------------------------------

    def _unavailable(self, mission: _Mission, wall: float) -> dict[str, str]:
        """Robot -> why it cannot take part in planning now ('' if it can)."""
        why = {}
        for robot in mission.problem.robots:
            agent = self.agents.get(robot.name)
            if agent is None:
                why[robot.name] = (f'has not reported since the mission was accepted '
                                   f'{wall - mission.accepted:.0f} s ago')
            elif agent.offline_since is not None:
                why[robot.name] = 'offline (heartbeat lost)'
            elif agent.report.mode == RobotMode.FAILED:
                why[robot.name] = 'failed'
            elif agent.report.refusal:
                why[robot.name] = f'refuses its plan: {agent.report.refusal}'
            elif robot.name in mission.missed:
                why[robot.name] = (f'has not taken plan revision {mission.missed[robot.name]} '
                                   f'within {self.settings.plan_uptake_timeout:g} s')
            else:
                why[robot.name] = ''
        return why

    def _fleet(self, mission: _Mission, unavailable: dict[str, str]) -> dict:
        return {name: (self.agents[name].report.incarnation, self.agents[name].report.failures)
                for name, why in unavailable.items() if not why}

    def _plan(self, mission: _Mission, wall: float) -> list[Effect]:
        """The first plan of the mission, for the robots available now, from where they are."""
        unavailable = self._unavailable(mission, wall)
        fleet = self._fleet(mission, unavailable)
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
        mission.state = MissionState.PLANNING
        return [self._solve(mission, 'plan', fleet, (), posed, mission.settings.time_limit)]

    def _initial_state(self, mission: _Mission, fleet) -> ExecutionState | None:
        """Where the robots are at the mission start, when that is not simply what the
        scenario says: some robots are out, or the last mission left them somewhere the
        scenario knows."""
        problem = mission.problem
        locations = set(problem.locations())
        robots, moved = {}, False
        for robot in problem.robots:
            agent = self.agents.get(robot.name)
            at = agent.report.destination or agent.report.location if agent else ''
            location = robot.start_location
            if robot.name in fleet and at in locations and at != location:
                location, moved = at, True
            robots[robot.name] = RobotState(robot.name, robot.name in fleet, location,
                                            robot.release_time)
        if not moved and len(fleet) == len(problem.robots):
            return None
        return ExecutionState(Fraction(0), frozenset(), {}, robots)

    def _replan(self, mission: _Mission, wall: float, reasons: tuple[str, ...]
                ) -> list[Effect]:
        unavailable = self._unavailable(mission, wall)
        fleet = self._fleet(mission, unavailable)
        try:
            state = mission.tracker.execution_state(self._now(mission, wall))
        except ValueError as error:
            mission.planned = fleet
            return self._block(mission, wall, (f'cannot tell the execution state: {error}',))
        # The tracker knows failed and offline robots; refusing and silent ones are out too.
        state = replace(state, robots={name: replace(robot, healthy=name in fleet)
                                       for name, robot in state.robots.items()})
        mission.state = MissionState.REPLANNING
        mission.improving = None  # a search from an older state would only be discarded
        limit = min(REPAIR_LIMIT, mission.settings.replan_time_limit)
        return [self._solve(mission, 'repair', fleet, reasons, mission.problem, limit,
                            mission.schedule, state)]

    def _solve(self, mission, kind, fleet, reasons, problem, time_limit, previous=None,
               state=None) -> Solve:
        self._tokens += 1
        mission.solving = _Solving(self._tokens, kind, problem, fleet, reasons, state)
        return Solve(self._tokens, kind, problem, time_limit, previous, state, reasons)

    def _improve(self, mission, solving: _Solving, published: Replan, wall: float,
                 time_limit: float | None = None) -> Solve:
        """Search for a better plan from the one just published, while it is followed: the
        robots go on with what it has them do until the search's plan can reach them."""
        self._tokens += 1
        limit = time_limit or mission.settings.replan_time_limit
        mission.improving = replace(solving, token=self._tokens, kind='improve',
                                    time_limit=limit, published=published)
        # Robots start a job as soon as its robots and predecessors are ready, so they may
        # be ahead of the plan: what they started is kept too.
        started = frozenset(name for name, record in mission.tracker.jobs.items()
                            if record.begun)
        return Solve(self._tokens, 'improve', published.residual.problem, limit,
                     state=solving.state, reasons=solving.reasons, published=published,
                     frozen_until=self._now(mission, wall + limit + IMPROVE_REACH),
                     started=started)

    def solved(self, token: int, outcome, wall: float) -> list[Effect]:
        """The outcome of `Solve` `token`: a `Result` ('plan'), a `Replan` ('replan'), or
        the ValueError the solver raised. Outcomes of superseded solves are dropped."""
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
        fleet_now = self._fleet(mission, self._unavailable(mission, wall))
        if solving.kind == 'plan':
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
            mission.state = MissionState.EXECUTING
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
            mission.state = MissionState.EXECUTING
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
        continued = frozenset(residual.problem.fixed)
        progressed = self._progressed(mission, solving, residual.problem, wall)
        if progressed and not self._goes_on(mission, result.schedule, progressed, continued):
            # Restarting these would redo work done meanwhile: plan again from now.
            mission.state = MissionState.EXECUTING
            mission.pending = solving.reasons
            return [Note(MissionEventKind.WARNING,
                         ('re-plan discarded: ' + ', '.join(f"job '{j}'" for j in progressed)
                          + ' progressed while it was solved',))]
        notes = [Note(MissionEventKind.JOB_VOIDED, ('its hold was lost',), job=job,
                      revision=mission.tracker.revision) for job in residual.voided]
        mission.blocked, mission.blocked_since = (), None
        continued |= frozenset(progressed)
        continued |= self._unchanged(mission, result.schedule, continued)
        published = self._publish(mission, residual.problem, result, continued,
                                  solving.reasons, wall)
        if result.status == Status.OPTIMAL:
            return notes + published
        return notes + published + [self._improve(mission, solving, replanned, wall)]

    def _improved(self, mission, solving: _Solving, outcome, wall: float) -> list[Effect]:
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
        if self._fleet(mission, self._unavailable(mission, wall)) != solving.fleet:
            return []
        if not outcome.improved:
            kept = outcome.replan.result
            if kept.lower_bound is not None and kept.lower_bound >= kept.makespan:
                return []
            return self._search_longer(mission, solving, outcome.replan, wall)
        better = outcome.replan
        continued = frozenset(better.residual.problem.fixed)
        progressed = self._progressed(mission, solving, better.residual.problem, wall)
        if progressed and not self._goes_on(mission, better.schedule, progressed, continued):
            # The robots got further than the search kept: the plan cannot be followed.
            dropped = Note(MissionEventKind.WARNING, (
                f'a better plan (makespan {float(better.result.makespan):.2f}) dropped: '
                + ', '.join(f"job '{j}'" for j in progressed)
                + ' progressed while it was searched for',))
            return [dropped] + self._search_longer(mission, solving, solving.published, wall)
        reason = (f'a better plan: makespan {mission.planned_makespan:.2f} -> '
                  f'{float(better.result.makespan):.2f}')
        continued |= frozenset(progressed)
        continued |= self._unchanged(mission, better.schedule, continued)
        published = self._publish(mission, better.residual.problem, better.result, continued,
                                  (reason,), wall)
        if better.result.status == Status.OPTIMAL:
            return published
        return published + [self._improve(mission, solving, better, wall,
                                          solving.time_limit)]

    def _search_longer(self, mission, solving: _Solving, published: Replan, wall: float
                       ) -> list[Effect]:
        """After a search that gave no plan to publish: one twice as long from `published`,
        up to LONGEST_SEARCH times `replan_time_limit`."""
        longer = 2 * solving.time_limit
        if longer > LONGEST_SEARCH * mission.settings.replan_time_limit:
            return []
        return [self._improve(mission, solving, published, wall, longer)]

    def _progressed(self, mission, solving: _Solving, posed: Problem, wall: float
                    ) -> list[str]:
        """Jobs the new plan starts afresh that started or completed since it was posed, or
        whose start fell due within the last DUE_GRACE seconds: their robots, all available
        when it was posed and none failed or restarted since the current plan, start them
        on reports the planner has too, so their start reports are on their way."""
        tracker = mission.tracker
        recent = self._now(mission, wall) - DUE_GRACE / mission.settings.time_scale
        shaken = tracker.failed_since(tracker.revision)
        moved = []
        for job in posed.jobs:
            if job.name in posed.fixed:
                continue
            if job.name in solving.state.running or job.name in solving.state.done:
                continue
            if tracker.jobs[job.name].begun:
                moved.append(job.name)
                continue
            due = tracker.due_start(job.name)
            if due is None or due < recent:
                continue
            robots = tracker.plan.jobs[job.name].robots
            if not shaken & set(robots) and all(r in solving.fleet for r in robots):
                moved.append(job.name)
        return moved

    def _goes_on(self, mission, schedule: Schedule, progressed, continued) -> bool:
        """Whether the new plan can let the jobs that progressed while it was solved go on
        as they are (continued, not redone): it gives each the plan and robots it runs with,
        and each of those robots does them first, in the order it began them, before any
        job the plan starts afresh — so every robot's next leg leaves from where it is."""
        tracker = mission.tracker
        order = sorted(progressed, key=lambda job: tracker.jobs[job].start
                       if tracker.jobs[job].begun else tracker.due_start(job))
        for job in order:
            running, new = tracker.plan.jobs[job], schedule.jobs.get(job)
            if new is None or new.plan != running.plan \
                    or dict(new.robots) != dict(running.robots):
                return False
        for robot in {r for job in order for r in tracker.plan.jobs[job].robots}:
            mine = [job for job in order if robot in tracker.plan.jobs[job].robots]
            fresh = [job for job in schedule.sequences.get(robot, ()) if job not in continued]
            if fresh[:len(mine)] != mine:
                return False
        return True

    def _unchanged(self, mission, schedule: Schedule, continued) -> frozenset[str]:
        """Jobs not begun that the new plan leaves as the old one had them: the same plan and
        robots, none of which failed or restarted since the old plan, and for each of those
        robots next in both the old and the new order, after what goes on. They go on rather
        than start afresh: a robot may have arrived at one, or started it, on reports still
        on their way to the planner, and starting it afresh would void those arrivals and
        have its robots do it twice."""
        tracker = mission.tracker
        old = tracker.plan
        # What a robot that failed or restarted since reported no longer holds.
        shaken = tracker.failed_since(tracker.revision)

        def same(job: str) -> bool:
            was, new, record = old.jobs.get(job), schedule.jobs.get(job), tracker.jobs[job]
            return (was is not None and new is not None and not record.begun
                    and not record.aborted and new.plan == was.plan
                    and dict(new.robots) == dict(was.robots) and not shaken & set(new.robots))

        heads = {}
        for robot, sequence in schedule.sequences.items():
            # A job begun and started afresh is still ahead of its robots in both orders.
            before = [job for job in old.sequences.get(robot, ())
                      if job not in continued and tracker.jobs[job].end is None]
            after = [job for job in sequence if job not in continued]
            head = []
            for a, b in zip(before, after, strict=False):
                if a != b or not same(a):
                    break
                head.append(a)
            heads[robot] = head
        while True:
            kept = {job for head in heads.values() for job in head
                    if all(job in heads.get(r, ()) for r in schedule.jobs[job].robots)}
            cut = {robot: head[:next((i for i, job in enumerate(head) if job not in kept),
                                     len(head))]
                   for robot, head in heads.items()}
            if cut == heads:
                return frozenset(kept)
            heads = cut

    def _publish(self, mission, posed, result, continued, reasons, wall) -> list[Effect]:
        tracker = mission.tracker
        mission.published_at = wall
        revision = self._next_revision(mission)
        tracker.set_plan(result.schedule, revision, continued)
        mission.schedule = result.schedule
        mission.planned_makespan = float(result.makespan)
        mission.replan_reasons = reasons
        mission.state = MissionState.EXECUTING
        starts = {r.name: r.start_location for r in mission.problem.robots}
        incarnations = {name: planned[0] for name, planned in mission.planned.items()}
        restarted_in = {job: tracker.jobs[job].since_revision for job in result.schedule.jobs}
        return [PublishPlan(revision, posed, result, continued, reasons, mission.start,
                            restarted_in=restarted_in, incarnations=incarnations,
                            starts=starts),
                Note(MissionEventKind.PLAN_PUBLISHED, reasons)]

    def _next_revision(self, mission: _Mission) -> int:
        """Above any revision a robot follows: after a restart, the journal may lag them."""
        followed = [a.report.revision for a in self.agents.values()
                    if a.report.mission_id == mission.id]
        return max([mission.tracker.revision, *followed]) + 1

    def _replan_reasons(self, mission: _Mission, wall: float) -> list[str]:
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
                report = self.agents[name].report
                if report.incarnation != planned[0]:
                    reasons.append(f"robot '{name}' restarted: its agent lost its tasks")
                elif report.failures != planned[1]:
                    reasons.append(f"robot '{name}' failed and recovered")
        if mission.state == MissionState.EXECUTING:
            tracker = mission.tracker
            reasons += [f"job '{j}' aborted" for j in sorted(tracker.aborted)]
            reasons += tracker.overruns(self.settings.delay_threshold)
        return reasons

    # --- ends ------------------------------------------------------------------------------

    def _block(self, mission, wall, reasons) -> list[Effect]:
        """Nothing can be planned until the fleet changes; the current plan stays, so the
        robots finish what they can of it."""
        mission.state = MissionState.BLOCKED
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
        mission.state = MissionState.FAILED
        mission.failure = reasons
        return [Note(MissionEventKind.MISSION_FAILED, reasons)]

    def _complete(self, mission) -> list[Effect]:
        """Every job reported done: the mission is complete if what was executed is a valid
        schedule, and failed otherwise."""
        violations = mission.tracker.violations()
        if violations:
            return self._fail(mission, tuple(f'executed timeline: {v}' for v in violations))
        mission.state = MissionState.COMPLETE
        # A mission blocked for want of robots can still complete on the plan it had.
        mission.blocked, mission.blocked_since = (), None
        executed = float(mission.tracker.projected_makespan(0))
        return [Note(MissionEventKind.MISSION_COMPLETE,
                     (f'executed makespan {executed:.2f}, planned '
                      f'{mission.planned_makespan:.2f}',))]

    # --- views -----------------------------------------------------------------------------

    def _now(self, mission: _Mission, wall: float) -> float:
        """Schedule time since the mission start (negative before it, 0 without a plan)."""
        if mission.start is None:
            return 0.0
        return (wall - mission.start) / mission.settings.time_scale

    def now_units(self, wall: float) -> float:
        return 0.0 if self.mission is None else self._now(self.mission, wall)

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
        for name, agent in sorted(self.agents.items()):
            if name not in mission.tracker.robots and wall - agent.heard <= timeout:
                warnings.append(self._unknown(name))
        return tuple(warnings)

    def status(self, wall: float) -> StatusView | None:
        mission = self.mission
        if mission is None:
            return None
        tracker = mission.tracker
        now = self._now(mission, wall)
        blocked = mission.blocked
        if mission.state == MissionState.WAITING_FOR_ROBOTS:
            blocked = tuple(f"waiting for robot '{r.name}' to report"
                            for r in mission.problem.robots if not self._heard(r.name))
        elif mission.state in (MissionState.FAILED, MissionState.CANCELLED):
            blocked = mission.failure
        projected = float(tracker.projected_makespan(now)) if tracker.plan else math.nan
        return StatusView(
            mission.id, mission.problem.name, mission.state, tracker.revision,
            len(tracker.done), len(tracker.running), len(tracker.jobs),
            mission.planned_makespan, projected, max(now, 0.0), blocked,
            mission.replan_reasons, self.warnings(wall), Counter(tracker.ignored),
            mission.blocked_too_long)

