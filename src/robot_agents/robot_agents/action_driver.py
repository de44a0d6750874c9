"""The `action` driver: each leg and each operation is a goal to the robot's own ROS 2 action
servers (`fjsp_msgs/action/Travel`, `fjsp_msgs/action/ExecuteOperation`; docs/robot-drivers.md).

The agent names the servers in its parameters (`travel_action`, `operation_action`, where
`{robot}` stands for the robot's name and `{operation}` for the operation type's name). A goal
carries the plan's duration in wall seconds; the server's feedback gives the share done and
the duration it now expects, its result the duration it took. An ABORTED goal, a goal the
server refuses, a server that does not answer within `server_timeout` seconds or that
disappears while it works is a robot failure. A goal cancelled by the agent (a new plan no
longer needs it) is forgotten, whatever its server answers later.

Everything runs on the agent's executor thread: rclpy's action client of Jazzy files a
request only after sending it, so an answer taken by another thread in between is lost.
"""

import math
import re
from collections.abc import Callable
from dataclasses import dataclass

from action_msgs.msg import GoalStatus
from rclpy.action import ActionClient
from rclpy.exceptions import InvalidTopicNameException
from rclpy.expand_topic_name import expand_topic_name
from rclpy.node import Node
from rclpy.validate_full_topic_name import validate_full_topic_name

from fjsp_msgs.action import ExecuteOperation, Travel
from robot_agents.drivers import Ending, Leg, Operation, later

ROBOT_FIELD = '{robot}'
OPERATION_FIELD = '{operation}'
DEFAULT_TRAVEL_ACTION = f'{ROBOT_FIELD}/travel'
DEFAULT_OPERATION_ACTION = f'{ROBOT_FIELD}/execute_operation'


def action_name(template: str, robot: str, operation: str = '') -> str:
    """`template` with the robot's and the operation type's name in place of its fields; in
    the operation's name every character a ROS name may not have becomes `_` (`hold frame
    link`: `hold_frame_link`)."""
    operation = re.sub(r'[^A-Za-z0-9_]', '_', operation)
    return template.replace(ROBOT_FIELD, robot).replace(OPERATION_FIELD, operation)


def usable(node: Node, name: str) -> bool:
    """Whether `name` can name an action of `node`."""
    try:
        return validate_full_topic_name(expand_topic_name(name, node.get_name(),
                                                          node.get_namespace()))
    except (InvalidTopicNameException, ValueError):
        return False


@dataclass
class _Goal:
    """One leg or operation sent to a server, from sending to its end."""

    kind: type
    name: str
    message: object
    start: float
    """Schedule time it began (the plan's instant, see `drivers`)."""
    nominal: float
    """Wall seconds the plan gives it."""
    sent: bool = False
    waiting_since: float = math.nan
    """Wall seconds since which it waits for its server."""
    handle: object = None
    share: float = 0.0
    expected: float = 0.0
    """Wall seconds the server expects it to take, from its latest feedback (0: none yet)."""
    ending: Ending | None = None
    cancelled: bool = False


class ActionDriver:
    """A `Driver` whose robot serves its legs and operations as ROS 2 actions."""

    ends_when_expected = False

    def __init__(self, node: Node, robot: str, travel_action: str, operation_action: str,
                 server_timeout: float, time_scale: Callable[[], float],
                 schedule_time: Callable[[], float]):
        """`time_scale()` gives the wall seconds per schedule unit of the mission followed,
        `schedule_time()` the schedule time now."""
        self.node = node
        self.robot = robot
        self.travel_action = travel_action
        self.operation_action = operation_action
        self.server_timeout = server_timeout
        self.time_scale = time_scale
        self.schedule_time = schedule_time
        self._clients: dict[tuple[type, str], ActionClient] = {}
        self._goal: _Goal | None = None

    def _client(self, kind, name: str) -> ActionClient:
        key = (kind, name)
        if key not in self._clients:
            self._clients[key] = ActionClient(self.node, kind, name)
        return self._clients[key]

    def _wall(self) -> float:
        return self.node.get_clock().now().nanoseconds * 1e-9

    # --- the Driver protocol -----------------------------------------------------------

    def begin(self, work: Leg | Operation, start: float) -> None:
        self._abandon()
        scale = self.time_scale()
        nominal = work.duration * scale
        if isinstance(work, Leg):
            kind, name = Travel, action_name(self.travel_action, self.robot)
            message = Travel.Goal(robot=self.robot, origin=work.origin,
                                  destination=work.destination, job=work.job,
                                  nominal_duration=nominal)
        else:
            kind = ExecuteOperation
            name = action_name(self.operation_action, self.robot, work.operation_name)
            message = ExecuteOperation.Goal(
                robot=self.robot, job=work.job, operation_type=work.operation_type,
                operation_name=work.operation_name, location=work.location,
                co_workers=list(work.co_workers), nominal_duration=nominal)
        self._goal = _Goal(kind, name, message, start, nominal)
        if not usable(self.node, name):
            self._goal.ending = Ending(start, f"cannot send it to '{name}', which is no "
                                              'action name', 0.0)
            return
        self._send()

    def ending(self, now: float) -> Ending | None:
        goal = self._goal
        if goal is None:
            return None
        if not goal.sent:
            self._send()
        elif goal.ending is None and goal.handle is not None \
                and not self._client(goal.kind, goal.name).server_is_ready():
            goal.ending = Ending(now, f"its action server '{goal.name}' disappeared",
                                 goal.share)
        if goal.ending is None:
            return None
        self._goal = None
        return goal.ending

    def stop(self, now: float) -> float:
        goal = self._goal
        if goal is None:
            return 0.0
        self._abandon()
        return goal.share

    def progress(self, now: float) -> float:
        return self._goal.share if self._goal is not None else 0.0

    def expected_end(self) -> float:
        goal = self._goal
        if goal is None:
            return math.nan
        return goal.start + max(goal.expected, goal.nominal) / self.time_scale()

    def retime(self, duration: float, now: float) -> bool:
        return False

    # --- goals -------------------------------------------------------------------------

    def _send(self) -> None:
        """Send the goal once its server is there; a robot failure after `server_timeout`."""
        goal = self._goal
        client = self._client(goal.kind, goal.name)
        if not client.server_is_ready():
            wall = self._wall()
            if math.isnan(goal.waiting_since):
                goal.waiting_since = wall
            elif wall - goal.waiting_since > self.server_timeout:
                goal.ending = Ending(self.schedule_time(),
                                     f"no action server '{goal.name}' answered within "
                                     f'{self.server_timeout:g} s', 0.0)
            return
        goal.sent = True
        future = client.send_goal_async(goal.message,
                                        feedback_callback=lambda msg: self._feedback(goal, msg))
        future.add_done_callback(lambda done: self._accepted(goal, done))

    def _feedback(self, goal: _Goal, msg) -> None:
        feedback = msg.feedback
        if math.isfinite(feedback.share):
            goal.share = min(1.0, max(goal.share, feedback.share))
        if math.isfinite(feedback.expected_duration) and feedback.expected_duration >= 0:
            goal.expected = feedback.expected_duration

    def _accepted(self, goal: _Goal, done) -> None:
        handle = done.result()
        if goal.cancelled:
            if handle is not None and handle.accepted:
                handle.cancel_goal_async()
            return
        if handle is None or not handle.accepted:
            goal.ending = Ending(self.schedule_time(),
                                 f"its action server '{goal.name}' refused the goal", 0.0)
            return
        goal.handle = handle
        handle.get_result_async().add_done_callback(lambda result: self._result(goal, result))

    def _result(self, goal: _Goal, done) -> None:
        if goal.cancelled:
            return
        response = done.result()
        result = response.result
        took = result.duration if math.isfinite(result.duration) and result.duration >= 0 \
            else goal.nominal
        end = later(goal.start + took / self.time_scale())
        if response.status == GoalStatus.STATUS_SUCCEEDED:
            goal.ending = Ending(end)
            return
        if goal.kind is Travel and math.isfinite(result.share):
            goal.share = min(1.0, max(0.0, result.share))
        why = result.message or {GoalStatus.STATUS_ABORTED: 'aborted',
                                  GoalStatus.STATUS_CANCELED: 'cancelled by the robot'}.get(
                                      response.status, f'ended with status {response.status}')
        goal.ending = Ending(end, f"'{goal.name}': {why}", goal.share)

    def _abandon(self) -> None:
        """Cancel the goal under way (its late answers are ignored)."""
        goal, self._goal = self._goal, None
        if goal is None:
            return
        goal.cancelled = True
        if goal.handle is not None and goal.ending is None:
            goal.handle.cancel_goal_async()

    def close(self) -> None:
        self._abandon()
        for client in self._clients.values():
            client.destroy()
