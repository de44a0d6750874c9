"""Topic names, QoS profiles and message constants the whole fleet agrees on.

Names are relative, so a whole fleet can be moved into a namespace with `-r __ns:=/cell1`.
`TOPICS` is the one table of the fleet's topics, each with its message type and QoS: every
node publishes and subscribes through it (`publisher`, `subscription`). Every vocabulary of
`fjsp_common.vocabulary` is paired here with its message constants by name; a vocabulary
word without a constant (or the reverse) fails at import, not in a mission.
"""

from dataclasses import dataclass

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseArray
from rclpy.exceptions import InvalidHandle
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from visualization_msgs.msg import MarkerArray

from fjsp_common.diagnostics import DIAGNOSTICS_QOS, DIAGNOSTICS_TOPIC
from fjsp_common.vocabulary import EventKind, MissionEventKind, MissionState, RobotMode
from fjsp_msgs.msg import JobStates, MissionEvent, MissionStatus, Plan, RobotState, TaskEvent

PLAN_TOPIC = 'plan'
ROBOT_STATES_TOPIC = 'robot_states'
JOB_STATES_TOPIC = 'job_states'
TASK_EVENTS_TOPIC = 'task_events'
MISSION_EVENTS_TOPIC = 'mission_events'
MISSION_STATUS_TOPIC = 'mission_status'
ROBOT_POSES_TOPIC = 'robot_poses'
FLEET_MAP_TOPIC = 'fleet_map'
INJECT_FAULT_SERVICE = 'inject_fault'
"""Served by each agent under its robot name: `<robot>/inject_fault`."""
RUN_MISSION_ACTION = 'run_mission'
ADD_JOBS_SERVICE = 'add_jobs'
CANCEL_MISSION_SERVICE = 'cancel_mission'

MAX_FLEET = 128
"""Robot states a late joiner catches up on: at least the largest fleet a scenario may have."""

EVENT_HISTORY = 5000
"""Events each writer keeps for late joiners: a robot reports 4 per job attempt, so this
covers a mission of 1000 jobs with room for redone attempts."""

LATCHED_QOS = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
)
"""The current plan and latest status: a node that joins late gets the last one."""

READER_HISTORY = 5000
"""Messages a reader of a latched topic (the plan, robot states, the mission status) holds
until it takes them. Each writer keeps only its latest, but all writers of a topic share a
reader's history, so it must hold what a flood of forged messages delivers while the reader
waits for a core, or the fleet's own are pushed out before they are taken. As many as Fast DDS
keeps for a reader (its default `max_samples`, which rclpy cannot raise): a deeper history
holds no more."""

LATCHED_READER_QOS = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    history=HistoryPolicy.KEEP_LAST,
    depth=READER_HISTORY,
)
"""How latched topics are read. A reader of robot states must also hold at least one per
robot, or a late joiner would get a single robot's state, and a burst (a failure followed at
once by a recovery) could lose the failure before the reader's executor takes it."""

EVENTS_QOS = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    history=HistoryPolicy.KEEP_LAST,
    depth=EVENT_HISTORY,
)
"""Task and mission events are facts nobody may miss: each writer keeps its history for late
joiners (a restarted planner rebuilds a mission from the agents' histories)."""


FAULT_REQUESTS_QOS = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
    history=HistoryPolicy.KEEP_LAST,
    depth=256,
)
"""An agent's fault service queues this many requests; the default (10) dropped most of a
burst of 40, leaving their callers waiting out their timeouts."""


@dataclass(frozen=True)
class Topic:
    name: str
    type: type
    qos: QoSProfile
    """What its readers subscribe with, and its writers publish with unless `writer_qos`
    says otherwise."""
    writer_qos: QoSProfile | None = None


PLAN = Topic(PLAN_TOPIC, Plan, LATCHED_READER_QOS, writer_qos=LATCHED_QOS)
ROBOT_STATES = Topic(ROBOT_STATES_TOPIC, RobotState, LATCHED_READER_QOS, writer_qos=LATCHED_QOS)
"""Each agent's writer keeps only its latest state; readers keep one per robot."""
TASK_EVENTS = Topic(TASK_EVENTS_TOPIC, TaskEvent, EVENTS_QOS)
MISSION_EVENTS = Topic(MISSION_EVENTS_TOPIC, MissionEvent, EVENTS_QOS)
MISSION_STATUS = Topic(MISSION_STATUS_TOPIC, MissionStatus, LATCHED_READER_QOS,
                       writer_qos=LATCHED_QOS)
JOB_STATES = Topic(JOB_STATES_TOPIC, JobStates, LATCHED_QOS)
DIAGNOSTICS = Topic(DIAGNOSTICS_TOPIC, DiagnosticArray, DIAGNOSTICS_QOS)
ROBOT_POSES = Topic(ROBOT_POSES_TOPIC, PoseArray, LATCHED_QOS)
"""The monitor's view of where each robot is on the mission's map (standard messages, for
Foxglove and other tools)."""
FLEET_MAP = Topic(FLEET_MAP_TOPIC, MarkerArray, LATCHED_QOS)

TOPICS = (PLAN, ROBOT_STATES, TASK_EVENTS, MISSION_EVENTS, MISSION_STATUS, JOB_STATES,
          DIAGNOSTICS, ROBOT_POSES, FLEET_MAP)
"""Every topic of a mission."""


def publisher(node, topic: Topic):
    """A publisher of `topic` on `node`, with the QoS its writers use."""
    return node.create_publisher(topic.type, topic.name, topic.writer_qos or topic.qos)


DRAIN = 1000
"""Messages a subscription's callback takes in a row once one came, before the executor serves
the node's other callbacks."""


def subscription(node, topic: Topic, callback, auth=None, **options):
    """A subscription of `node` to `topic`, with the QoS its readers use, that takes every
    message waiting (up to DRAIN) each time the executor serves it.

    rclpy's executor rebuilds its wait set for every message it hands over, which limits a
    node to a few hundred messages a second; all writers of a topic share one reader history
    (KEEP_LAST), so a flood beyond that rate — forged messages, dropped at once by the
    callback — would push the fleet's own messages out of the history before they are taken
    (robots' heartbeats lost: robots declared offline). Taken in a row, messages cost only
    their callback.

    With `auth` (the node's `NodeAuth`) in an authenticated fleet, signed topics are taken as
    their bytes, and only what could carry a signature is decoded for `callback`
    (`NodeAuth.screen`): decoding is most of what a flood of unsigned messages costs."""
    if auth is not None and auth.enabled and not options.get('raw') \
            and 'auth' in topic.type.get_fields_and_field_types():
        callback = screening(auth, topic.name, topic.type, callback,
                             lambda: auth.unreadable(topic.name))
        options['raw'] = True
    return draining(node, topic.type, topic.name, topic.qos, callback, **options)


def screened_subscription(node, msg_type, name: str, qos, callback, verifier=None):
    """A draining subscription (see `subscription`) for a process that checks messages with a
    `Verifier` of its own rather than a node's `NodeAuth` (the launcher, tools, tests): with
    the fleet key, what cannot carry a signature is dropped from its bytes
    (`Verifier.screen`); `callback` checks the rest."""
    if verifier is None or verifier.key is None \
            or 'auth' not in msg_type.get_fields_and_field_types():
        return draining(node, msg_type, name, qos, callback)
    callback = screening(verifier, node.resolve_topic_name(name), msg_type, callback)
    return draining(node, msg_type, name, qos, callback, raw=True)


def draining(node, msg_type, name: str, qos, callback, **options):
    """A subscription whose callback, once the executor hands it a message, also takes every
    message waiting behind it (up to DRAIN)."""
    taking = []

    def take_all(msg) -> None:
        callback(msg)
        take_waiting(taking[0], callback)

    sub = node.create_subscription(msg_type, name, take_all, qos, **options)
    taking.append(sub)
    return sub


def screening(screener, name: str, msg_type, callback, unreadable=lambda: None):
    """`callback` for raw messages: those `screener.screen(data, name)` refuses are dropped
    from their bytes, the others decoded for it (`unreadable()` for bytes rclpy cannot
    read)."""
    def screen(data: bytes) -> None:
        if not screener.screen(data, name):
            return
        try:
            msg = deserialize_message(data, msg_type)
        except Exception:  # noqa: BLE001  bytes rclpy cannot read, whatever it raises
            unreadable()
            return
        callback(msg)
    return screen


def take_waiting(sub, callback, limit: int = DRAIN) -> int:
    """Hand `callback` the messages waiting in `sub`'s history, up to `limit`, without the
    executor (a node stopping takes what arrived before it closes); how many it took."""
    for count in range(limit):
        try:
            with sub.handle:
                taken = sub.handle.take_message(sub.msg_type, sub.raw)
        except InvalidHandle:
            return count  # destroyed by the callback
        if taken is None:
            return count
        callback(taken[0])
    return limit


def catch_up(sub) -> None:
    """Serve `sub` now with every message waiting in its history, as the executor would: a
    node about to judge by what it heard (a robot silent for too long) first takes what has
    arrived. The executor serves a node's timers before its subscriptions, so a node kept
    from a core for a while would otherwise judge by what it heard before; and the newest
    messages come last, behind however many a flood left waiting. It takes at most a full
    history and a drain more, so that a flood outpacing it cannot hold the node here."""
    rounds = sub.qos_profile.depth // (DRAIN + 1) + 2
    for _ in range(rounds):
        if not take_waiting(sub, sub.callback, limit=1):  # its callback takes up to DRAIN more
            return


def _pair(vocabulary, message, prefix: str) -> tuple[dict, dict]:
    to_msg = {word: getattr(message, f'{prefix}_{word.name}') for word in vocabulary}
    constants = {getattr(message, name) for name in dir(message) if name.startswith(f'{prefix}_')}
    unpaired = constants - set(to_msg.values())
    if unpaired:
        raise ImportError(f'{message.__name__} constants {sorted(unpaired)} have no word in '
                          f'{vocabulary.__name__}')
    return to_msg, {value: word for word, value in to_msg.items()}


MODE_TO_MSG, MODE_FROM_MSG = _pair(RobotMode, RobotState, 'MODE')
EVENT_TO_MSG, EVENT_FROM_MSG = _pair(EventKind, TaskEvent, 'KIND')
STATE_TO_MSG, STATE_FROM_MSG = _pair(MissionState, MissionStatus, 'STATE')
MISSION_EVENT_TO_MSG, MISSION_EVENT_FROM_MSG = _pair(MissionEventKind, MissionEvent, 'KIND')
