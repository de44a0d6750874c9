"""The fleet's messages as plain, immutable facts, read from anything shaped like them.

A live rclpy message and a message decoded from a recording by `mcap_ros2` have the same field
names but not the same classes, and only the live one carries the message constants. A
`Decoder` reads both: it is built from the constants of the message classes (live) or from the
message definitions stored in the recording (replay), and pairs each constant with the
vocabulary word of the same name, as `fjsp_common.contract` does for the nodes. Numbers the
decoder does not know (a newer fleet, a forged message) raise `UnreadableMessageError` instead
of being guessed, as do fields of the wrong type (a recording can hold any schema) and times
that are not finite numbers (`fjsp_common.wellformed`).
"""

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass

from fjsp_common.clock import ScheduleClock, seconds
from fjsp_common.revisions import attempt_revision
from fjsp_common.vocabulary import EventKind, MissionEventKind, MissionState, RobotMode
from fjsp_common.wellformed import plan_problem, time_problem

VOCABULARIES = {
    'RobotState': ('MODE', RobotMode),
    'TaskEvent': ('KIND', EventKind),
    'MissionStatus': ('STATE', MissionState),
    'MissionEvent': ('KIND', MissionEventKind),
}
"""Message type -> (prefix of its constants, the vocabulary they name)."""


MAX_NAME = 256
"""Characters of a name or id: a scenario's names have at most 100, ids a few more."""


class UnreadableMessageError(ValueError):
    """A message with a value this decoder cannot name."""


@dataclass(frozen=True)
class PlannedTask:
    """One robot's part in one job of a plan revision (schedule units)."""

    robot: str
    job: str
    operation: str
    location: str
    travel_start: float
    arrival: float
    start: float
    operation_end: float
    end: float
    co_workers: tuple[str, ...]
    predecessors: tuple[str, ...]
    held_into_next: bool
    continued: bool
    restarted_in: int
    """The revision that last started the job afresh (0 if the plan does not say)."""

    def attempt_since(self, revision: int) -> int:
        """The revision whose attempt at the job this task, of plan `revision`, goes on with
        (0: unknown)."""
        return attempt_revision(revision, self.continued, self.restarted_in)


@dataclass(frozen=True)
class MapPlace:
    """A location of the mission's map (a 2-D one at z = 0)."""

    name: str
    x: float
    y: float
    z: float


@dataclass(frozen=True)
class PlanFact:
    stamp: float
    """Wall time of publication, seconds since the epoch (as every stamp here)."""
    mission_id: str
    revision: int
    scenario_id: str
    mission_start: float
    time_scale: float
    cancelled: bool
    makespan: float
    solver_status: str
    lower_bound: float
    reasons: tuple[str, ...]
    robots: tuple[tuple[str, str], ...]
    """(robot, robot type) of every robot of the scenario, in the plan's order."""
    tasks: tuple[PlannedTask, ...]
    places: tuple[MapPlace, ...] = ()
    """The scenario's map (empty: it has none)."""

    @property
    def clock(self) -> ScheduleClock | None:
        """The mission's schedule time as this plan gives it (None for a time scale that is
        not positive)."""
        return ScheduleClock(self.mission_start, self.time_scale) if self.time_scale > 0 \
            else None


@dataclass(frozen=True)
class TaskEventFact:
    stamp: float
    event_id: str
    mission_id: str
    kind: EventKind
    robot: str
    job: str
    revision: int
    time: float
    reason: str


@dataclass(frozen=True)
class MissionEventFact:
    stamp: float
    event_id: str
    mission_id: str
    kind: MissionEventKind
    revision: int
    time: float
    robot: str
    job: str
    reasons: tuple[str, ...]


@dataclass(frozen=True)
class RobotStateFact:
    stamp: float
    robot: str
    robot_type: str
    incarnation: int
    mission_id: str
    mode: RobotMode
    revision: int
    refusal: str
    failures: int
    current_job: str
    location: str
    destination: str
    progress: float
    busy_until: float


@dataclass(frozen=True)
class StatusFact:
    stamp: float
    mission_id: str
    state: MissionState
    revision: int
    scenario_id: str
    jobs_done: int
    jobs_running: int
    jobs_total: int
    planned_makespan: float
    projected_makespan: float
    elapsed: float
    blocked_reasons: tuple[str, ...]
    replan_reasons: tuple[str, ...]
    warnings: tuple[str, ...]
    ignored: tuple[int, int, int]
    """Messages the planner ignored as stale, duplicate, unknown."""


Fact = PlanFact | TaskEventFact | MissionEventFact | RobotStateFact | StatusFact

_CONSTANT = re.compile(r'^\s*(?:u?int(?:8|16|32|64)|byte|char)\s+([A-Z][A-Z0-9_]*)\s*=\s*(-?\d+)',
                       re.MULTILINE)
_SECTION = re.compile(r'^={3,}\s*$', re.MULTILINE)
_SECTION_NAME = re.compile(r'^MSG:\s*(\S+)\s*$', re.MULTILINE)


def short_type(type_name: str) -> str:
    """'fjsp_msgs/msg/Plan' (or 'fjsp_msgs/Plan') -> 'Plan'."""
    return type_name.rsplit('/', 1)[-1]


class Decoder:
    """Turns message-shaped objects into facts, given what each message constant means."""

    def __init__(self, constants: Mapping[str, Mapping[str, int]]):
        """`constants`: message type ('RobotState') -> {constant name: value}."""
        self._words = {}
        for type_name, (prefix, vocabulary) in VOCABULARIES.items():
            table = constants.get(type_name, {})
            self._words[type_name] = {table[f'{prefix}_{word.name}']: word
                                      for word in vocabulary
                                      if f'{prefix}_{word.name}' in table}

    @classmethod
    def from_classes(cls, *classes) -> 'Decoder':
        """From message classes that carry their constants as attributes (rclpy's)."""
        return cls({c.__name__: {name: getattr(c, name) for name in dir(c)
                                 if name.isupper() and not name.startswith('_')}
                    for c in classes})

    @classmethod
    def from_definitions(cls, definitions: Mapping[str, str]) -> 'Decoder':
        """From ROS 2 message definitions (`ros2msg` text, as a recording stores them),
        keyed by type name; constants of the nested definitions are read too."""
        constants: dict[str, dict[str, int]] = {}
        for type_name, text in definitions.items():
            for section in _SECTION.split(text):
                named = _SECTION_NAME.search(section)
                name = short_type(named.group(1) if named else type_name)
                constants.setdefault(name, {}).update(
                    (m.group(1), int(m.group(2))) for m in _CONSTANT.finditer(section))
        return cls(constants)

    def _word(self, type_name: str, value: int):
        try:
            return self._words[type_name][value]
        except (KeyError, TypeError):
            raise UnreadableMessageError(f'{type_name} value {value} has no known meaning'
                                         ) from None

    def read(self, type_name: str, msg) -> Fact | None:
        """The fact `msg` (a message of type `type_name`) states, or None for a type the
        history does not use. UnreadableMessageError for a message with a field of the wrong
        type, a time that is not a finite number, or a constant with no known meaning."""
        reader = {'Plan': self.plan, 'TaskEvent': self.task_event,
                  'MissionEvent': self.mission_event, 'RobotState': self.robot_state,
                  'MissionStatus': self.status}.get(short_type(type_name))
        if reader is None:
            return None
        try:
            return reader(msg)
        except AttributeError as error:
            raise UnreadableMessageError(f'{short_type(type_name)}: {error}') from None

    def plan(self, msg) -> PlanFact:
        malformed = plan_problem(msg)
        if malformed:
            raise UnreadableMessageError(f'Plan: {malformed}')
        tasks = tuple(
            PlannedTask(robot=_name(r.robot), job=_name(t.job),
                        operation=_name(t.operation_name), location=_name(t.location),
                        travel_start=t.travel_start, arrival=t.arrival, start=t.start,
                        operation_end=t.operation_end, end=t.end,
                        co_workers=_names(t.co_workers), predecessors=_names(t.predecessors),
                        held_into_next=bool(t.held_into_next), continued=bool(t.continued),
                        # A recording made before plans carried it decodes without it.
                        restarted_in=_count(getattr(t, 'restarted_in', 0)))
            for r in msg.robots for t in r.tasks)
        return PlanFact(stamp=_stamp(msg.stamp), mission_id=_name(msg.mission_id),
                        revision=_count(msg.revision), scenario_id=_name(msg.scenario_id),
                        mission_start=_stamp(msg.mission_start),
                        time_scale=float(msg.time_scale), cancelled=bool(msg.cancelled),
                        makespan=_measure(msg.makespan),
                        solver_status=_text(msg.solver_status),
                        lower_bound=_measure(msg.lower_bound), reasons=_texts(msg.reasons),
                        robots=tuple((_name(r.robot), _name(r.robot_type)) for r in msg.robots),
                        tasks=tasks,
                        # A recording made before plans carried a map decodes without one.
                        places=tuple(MapPlace(_name(p.name), _coordinate(p.x), _coordinate(p.y),
                                              _coordinate(p.z))
                                     for p in getattr(msg, 'places', ())))

    def task_event(self, msg) -> TaskEventFact:
        return TaskEventFact(stamp=_stamp(msg.stamp), event_id=_name(msg.event_id),
                             mission_id=_name(msg.mission_id),
                             kind=self._word('TaskEvent', msg.kind), robot=_name(msg.robot),
                             job=_name(msg.job), revision=_count(msg.plan_revision),
                             time=_time(msg.time, 'TaskEvent time'),
                             reason=_text(msg.reason))

    def mission_event(self, msg) -> MissionEventFact:
        return MissionEventFact(stamp=_stamp(msg.stamp), event_id=_name(msg.event_id),
                                mission_id=_name(msg.mission_id),
                                kind=self._word('MissionEvent', msg.kind),
                                revision=_count(msg.plan_revision),
                                time=_time(msg.time, 'MissionEvent time'),
                                robot=_name(msg.robot), job=_name(msg.job),
                                reasons=_texts(msg.reasons))

    def robot_state(self, msg) -> RobotStateFact:
        return RobotStateFact(stamp=_stamp(msg.stamp), robot=_name(msg.robot),
                              robot_type=_name(msg.robot_type),
                              incarnation=_count(msg.incarnation),
                              mission_id=_name(msg.mission_id),
                              mode=self._word('RobotState', msg.mode),
                              revision=_count(msg.plan_revision), refusal=_text(msg.refusal),
                              failures=_count(msg.failures),
                              current_job=_name(msg.current_job), location=_name(msg.location),
                              destination=_name(msg.destination),
                              progress=_measure(msg.progress),
                              busy_until=_measure(msg.busy_until))

    def status(self, msg) -> StatusFact:
        return StatusFact(stamp=_stamp(msg.stamp), mission_id=_name(msg.mission_id),
                          state=self._word('MissionStatus', msg.state),
                          revision=_count(msg.plan_revision),
                          scenario_id=_name(msg.scenario_id), jobs_done=_count(msg.jobs_done),
                          jobs_running=_count(msg.jobs_running),
                          jobs_total=_count(msg.jobs_total),
                          planned_makespan=_measure(msg.planned_makespan),
                          projected_makespan=_measure(msg.projected_makespan),
                          elapsed=_measure(msg.elapsed),
                          blocked_reasons=_texts(msg.blocked_reasons),
                          replan_reasons=_texts(msg.replan_reasons),
                          warnings=_texts(msg.warnings),
                          ignored=(_count(msg.ignored_stale), _count(msg.ignored_duplicate),
                                   _count(msg.ignored_unknown)))


def _text(value) -> str:
    if not isinstance(value, str):
        raise UnreadableMessageError(f'{value!r:.80} where text belongs')
    return value


def _name(value) -> str:
    """A name or id: text no longer than any a fleet gives."""
    if len(_text(value)) > MAX_NAME:
        raise UnreadableMessageError(f'a name of {len(value)} characters')
    return value


def _names(values) -> tuple[str, ...]:
    return tuple(_name(value) for value in _texts(values))


def _texts(values) -> tuple[str, ...]:
    if isinstance(values, str | bytes):
        raise UnreadableMessageError(f'{values!r:.80} where a list of texts belongs')
    return tuple(_text(value) for value in values)


def _count(value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise UnreadableMessageError(f'{value!r:.80} where a count belongs')
    return value


def _time(value, what: str) -> float:
    why = time_problem(value, what)
    if why:
        raise UnreadableMessageError(why)
    return float(value)


def _measure(value) -> float:
    """A number that may be missing (NaN: no bound, nothing busy); one beyond any time a
    mission can reach counts as missing too."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise UnreadableMessageError(f'{value!r:.80} where a number belongs')
    return float(value) if not time_problem(value, '') else math.nan


def _coordinate(value) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise UnreadableMessageError(f'{value!r:.80} where a coordinate belongs')
    return float(value)


def _stamp(stamp) -> float:
    if not isinstance(stamp.sec, int) or not isinstance(stamp.nanosec, int):
        raise UnreadableMessageError(f'stamp {stamp!r:.80} is not a time')
    return seconds(stamp)
