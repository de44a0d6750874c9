"""Which robots' agents are live and follow the plan: heartbeats, availability, plan uptake.

A robot takes part in planning only while it is *available*: it has reported, it is neither
failed nor offline, and it follows the plans it is given (an agent that refuses a plan, e.g.
for a robot type it cannot play, is left out and named in the warnings; so is one that keeps
reporting an older revision than the latest, which it may never have received, until it
reports the latest). A robot whose heartbeat is lost is offline until it has been heard again
for a full heartbeat timeout, so that one late heartbeat does not re-plan twice. A heartbeat is
lost when the robot has not been heard for a timeout longer than the robot heard last: states
that all come late together tell of a planner that could not read them (a flood, a stalled
core), not of failed robots. When no robot at all is heard, they go offline after
FLEET_SILENCE timeouts: the planner cannot tell its own stall from a fleet-wide loss then.
States that do not verify with the fleet key are no heartbeat, but they are remembered: a
robot whose agent lacks the key is said to be unverified rather than merely silent.
Under a flood of unauthenticated messages (more than FLOOD_RATE refused a second by the
planner, or by an agent as its states say) the planner's subscriptions drop messages it never
reads, its robots' states among them, at random, and flooded agents publish late: heartbeats
are then judged over FLOOD_STRETCH timeouts, so a flood slows the detection of a lost robot
instead of inventing one.
"""

import math
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING

from fjsp_common.vocabulary import MissionEventKind, RobotMode
from fjsp_planner.execution.mission.effects import Effect, Note, ResendPlan
from fjsp_planner.execution.mission.reports import RobotReport

if TYPE_CHECKING:
    from fjsp_planner.execution.mission.controller import Mission

EVENTS_REMEMBERED = 10000
"""Ids of the latest task events remembered per robot, to tell when the event history a
robot reports having published has arrived: twice what an agent's writer keeps for late
joiners."""

PLAN_RESEND_AFTER = 2.0
"""Seconds a robot that reports may stay on an older plan revision than the latest before
the plan is published again, on a new writer, and again every as many seconds until the
robot takes it or is planned without: a sample lost on a matched subscription is resent by
the reliable writer long before, so the robot's subscription is likely not matched to the
writer at all, or a flood pushed the plan out of the robot's reader before it was taken."""

FLEET_SILENCE = 3
"""Heartbeat timeouts after which robots are offline although no robot was heard since."""

FLOOD_RATE = 200
"""Messages refused as unauthenticated per second beyond which the node is flooded: a fleet
member without the key sends a few states a second, a flooder thousands."""

FLOOD_STRETCH = 5
"""Heartbeat timeouts a robot may stay unheard while the node is flooded: at 5 states a
second, a robot's states all lost for five timeouts at once is unlikely even when most of
what the node could read is dropped."""

FLOOD_WINDOW = 2.0
"""Seconds over which the rate of refused messages is measured."""

STARVED = 0.25
"""Seconds between two ticks beyond which the node could not take messages for a while: the
heartbeats it has not processed yet come first, before any robot is judged silent."""


@dataclass
class Agent:
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


@dataclass(frozen=True)
class HeartbeatChange:
    """A robot's agent went offline, or counts again after an offline spell."""

    robot: str
    back: bool
    silent: float
    """Seconds since its latest state."""


class RecentEvents:
    """Ids of the latest task events received from one robot, oldest first."""

    def __init__(self):
        self._ids: dict[str, None] = {}

    def add(self, event_id: str) -> None:
        self._ids[event_id] = None
        if len(self._ids) > EVENTS_REMEMBERED:
            del self._ids[next(iter(self._ids))]

    def __contains__(self, event_id: str) -> bool:
        return event_id in self._ids


class RefusalRate:
    """How fast a running count of refused messages grows, over the latest FLOOD_WINDOW."""

    def __init__(self):
        self._samples: deque[tuple[float, int]] = deque()

    def count(self, refused: int, wall: float) -> None:
        """Take the count as it is at `wall`."""
        self._samples.append((wall, refused))
        while len(self._samples) > 2 and wall - self._samples[1][0] >= FLOOD_WINDOW:
            self._samples.popleft()

    def clear(self) -> None:
        """Forget the counts (a new process counts from 0)."""
        self._samples.clear()

    def per_second(self, wall: float) -> float:
        """Refused a second lately; 0 before two counts, or when the latest is older than
        FLOOD_WINDOW at `wall`."""
        if len(self._samples) < 2 or wall - self._samples[-1][0] > FLOOD_WINDOW:
            return 0.0
        (first, first_count), (last, last_count) = self._samples[0], self._samples[-1]
        return max(0, last_count - first_count) / (last - first) if last > first else 0.0


class Liveness:
    """What is known of every robot's agent, across missions: its latest report, when it was
    heard, its offline spells and the task events received from it."""

    def __init__(self):
        self.agents: dict[str, Agent] = {}
        self.events_heard: dict[str, RecentEvents] = {}
        """Per robot (of the mission, or heard from), the task events received from it."""
        self.unverified: dict[str, tuple[str, float]] = {}
        """Robot -> (why, when) of the latest state about it that did not verify."""
        self._last_tick: float | None = None
        self.node_refusals = RefusalRate()
        """Messages this node refused as unauthenticated."""
        self.agent_refusals: dict[str, RefusalRate] = {}
        """Per robot, those its agent says it refused."""

    def count_refused(self, refused: int, wall: float) -> None:
        """Take the node's running count of messages refused as unauthenticated at `wall`."""
        self.node_refusals.count(refused, wall)

    def refused_rate(self, wall: float) -> float:
        """The most unauthenticated messages a second that this node or an agent refused
        lately."""
        rates = [self.node_refusals, *self.agent_refusals.values()]
        return max(rate.per_second(wall) for rate in rates)

    def flooded(self, wall: float) -> bool:
        return self.refused_rate(wall) > FLOOD_RATE

    def hear(self, report: RobotReport, wall: float) -> bool:
        """Take a robot's state; whether its agent restarted since its previous one."""
        agent = self.agents.get(report.robot)
        restarted = False
        if agent is None:
            self.agents[report.robot] = Agent(report, wall, reachable_since=wall)
        else:
            if agent.offline_since is not None and agent.back_since is None:
                agent.back_since = agent.reachable_since = wall
            restarted = report.incarnation != agent.report.incarnation
            if restarted:
                agent.reachable_since = wall
            agent.report, agent.heard = report, wall
        refusals = self.agent_refusals.setdefault(report.robot, RefusalRate())
        if restarted:
            refusals.clear()
        refusals.count(report.refused, wall)
        return restarted

    def refuse(self, robot: str, why: str, wall: float) -> None:
        """A state about `robot` that does not verify with the fleet key (`why`) came."""
        self.unverified[robot] = (why, wall)

    def silenced(self, robot: str) -> str:
        """Why the robot's latest states were dropped, if one came after the latest state
        that verified ('' otherwise): it reports, but not with the fleet's key."""
        why, at = self.unverified.get(robot, ('', -math.inf))
        agent = self.agents.get(robot)
        return why if agent is None or at > agent.heard else ''

    def hear_event(self, robot: str, event_id: str) -> None:
        self.events_heard.setdefault(robot, RecentEvents()).add(event_id)

    def caught_up(self, robot: str) -> bool:
        """Whether the latest event the robot says it published has been received (events
        of one writer arrive in order, so all before it have too); true for a robot not
        heard from."""
        agent = self.agents.get(robot)
        last = agent.report.last_event if agent is not None else ''
        return not last or last in self.events_heard.get(robot, ())

    def heard(self, robot: str) -> bool:
        agent = self.agents.get(robot)
        return agent is not None and agent.offline_since is None

    def starved(self, wall: float) -> bool:
        """Whether more than STARVED seconds passed since the previous tick (this one at
        `wall`): no robot may be judged silent before the states waiting are taken."""
        starved = self._last_tick is not None and wall - self._last_tick > STARVED
        self._last_tick = wall
        return starved

    def check_heartbeats(self, wall: float, timeout: float) -> list[HeartbeatChange]:
        """The agents that went offline at `wall` (no state for more than `timeout` before the
        latest state of any robot, or for FLEET_SILENCE timeouts) and those that count again
        (heard for a full `timeout` after an offline spell); FLOOD_STRETCH timeouts when
        flooded."""
        if self.flooded(wall):
            timeout *= FLOOD_STRETCH
        changes = []
        latest = max((agent.heard for agent in self.agents.values()), default=wall)
        for name, agent in self.agents.items():
            silent = wall - agent.heard
            lost = latest - agent.heard > timeout or silent > FLEET_SILENCE * timeout
            if agent.offline_since is None and lost:
                agent.offline_since, agent.back_since = wall, None
                changes.append(HeartbeatChange(name, False, silent))
            elif agent.back_since is not None and silent <= timeout \
                    and wall - agent.back_since >= timeout:
                agent.offline_since = agent.back_since = None
                changes.append(HeartbeatChange(name, True, silent))
        return changes

    def unavailable(self, mission: 'Mission', wall: float, uptake_timeout: float
                    ) -> dict[str, str]:
        """Robot -> why it cannot take part in planning now ('' if it can)."""
        why = {}
        for robot in mission.problem.robots:
            agent = self.agents.get(robot.name)
            unverified = self.silenced(robot.name)
            if unverified and (agent is None or agent.offline_since is not None):
                why[robot.name] = f'sends states that do not verify: {unverified}'
            elif agent is None:
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
                                   f'within {uptake_timeout:g} s')
            else:
                why[robot.name] = ''
        return why

    def fleet(self, unavailable: dict[str, str]) -> dict[str, tuple[int, int]]:
        """The available robots: (incarnation, failures) as their agents report them."""
        return {name: (self.agents[name].report.incarnation, self.agents[name].report.failures)
                for name, why in unavailable.items() if not why}

    def check_uptake(self, mission: 'Mission', wall: float, uptake_timeout: float
                     ) -> list[Effect]:
        """Robots that report, but not the latest revision: the plan is published again
        every PLAN_RESEND_AFTER, and they are planned without after `uptake_timeout`, until
        they report it."""
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
            if (mission.resent is None or mission.resent[0] < revision
                    or (waited < uptake_timeout
                        and wall - mission.resent[1] >= PLAN_RESEND_AFTER)):
                mission.resent = (revision, wall)
                effects.append(ResendPlan(revision))
            if waited >= uptake_timeout:
                mission.missed.setdefault(robot.name, revision)
        return effects
