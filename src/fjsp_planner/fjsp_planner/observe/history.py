"""The whole of each mission, rebuilt from the facts the fleet publishes.

A plan revision replaces the one before it, so a view built from the latest plan forgets what
was done under earlier ones. `MissionHistory` keeps every revision, every task event, every
mission event and every change of each robot's state, and derives from them:

- each **attempt** of each job: the robots that started it, and how it ended (done; aborted
  when a robot on it failed or a re-plan restarted it while it ran; voided when a re-plan
  restarted it after it was done, e.g. a jig job whose holder failed);
- each robot's **health spans**: failed (it said so) and offline (its heartbeat stopped);
- each robot's **activities**: travelling, waiting, working, holding, idle;
- the **revisions** with the reasons they were planned (the story told from all this is in
  `story`).

Everything is derived on demand from sets of facts, so the result does not depend on the
order in which messages of different topics arrive: the live monitor and a replay of the
recording of the same mission build the same history. Events are grouped into attempts by the
revision that started their job afresh (`PlanTask.continued` false, or `restarted_in` of a
later plan that continues it). A history that missed early plans (a monitor started late
gets only the latched latest plan) also takes the revisions its STARTED events carry.

Times are schedule units since the mission start; stamps are wall seconds since the epoch.
A robot is offline while no state of it is stamped within `heartbeat_timeout` seconds: gaps
are measured between the robots' own stamps, so a monitor that is slow to take its messages
does not see robots go offline (hosts must keep their clocks in sync, as the mission start
time already requires).
"""

import math
from collections import Counter, defaultdict
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum

from fjsp_common.fleet import HEARTBEAT_TIMEOUT
from fjsp_common.vocabulary import EventKind, MissionEventKind, MissionState, RobotMode
from fjsp_planner.observe.facts import (
    Fact,
    MissionEventFact,
    PlanFact,
    PlannedTask,
    RobotStateFact,
    StatusFact,
    TaskEventFact,
)


class Outcome(StrEnum):
    RUNNING = 'running'
    DONE = 'done'
    ABORTED = 'aborted'
    VOIDED = 'voided'


@dataclass(frozen=True)
class Attempt:
    """One go at a job: from its start by its robots to how it ended."""

    job: str
    number: int
    """1 for the first attempt of the job, 2 for the one redoing it, ..."""
    revision: int
    """The revision that started the job afresh for this attempt (0: not known)."""
    started: Mapping[str, float]
    """Robot -> when it started its operation."""
    operation_done: Mapping[str, float]
    outcome: Outcome
    finish: float | None
    """When the work ended (completion or abort); None while it runs."""
    outcome_time: float | None
    """When the outcome was decided: = finish, except for voided attempts (the re-plan)."""
    reason: str = ''

    @property
    def start(self) -> float:
        return min(self.started.values())

    @property
    def robots(self) -> tuple[str, ...]:
        return tuple(sorted(self.started, key=lambda r: (self.started[r], r)))


@dataclass(frozen=True)
class Span:
    """A robot out of service: failed (it said so) or offline (heartbeat lost)."""

    robot: str
    kind: str
    start: float
    end: float | None
    """When it was back in service; None while it is out."""


@dataclass(frozen=True)
class Activity:
    robot: str
    mode: RobotMode
    job: str
    start: float
    end: float | None
    """None: still going on."""
    location: str = ''
    destination: str = ''


@dataclass(frozen=True)
class Revision:
    number: int
    published: float
    reasons: tuple[str, ...]
    makespan: float
    solver_status: str
    lower_bound: float


@dataclass(frozen=True)
class Counts:
    done: int
    running: int
    total: int
    aborted: int
    """Attempts aborted (each is redone)."""
    voided: int
    """Done attempts voided (each is redone)."""


def _trail_key(state: RobotStateFact) -> tuple:
    return (state.mode, state.current_job, state.location, state.destination, state.revision,
            state.refusal, state.robot_type, state.incarnation)


def _status_key(status: StatusFact) -> tuple:
    return (status.state, status.revision, status.blocked_reasons, status.replan_reasons,
            status.warnings)


@dataclass
class _Group:
    """Everything reported about one job under the revisions of one attempt."""

    started: dict[str, float] = field(default_factory=dict)
    operation_done: dict[str, float] = field(default_factory=dict)
    done: float | None = None
    aborted: TaskEventFact | None = None
    aborted_event: MissionEventFact | None = None
    voided_event: MissionEventFact | None = None
    first_time: float = math.inf


class MissionHistory:
    """Every fact of one mission (one mission id) and what they add up to."""

    def __init__(self, mission_id: str):
        self.mission_id = mission_id
        self.plans: dict[int, PlanFact] = {}
        self.task_events: dict[str, TaskEventFact] = {}
        self.mission_events: dict[str, MissionEventFact] = {}
        self.status: StatusFact | None = None
        self.status_changes: list[StatusFact] = []
        self.trails: dict[str, list[RobotStateFact]] = defaultdict(list)
        """Per robot, its states that changed something but progress (by stamp)."""
        self.silences: dict[str, list[tuple[float, float]]] = defaultdict(list)
        """Per robot, (last stamp before, first stamp after) of each heartbeat gap."""
        self.last_stamp = -math.inf
        self.version = 0
        self._cache: dict[str, object] = {}
        self._cached_version = -1

    # --- facts ---------------------------------------------------------------------------

    def _changed(self, stamp: float) -> bool:
        self.version += 1
        self.last_stamp = max(self.last_stamp, stamp)
        return True

    def add_plan(self, plan: PlanFact) -> bool:
        if plan.revision in self.plans:
            return False
        self.plans[plan.revision] = plan
        return self._changed(plan.stamp)

    def add_task_event(self, event: TaskEventFact) -> bool:
        if event.event_id in self.task_events:
            return False
        self.task_events[event.event_id] = event
        return self._changed(event.stamp)

    def add_mission_event(self, event: MissionEventFact) -> bool:
        if event.event_id in self.mission_events:
            return False
        self.mission_events[event.event_id] = event
        return self._changed(event.stamp)

    def add_status(self, status: StatusFact) -> bool:
        """Whether it is news. Only a change of state or reasons changes what is derived
        (`version`); the clock and counters in every periodic status do not."""
        if self.status is not None and status.stamp <= self.status.stamp:
            return False
        self.status = status
        self.last_stamp = max(self.last_stamp, status.stamp)
        if not self.status_changes or _status_key(self.status_changes[-1]) != \
                _status_key(status):
            self.status_changes.append(status)
            self._changed(status.stamp)
        return True

    def add_robot_state(self, state: RobotStateFact) -> bool:
        trail = self.trails[state.robot]
        if trail and (state.stamp <= trail[-1].stamp or _trail_key(trail[-1]) ==
                      _trail_key(state)):
            return False
        trail.append(state)
        return self._changed(state.stamp)

    def add_silence(self, robot: str, since: float, until: float) -> bool:
        self.silences[robot].append((since, until))
        return self._changed(until)

    # --- time ----------------------------------------------------------------------------

    @property
    def first_plan(self) -> PlanFact | None:
        return self.plans[min(self.plans)] if self.plans else None

    @property
    def last_plan(self) -> PlanFact | None:
        return self.plans[max(self.plans)] if self.plans else None

    def units(self, stamp: float) -> float | None:
        """Schedule time of a wall stamp (None before any plan says when the mission began)."""
        clock = self.first_plan.clock if self.plans else None
        return None if clock is None else clock.units(stamp)

    @property
    def scenario_id(self) -> str:
        for source in (self.last_plan, self.status):
            if source is not None and source.scenario_id:
                return source.scenario_id
        return ''

    def robot_names(self) -> list[str]:
        """The scenario's robots in the plan's order, then any other that reported."""
        names = [robot for robot, _ in self.last_plan.robots] if self.plans else []
        for plan in self.plans.values():
            names += [robot for robot, _ in plan.robots if robot not in names]
        return names + sorted(set(self.trails) - set(names))

    def jobs(self) -> list[str]:
        """Every job of the mission: all revisions together (later ones leave done jobs out,
        and jobs added mid-mission appear only in later ones)."""
        seen = {}
        for revision in sorted(self.plans):
            for task in self.plans[revision].tasks:
                seen.setdefault(task.job, None)
        if 1 not in self.plans:
            # Joined late: jobs done before the latched plan are known from their events.
            for event in self.task_events.values():
                seen.setdefault(event.job, None)
        return list(seen)

    def tasks_of(self, revision: int, job: str) -> list[PlannedTask]:
        plan = self.plans.get(revision)
        return [t for t in plan.tasks if t.job == job] if plan else []

    # --- what it adds up to --------------------------------------------------------------

    def cached(self, name: str, compute):
        """`compute()`, computed again only once a fact was added since."""
        if self._cached_version != self.version:
            self._cache.clear()
            self._cached_version = self.version
        if name not in self._cache:
            self._cache[name] = compute()
        return self._cache[name]

    def revisions(self) -> list[Revision]:
        return self.cached('revisions', self._revisions)

    def _revisions(self) -> list[Revision]:
        revisions = {}
        for plan in self.plans.values():
            published = self.units(plan.stamp)
            revisions[plan.revision] = Revision(plan.revision, published, plan.reasons,
                                                plan.makespan, plan.solver_status,
                                                plan.lower_bound)
        for event in self.mission_events.values():
            if event.kind == MissionEventKind.PLAN_PUBLISHED \
                    and event.revision not in revisions:
                revisions[event.revision] = Revision(event.revision, event.time, event.reasons,
                                                     math.nan, '', math.nan)
        return [revisions[r] for r in sorted(revisions)]

    def attempts(self) -> list[Attempt]:
        return self.cached('attempts', self._attempts)

    def _attempts(self) -> list[Attempt]:
        restarts: dict[str, set[int]] = defaultdict(set)
        spans: dict[str, set[tuple[int, int]]] = defaultdict(set)
        """Per job, revisions known to run one attempt: from its restart to a plan continuing
        it."""
        for plan in self.plans.values():
            for task in plan.tasks:
                since = task.attempt_since(plan.revision)
                restarts[task.job].add(since)
                if since:
                    spans[task.job].add((since, plan.revision))
        for event in self.task_events.values():
            if event.kind == EventKind.STARTED and event.revision not in self.plans and not any(
                    since <= event.revision <= until for since, until in spans[event.job]):
                restarts[event.job].add(event.revision)
        groups: dict[str, dict[int, _Group]] = defaultdict(dict)

        def group(job: str, revision: int) -> _Group:
            boundary = max((b for b in restarts[job] if b <= revision), default=0)
            return groups[job].setdefault(boundary, _Group())

        for e in self.task_events.values():
            g = group(e.job, e.revision)
            g.first_time = min(g.first_time, e.time)
            if e.kind == EventKind.STARTED:
                g.started.setdefault(e.robot, e.time)
            elif e.kind == EventKind.OPERATION_DONE:
                g.operation_done.setdefault(e.robot, e.time)
            elif e.kind == EventKind.JOB_DONE:
                g.done = e.time if g.done is None else min(g.done, e.time)
            elif e.kind == EventKind.ABORTED and (g.aborted is None or e.time < g.aborted.time):
                g.aborted = e
        for e in self.mission_events.values():
            if e.kind == MissionEventKind.JOB_ABORTED and e.job:
                group(e.job, e.revision).aborted_event = e
            elif e.kind == MissionEventKind.JOB_VOIDED and e.job:
                group(e.job, e.revision).voided_event = e

        attempts = []
        for job in sorted(groups):
            boundaries = sorted(groups[job])
            number = 0
            for boundary in boundaries:
                g = groups[job][boundary]
                if not g.started:
                    continue
                number += 1
                later = sorted(b for b in restarts[job] if b > boundary)
                replanned = None
                if later:
                    plan = self.plans.get(later[0])
                    following = groups[job].get(later[0])
                    replanned = (self.units(plan.stamp) if plan is not None
                                 else following.first_time if following else None)
                attempts.append(self._attempt(job, number, boundary, g, later, replanned))
        return sorted(attempts, key=lambda a: (a.start, a.job, a.number))

    @staticmethod
    def _attempt(job, number, boundary, g: _Group, later, replanned) -> Attempt:
        base = dict(job=job, number=number, revision=boundary, started=dict(g.started),
                    operation_done=dict(g.operation_done))
        if g.done is not None:
            if g.voided_event is not None or later:
                when = g.voided_event.time if g.voided_event is not None else replanned
                reason = ('; '.join(g.voided_event.reasons) if g.voided_event is not None
                          else f'redone from revision {later[0]}')
                return Attempt(**base, outcome=Outcome.VOIDED, finish=g.done,
                               outcome_time=when, reason=reason)
            return Attempt(**base, outcome=Outcome.DONE, finish=g.done, outcome_time=g.done)
        if g.aborted is not None:
            reason = g.aborted.reason or f"robot '{g.aborted.robot}' aborted it"
            return Attempt(**base, outcome=Outcome.ABORTED, finish=g.aborted.time,
                           outcome_time=g.aborted.time, reason=reason)
        if g.aborted_event is not None:
            e = g.aborted_event
            return Attempt(**base, outcome=Outcome.ABORTED, finish=e.time, outcome_time=e.time,
                           reason='; '.join(e.reasons))
        if later:
            return Attempt(**base, outcome=Outcome.ABORTED, finish=replanned,
                           outcome_time=replanned, reason=f'restarted by revision {later[0]}')
        return Attempt(**base, outcome=Outcome.RUNNING, finish=None, outcome_time=None)

    def latest_attempts(self) -> dict[str, Attempt]:
        """Each job's latest attempt."""
        return self.cached('latest', self._latest_attempts)

    def _latest_attempts(self) -> dict[str, Attempt]:
        latest = {}
        for attempt in self.attempts():
            if attempt.job not in latest or attempt.number > latest[attempt.job].number:
                latest[attempt.job] = attempt
        return latest

    def counts(self) -> Counts:
        return self.cached('counts', self._counts)

    def _counts(self) -> Counts:
        latest = self.latest_attempts().values()
        outcomes = Counter(a.outcome for a in self.attempts())
        return Counts(done=sum(a.outcome == Outcome.DONE for a in latest),
                      running=sum(a.outcome == Outcome.RUNNING for a in latest),
                      total=len(self.jobs()), aborted=outcomes[Outcome.ABORTED],
                      voided=outcomes[Outcome.VOIDED])

    def agrees_with_status(self) -> bool:
        """Whether the jobs done and in total agree with the planner's latest status."""
        s, c = self.status, self.counts()
        return s is not None and (s.jobs_done, s.jobs_total) == (c.done, c.total)

    def executed_makespan(self) -> float | None:
        ends = [a.finish for a in self.latest_attempts().values() if a.outcome == Outcome.DONE]
        return max(ends) if ends else None

    @property
    def state(self) -> MissionState | None:
        return self.status.state if self.status is not None else None

    @property
    def ended(self) -> bool:
        return self.state is not None and self.state.ended

    @property
    def ended_at(self) -> float | None:
        """Schedule time the planner first reported the mission ended (its later statuses
        keep counting time, so this is what a live view and a replay agree on)."""
        return next((s.elapsed for s in self.status_changes if s.state.ended), None)

    # --- robots --------------------------------------------------------------------------

    def spans(self, silent: Mapping[str, float] = {}) -> list[Span]:  # noqa: B006 (read only)
        """Health spans; `silent` names robots silent right now (robot -> last stamp), whose
        offline span is still open."""
        spans = list(self.cached('spans', self._recorded_spans))
        for robot, since in silent.items():
            start = self.units(since)
            if start is not None and robot in self.trails:
                spans.append(Span(robot, 'offline', start, None))
        return sorted(spans, key=lambda s: (s.start, s.robot))

    def _recorded_spans(self) -> list[Span]:
        spans = []
        for robot in self.robot_names():
            facts = self._health_facts(robot)
            opened = None
            for time, kind in sorted(facts, key=lambda f: (f[0], f[1] == 'back')):
                if kind == 'back':
                    if opened is not None:
                        spans.append(Span(robot, opened[1], opened[0], time))
                        opened = None
                elif opened is None:
                    opened = (time, kind)
            if opened is not None:
                spans.append(Span(robot, opened[1], opened[0], None))
        return spans

    def _health_facts(self, robot: str) -> list[tuple[float, str]]:
        """(time, 'failed' | 'offline' | 'back'), from the robot's own states when this
        history has them, else from the planner's mission events."""
        facts = []
        trail = self.trails.get(robot, [])
        if trail:
            failed = False
            for state in trail:
                time = self.units(state.stamp)
                if time is None:
                    continue
                if state.mode == RobotMode.FAILED and not failed:
                    facts.append((time, 'failed'))
                elif state.mode != RobotMode.FAILED and failed:
                    facts.append((time, 'back'))
                failed = state.mode == RobotMode.FAILED
            for since, until in self.silences.get(robot, []):
                start, end = self.units(since), self.units(until)
                if start is not None:
                    facts += [(start, 'offline'), (end, 'back')]
            return facts
        kinds = {MissionEventKind.ROBOT_FAILED: 'failed', MissionEventKind.ROBOT_OFFLINE:
                 'offline', MissionEventKind.ROBOT_BACK: 'back'}
        return [(e.time, kinds[e.kind]) for e in self.mission_events.values()
                if e.robot == robot and e.kind in kinds]

    def activities(self) -> list[Activity]:
        return self.cached('activities', self._activities)

    def _activities(self) -> list[Activity]:
        activities = []
        for robot, trail in self.trails.items():
            silences = sorted(self.silences.get(robot, []))
            for index, state in enumerate(trail):
                start = self.units(state.stamp)
                if start is None:
                    continue
                until = trail[index + 1].stamp if index + 1 < len(trail) else None
                cut = [s for s, _ in silences if s >= state.stamp
                       and (until is None or s < until)]
                if cut:
                    until = min(cut)
                activities.append(Activity(
                    robot, state.mode, state.current_job, start,
                    None if until is None else self.units(until), state.location,
                    state.destination))
            for since, until in silences:
                activities.append(Activity(robot, RobotMode.OFFLINE, '', self.units(since),
                                           self.units(until)))
        return sorted(activities, key=lambda a: (a.start, a.robot))

    def last_state(self, robot: str) -> RobotStateFact | None:
        trail = self.trails.get(robot)
        return trail[-1] if trail else None


class FleetHistory:
    """Every mission seen on one fleet (by mission id), and each robot's latest state."""

    def __init__(self, heartbeat_timeout: float = HEARTBEAT_TIMEOUT):
        self.heartbeat_timeout = heartbeat_timeout
        self.missions: dict[str, MissionHistory] = {}
        self.robots: dict[str, RobotStateFact] = {}
        """Each robot's latest state, whatever mission it follows."""
        self.idle_status: StatusFact | None = None
        """The planner's latest status while it has no mission."""
        self.version = 0

    def mission(self, mission_id: str) -> MissionHistory:
        if mission_id not in self.missions:
            self.missions[mission_id] = MissionHistory(mission_id)
        return self.missions[mission_id]

    def add(self, fact: Fact) -> bool:
        """Take one fact; whether it changed anything."""
        if isinstance(fact, RobotStateFact):
            changed = self._add_robot_state(fact)
        elif isinstance(fact, StatusFact) and not fact.mission_id:
            changed = self.idle_status is None or fact.stamp >= self.idle_status.stamp
            if changed:
                self.idle_status = fact
        elif isinstance(fact, StatusFact):
            changed = self.mission(fact.mission_id).add_status(fact)
        elif isinstance(fact, PlanFact):
            changed = self.mission(fact.mission_id).add_plan(fact)
        elif isinstance(fact, TaskEventFact):
            changed = self.mission(fact.mission_id).add_task_event(fact)
        else:
            changed = self.mission(fact.mission_id).add_mission_event(fact)
        if changed:
            self.version += 1
        return changed

    def _add_robot_state(self, state: RobotStateFact) -> bool:
        previous = self.robots.get(state.robot)
        if previous is not None and state.stamp <= previous.stamp:
            return False
        self.robots[state.robot] = state
        if previous is not None and previous.mission_id \
                and state.stamp - previous.stamp > self.heartbeat_timeout:
            self.mission(previous.mission_id).add_silence(state.robot, previous.stamp,
                                                          state.stamp)
        if state.mission_id:
            self.mission(state.mission_id).add_robot_state(state)
        # Progress and heartbeats change the live view even when the trail does not.
        return True

    def silent(self, mission: MissionHistory | None, wall: float) -> dict[str, float]:
        """Robots silent at wall time `wall` (robot -> its last stamp): those following
        `mission` or no mission yet; with `mission` None, every robot."""
        return {robot: state.stamp for robot, state in self.robots.items()
                if (mission is None or state.mission_id in ('', mission.mission_id))
                and wall - state.stamp > self.heartbeat_timeout}

    def current(self) -> MissionHistory | None:
        """The mission the planner reports on most recently (else the latest planned)."""
        with_status = [m for m in self.missions.values() if m.status is not None]
        if with_status:
            return max(with_status, key=lambda m: m.status.stamp)
        planned = [m for m in self.missions.values() if m.plans]
        return max(planned, key=lambda m: m.last_plan.stamp) if planned else None
