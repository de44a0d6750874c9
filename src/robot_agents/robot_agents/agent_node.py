"""A robot agent of any type: follows its task sequence of the latest plan, its robot's legs and
operations done by a driver (`drivers`): timed by the plan (`mock`, the default) or by the
robot's own action servers (`action`, see `action_driver` and docs/robot-drivers.md).

One process per robot (`robot_name` parameter); its node is named `agent_<robot>`, so a fleet
never has two nodes of the same name. Its type comes from the plan, unless the `robot_type`
parameter pins it (the `assembler_agent`, `marc_agent` and `lsms_agent` executables pin the
paper's types): a plan that makes a pinned robot another type is refused, and the refusal is
reported in the robot's state for the planner and any monitor to see, never executed.

Plans are followed per mission: revisions count within a mission, and a plan of a newer
mission (a later `mission_start`) starts afresh from where the robot is. Faults are injected
through `<robot_name>/inject_fault` (`fjsp_planner.faults`).
"""

import math
import sys
from collections import deque
from dataclasses import replace
from pathlib import Path

from rclpy.exceptions import InvalidServiceNameException
from rclpy.node import Node
from rclpy.time import Time as RosTime

from fjsp_common.auth import NodeAuth
from fjsp_common.clock import ScheduleClock, seconds
from fjsp_common.contract import (
    DIAGNOSTICS,
    EVENT_FROM_MSG,
    EVENT_HISTORY,
    EVENT_TO_MSG,
    FAULT_REQUESTS_QOS,
    INJECT_FAULT_SERVICE,
    MODE_TO_MSG,
    PLAN,
    PLAN_TOPIC,
    ROBOT_STATES,
    ROBOT_STATES_TOPIC,
    TASK_EVENTS,
    TASK_EVENTS_TOPIC,
    publisher,
    subscription,
)
from fjsp_common.diagnostics import diagnostic_array, robot_diagnostic
from fjsp_common.fleet import (
    DIAGNOSTICS_PERIOD,
    HEARTBEAT_PERIOD,
    LATE_THRESHOLD,
    PLANNER_NODE,
    agent_node_name,
)
from fjsp_common.parameters import ParameterSpec, table
from fjsp_common.revisions import plan_attempts
from fjsp_common.running import ParameterError, declare, run_node, shorten
from fjsp_common.vocabulary import EventKind, RobotMode
from fjsp_common.wellformed import plan_problem
from fjsp_msgs.msg import Plan, RobotState, TaskEvent
from fjsp_msgs.srv import InjectFault
from robot_agents.action_driver import (
    DEFAULT_OPERATION_ACTION,
    DEFAULT_TRAVEL_ACTION,
    OPERATION_FIELD,
    ROBOT_FIELD,
    ActionDriver,
    action_name,
    usable,
)
from robot_agents.drivers import MockDriver
from robot_agents.execution import FaultResult, RobotExecution, Task
from robot_agents.reports import ReportLog

ANSWERS_KEPT = 1024
IDLE_TICK = 0.25
"""Seconds at most between steps while nothing is due: a safety net, as every plan, report
and fault steps the robot when it comes."""
DUE_MARGIN = 0.0005
"""Seconds a step is set after the instant it is due at, so that the clock has reached it."""
NAME_LOOKUP_NODE = 'robot_agent'
"""The short-lived node that reads `robot_name` before the agent's own node can be named."""

ROBOT_NAME = ParameterSpec('robot_name', '',
                           'name of the robot this agent plays, as the scenario lists it')
ROBOT_TYPE = ParameterSpec('robot_type', '', 'robot type this agent must play; empty: whatever '
                           'type the plan gives it')
PARAMETERS = table(
    ROBOT_NAME,
    ROBOT_TYPE,
    ParameterSpec('time_scale', 0.0, "wall seconds per schedule unit; 0: the plan's", low=0.0,
                  high=1000.0),
    ParameterSpec('tick_period', 0.01, 'seconds between polls of a robot driven by actions; '
                  'the mock robot steps when its next leg, operation or job is due',
                  low=0.001, high=1.0),
    ParameterSpec('heartbeat_period', HEARTBEAT_PERIOD,
                  'seconds between robot states published as heartbeat', low=0.01, high=10.0),
    ParameterSpec('diagnostics_period', DIAGNOSTICS_PERIOD,
                  'seconds between health reports on /diagnostics', low=0.1, high=60.0),
    ParameterSpec('late_threshold', LATE_THRESHOLD, 'schedule units an operation may run past '
                  'its plan before the robot reports WARN', low=0.0, high=1e6),
    ParameterSpec('reports_dir', '', 'directory where the agent keeps its reports, so that a '
                  'planner resuming a mission learns what this robot did before its agent '
                  'restarted; empty: not kept'),
    ParameterSpec('driver', 'mock', "who moves the robot: 'mock' takes the plan's times, "
                  "'action' sends each leg and operation to the robot's action servers",
                  choices=('mock', 'action')),
    ParameterSpec('travel_action', DEFAULT_TRAVEL_ACTION, 'the Travel action server of the '
                  f'robot (action driver); {ROBOT_FIELD} is replaced by the robot name'),
    ParameterSpec('operation_action', DEFAULT_OPERATION_ACTION, 'the '
                  'ExecuteOperation action server of the robot (action driver); '
                  f'{ROBOT_FIELD} is replaced by the robot name, {OPERATION_FIELD} by the '
                  "operation type's name"),
    ParameterSpec('server_timeout', 10.0, 'seconds an action server may take to be there for '
                  'a goal before the robot counts as failed (action driver)', low=0.1,
                  high=600.0),
)
"""The agent's parameters, in the order it declares them; the agent's executable gives
`robot_name` (read first, to name the node) and `robot_type` (pinned by the per-type aliases)
their defaults."""


class RobotAgent(Node):
    def __init__(self, robot: str, pinned_type: str = ''):
        super().__init__(agent_node_name(robot))
        given = {ROBOT_NAME.name: robot, ROBOT_TYPE.name: pinned_type}
        value = {name: declare(self, replace(spec, default=given.get(name, spec.default)))
                 for name, spec in PARAMETERS.items()}
        self.robot = value['robot_name']
        self.pinned_type = value['robot_type'] or pinned_type
        self.time_scale = value['time_scale']
        self.late_threshold = value['late_threshold']
        if pinned_type and self.pinned_type != pinned_type:
            raise ParameterError(f"parameter 'robot_type': this executable plays a "
                                 f"'{pinned_type}', got '{self.pinned_type}' (use robot_agent "
                                 'for other types)')

        self.auth = NodeAuth(self, self.robot)
        self.incarnation = self.auth.signer.incarnation
        """Tells this process's reports from those of an earlier agent of the same robot."""
        self.event_count = 0
        self.last_event_id = ''
        """The latest task event published, for the state: a restarted planner waits for it."""
        self.failures = 0
        self.driver_name = value['driver']
        self.execution = RobotExecution(self.robot, self.make_driver(value))
        self.mission_id = ''
        self.clock: ScheduleClock | None = None
        """The followed mission's schedule time (None before its first plan)."""
        self.robot_type = self.pinned_type
        self.refusal = ''
        """Why the latest plan received is not followed ('' when it is)."""
        self.malformed_plans = 0
        self.last_state = None
        self.answered: dict[str, tuple[bool, str]] = {}
        """The latest fault requests' answers by request id, for callers that resend."""
        self.early_events: deque[TaskEvent] = deque(maxlen=EVENT_HISTORY)
        """Reports of a mission this robot does not follow (yet): its plan may come later."""

        self.state_pub = publisher(self, ROBOT_STATES)
        self.event_pub = publisher(self, TASK_EVENTS)
        subscription(self, PLAN, self.on_plan, self.auth)
        subscription(self, TASK_EVENTS, self.on_event, self.auth)
        self.fault_service = f'{self.robot}/{INJECT_FAULT_SERVICE}'
        try:
            self.create_service(InjectFault, self.fault_service, self.on_fault,
                                qos_profile=FAULT_REQUESTS_QOS)
        except InvalidServiceNameException:
            raise ParameterError(f"parameter 'robot_name' must be usable in a ROS name "
                                 f'(letters, digits, underscores), got {self.robot!r}') from None
        self.diagnostics_pub = publisher(self, DIAGNOSTICS)
        self.tick_period = value['tick_period']
        self.tick_timer = self.create_timer(self.tick_period, self.tick)
        self.create_timer(value['heartbeat_period'], self.publish_state)
        self.create_timer(value['diagnostics_period'], self.publish_diagnostics)
        reports_dir = value['reports_dir']
        self.reports = self.open_reports(reports_dir) if reports_dir else None
        self.publish_state()
        kind = f"a '{self.pinned_type}'" if self.pinned_type else 'any type'
        self.get_logger().info(f"robot '{self.robot}' ({kind}, {self.driver_name} driver) ready, "
                               'waiting for a plan')

    def make_driver(self, value):
        if self.driver_name == 'mock':
            return MockDriver()
        for name in ('travel_action', 'operation_action'):
            if not usable(self, action_name(value[name], self.robot, 'operation')):
                raise ParameterError(f"parameter '{name}' must name an action (letters, "
                                     f'digits, underscores, slashes; {ROBOT_FIELD}, '
                                     f'{OPERATION_FIELD}), got {shorten(value[name], 80)!r}')
        return ActionDriver(self, self.robot, value['travel_action'], value['operation_action'],
                            value['server_timeout'], lambda: self.clock.time_scale,
                            lambda: max(self.now_units(), 0.0))

    def now_units(self) -> float | None:
        """Schedule time since the mission start, or None before the first plan."""
        if self.clock is None:
            return None
        return self.clock.units(self.get_clock().now().nanoseconds * 1e-9)

    # --- plans -------------------------------------------------------------------------

    def on_plan(self, msg: Plan) -> None:
        if not self.auth.accept(msg, PLAN_TOPIC, {PLANNER_NODE}):
            return
        log = self.get_logger()
        mission = shorten(msg.mission_id, 80)
        malformed = plan_problem(msg)
        if malformed:
            # Not a refusal: the fleet's planner never sends one, so the robot's state stays
            # what its own planner expects.
            if not self.malformed_plans:
                log.warning(f"ignoring a malformed plan revision {msg.revision} of mission "
                            f"'{mission}': {malformed}; further ones are only counted")
            self.malformed_plans += 1
            return
        new_mission = msg.mission_id != self.mission_id
        if new_mission and self.clock is not None \
                and seconds(msg.mission_start) <= self.clock.mission_start:
            log.warning(f"ignoring plan of mission '{mission}': it started no later than "
                        f"mission '{self.mission_id}', which this robot follows")
            return
        if not new_mission and msg.revision <= self.execution.revision:
            if msg.revision < self.execution.revision:
                log.warning(f'ignoring stale plan revision {msg.revision}: following '
                            f'revision {self.execution.revision}')
            return
        refusal = self.refusal_of(msg)
        if refusal:
            if refusal != self.refusal:
                log.error(refusal)
            self.refusal = refusal
            self.publish_state()
            return
        self.refusal = ''
        if new_mission:
            self.begin_mission(msg)
        if msg.cancelled:
            self.cancel(msg)
            return
        mine = next(r for r in msg.robots if r.robot == self.robot)
        self.robot_type = mine.robot_type
        if self.time_scale and self.time_scale != msg.time_scale:
            log.warning(f'running at time_scale {self.time_scale} s/unit while the plan '
                        f'assumes {msg.time_scale}: this robot runs off the planned pace')
        job_robots = {}
        for robot_plan in msg.robots:
            for t in robot_plan.tasks:
                job_robots.setdefault(t.job, set()).add(robot_plan.robot)
        restarted_in = plan_attempts(msg.revision, (t for r in msg.robots for t in r.tasks))
        tasks = [Task(job=t.job, operation_type=t.operation_type, location=t.location,
                      travel_start=t.travel_start, arrival=t.arrival, start=t.start,
                      operation_end=t.operation_end, end=t.end,
                      co_workers=tuple(t.co_workers), predecessors=tuple(t.predecessors),
                      held_into_next=t.held_into_next, operation_name=t.operation_name)
                 for t in mine.tasks]
        if mine.incarnation and mine.incarnation != self.incarnation:
            # Planned for an earlier process of this robot, whose work in progress died with
            # it: doing these tasks from scratch would do a job apart from its co-workers.
            log.warning(f'plan revision {msg.revision} was made for an earlier agent of '
                        f"robot '{self.robot}': waiting for a revision planned for this one")
            tasks = []
        now = self.now_units()
        if now >= 0:
            # What was due before the new revision happened under the old one.
            self.publish_events(self.execution.step(now))
        self.execution.set_plan(msg.revision, tasks, job_robots, max(now, 0.0),
                                restarted_in=restarted_in, start_location=mine.start_location)
        log.info(f"following plan revision {msg.revision} of mission '{mission}': "
                 + (' -> '.join(t.job for t in tasks) or 'no task'))
        self.publish_state()  # a new revision is a transition, even before the mission start
        self.tick()

    def refusal_of(self, msg: Plan) -> str:
        """Why this agent cannot follow `msg`, or '' if it can."""
        where = f"plan revision {msg.revision} of mission '{shorten(msg.mission_id, 80)}'"
        mine = [r for r in msg.robots if r.robot == self.robot]
        if not mine:
            if msg.cancelled:
                return ''
            return (f"{where} has no robot '{self.robot}': this agent's robot is not in "
                    f"scenario '{shorten(msg.scenario_id, 80)}'")
        if self.pinned_type and mine[0].robot_type != self.pinned_type:
            return (f"{where} makes '{self.robot}' a '{shorten(mine[0].robot_type, 80)}' but "
                    f"this agent plays a '{self.pinned_type}'; refusing the plan")
        return ''

    def begin_mission(self, msg: Plan) -> None:
        self.execution.start_mission()
        self.mission_id = msg.mission_id
        self.clock = ScheduleClock(seconds(msg.mission_start), self.time_scale or msg.time_scale)
        self.last_state = None
        early = [e for e in self.early_events if e.mission_id == msg.mission_id]
        self.early_events.clear()
        # Verified when heard: checked again, each would be refused as a replay of itself.
        for event in early:
            self.take_event(event)

    def cancel(self, msg: Plan) -> None:
        now = max(self.now_units(), 0.0)
        self.publish_events(self.execution.cancel(now, 'mission cancelled'))
        # The cancelling revision is followed like any other, so older ones stay stale.
        self.execution.set_plan(msg.revision, (), {}, now, restarted_in={})
        self.get_logger().warning(f"mission '{shorten(msg.mission_id, 80)}' cancelled: "
                                  'tasks dropped')
        self.publish_state()
        self.tick()

    # --- what the others report --------------------------------------------------------

    def on_event(self, msg: TaskEvent) -> None:
        senders = {PLANNER_NODE} if msg.kind == TaskEvent.KIND_JOB_DONE else {msg.robot}
        if not self.auth.accept(msg, TASK_EVENTS_TOPIC, senders):
            return
        if msg.mission_id != self.mission_id:
            # The plan of a mission may come after the first reports of the others.
            self.early_events.append(msg)
            return
        self.take_event(msg)

    def take_event(self, msg: TaskEvent) -> None:
        """Record a verified report of the followed mission."""
        kind = EVENT_FROM_MSG.get(msg.kind)
        if kind is None or (msg.robot == self.robot and kind != EventKind.JOB_DONE):
            return
        execution, revision = self.execution, msg.plan_revision
        if kind == EventKind.ARRIVED:
            used = execution.arrived(msg.robot, msg.job, msg.time, revision)
        elif kind == EventKind.OPERATION_DONE:
            used = execution.operation_done(msg.robot, msg.job, msg.time, revision)
        elif kind == EventKind.JOB_DONE:
            used = execution.job_done(msg.job, msg.time, revision)
        elif kind == EventKind.ABORTED:
            used = execution.aborted(msg.job, revision)
        else:
            return
        if not used:
            self.get_logger().debug(f"ignoring event '{shorten(msg.event_id)}' of revision "
                                    f"{revision}: job '{shorten(msg.job)}' was restarted since")
        self.tick()

    # --- faults ------------------------------------------------------------------------

    def on_fault(self, request, response):
        if not self.auth.accept(request, self.fault_service, service=True):
            response.success = False
            response.message = (f"robot '{self.robot}': fault refused, the request is not "
                                'signed with the fleet key')
            return response
        if request.request_id and request.request_id in self.answered:
            response.success, response.message = self.answered[request.request_id]
            return response
        now = self.now_units()
        # Before the first plan nothing runs, so the time of a fault does not matter.
        now = 0.0 if now is None else max(now, 0.0)
        execution = self.execution
        if request.fault == InjectFault.Request.FAULT_FAIL:
            result = execution.fail(now)
        elif request.fault == InjectFault.Request.FAULT_RECOVER:
            result = execution.recover(now)
        elif request.fault == InjectFault.Request.FAULT_DELAY:
            result = execution.delay(request.factor, now)
        else:
            result = FaultResult(False, f"robot '{self.robot}': unknown fault "
                                        f'{request.fault} (FAIL=0, RECOVER=1, DELAY=2)')
        self.publish_events(result.events)
        self.tick()     # a delay moves the end of the operation under way
        if result.accepted:
            if request.fault == InjectFault.Request.FAULT_FAIL:
                self.failures += 1
            self.get_logger().warning(f'fault injected: {result.message}')
            self.publish_state()
        else:
            self.get_logger().warning(result.message)
        response.success, response.message = result.accepted, result.message
        if request.request_id:
            self.answered[request.request_id[:100]] = (result.accepted, result.message)
            while len(self.answered) > ANSWERS_KEPT:
                self.answered.pop(next(iter(self.answered)))
        return response

    # --- stepping and reporting --------------------------------------------------------

    def tick(self) -> None:
        now = self.now_units()
        if now is not None and now >= 0:
            self.publish_events(self.execution.step(now))
            if self.state_key() != self.last_state:
                self.publish_state()
        self.schedule_tick(now)

    def schedule_tick(self, now: float | None) -> None:
        """Step next when the execution is due, or at the latest after `IDLE_TICK` (a plan,
        report or fault steps it at once); poll every `tick_period` while only the driver
        knows when its work ends."""
        if now is None:
            wait = IDLE_TICK    # no mission yet
        else:
            due = 0.0 if now < 0 else self.execution.due()
            if due is None or math.isnan(due):
                wait = self.tick_period
            else:
                # Slightly past the instant, so that the step finds it due.
                wait = (due - now) * self.clock.time_scale + DUE_MARGIN
                wait = min(max(wait, self.tick_period), IDLE_TICK)
        period = round(wait * 1e9)
        if period != self.tick_timer.timer_period_ns:
            self.tick_timer.timer_period_ns = period
        self.tick_timer.reset()

    def state_key(self):
        execution = self.execution
        return (execution.mode, execution.current_job, execution.location,
                execution.revision, self.refusal, self.mission_id)

    def publish_events(self, events) -> None:
        """Publish what a step of the execution produced, and count the failures its driver
        reported meanwhile."""
        for message in self.execution.failures():
            self.failures += 1
            self.get_logger().warning(f'robot failure: {message}')
            self.publish_state()
        for e in events:
            self.event_count += 1
            msg = TaskEvent(
                stamp=self.get_clock().now().to_msg(),
                event_id=f'{self.robot}/{self.incarnation}/{self.event_count}',
                mission_id=self.mission_id, kind=EVENT_TO_MSG[e.kind], robot=self.robot,
                job=e.job, plan_revision=self.execution.revision, time=e.time,
                reason=e.reason)
            if self.reports is not None:
                self.keep_report(msg)
            self.event_pub.publish(self.auth.sign(msg, TASK_EVENTS_TOPIC))
            self.last_event_id = msg.event_id
            self.get_logger().info(f'{e.kind.value} {e.job} at t={e.time:.2f} (attempt '
                                   f'{e.attempt})' + (f' ({e.reason})' if e.reason else ''))

    def open_reports(self, directory: str) -> ReportLog:
        """Keep this agent's reports in `directory`, and publish again those an earlier
        agent of this robot kept there (the latest mission's)."""
        try:
            reports = ReportLog(Path(directory).expanduser(), self.robot, EVENT_HISTORY)
        except OSError as error:
            raise ParameterError(f"parameter 'reports_dir': cannot keep reports in "
                                 f'{directory}: {error.strerror or error}') from None
        published = 0
        for report in reports.earlier:
            try:
                msg = TaskEvent(
                    stamp=RosTime(seconds=report['sec'],
                                  nanoseconds=report['nanosec']).to_msg(),
                    event_id=report['event_id'], mission_id=report['mission_id'],
                    kind=report['kind'], robot=self.robot, job=report['job'],
                    plan_revision=report['revision'], time=float(report['time']),
                    reason=report['reason'])
            except (AssertionError, ValueError, TypeError, OverflowError):
                continue  # a damaged line: the others still count
            self.event_pub.publish(self.auth.sign(msg, TASK_EVENTS_TOPIC))
            self.last_event_id = msg.event_id
            published += 1
        if published:
            self.get_logger().info(f'published again {published} reports an earlier agent of '
                                   f"robot '{self.robot}' kept in {reports.path}")
        return reports

    def keep_report(self, msg: TaskEvent) -> None:
        """On disk before anyone hears of it; a disk that refuses it stops the keeping, not
        the robot."""
        try:
            self.reports.append({
                'sec': msg.stamp.sec, 'nanosec': msg.stamp.nanosec, 'event_id': msg.event_id,
                'mission_id': msg.mission_id, 'kind': msg.kind, 'robot': msg.robot,
                'job': msg.job, 'revision': msg.plan_revision, 'time': msg.time,
                'reason': msg.reason})
        except OSError as error:
            self.get_logger().error(f'no longer keeping reports in {self.reports.path}: '
                                    f'{error.strerror or error}')
            self.reports = None

    def publish_state(self) -> None:
        now = self.now_units()
        execution = self.execution
        self.last_state = self.state_key()
        self.state_pub.publish(self.auth.sign(RobotState(
            stamp=self.get_clock().now().to_msg(), robot=self.robot,
            robot_type=self.robot_type, incarnation=self.incarnation,
            mission_id=self.mission_id, mode=MODE_TO_MSG[execution.mode],
            plan_revision=execution.revision, refusal=self.refusal, failures=self.failures,
            current_job=execution.current_job, location=execution.location,
            destination=execution.destination,
            progress=execution.progress(now) if now is not None else 0.0,
            busy_until=execution.busy_until, last_event_id=self.last_event_id,
            refused=self.auth.rejected),
            ROBOT_STATES_TOPIC))


    def publish_diagnostics(self) -> None:
        execution = self.execution
        task = execution.task
        late_by = 0.0
        if task is not None and execution.mode == RobotMode.WORKING:
            late_by = max(0.0, execution.busy_until - task.operation_end)
        self.diagnostics_pub.publish(diagnostic_array(
            self.get_clock().now().to_msg(),
            [robot_diagnostic(f'{self.get_name()}: robot', self.robot, execution.mode,
                              job=execution.current_job, late_by=late_by,
                              late_threshold=self.late_threshold, refusal=self.refusal,
                              values={'type': self.robot_type, 'mission': self.mission_id,
                                      'plan revision': execution.revision,
                                      'failures': self.failures})]))


    def destroy_node(self):
        if isinstance(self.execution.driver, ActionDriver):
            self.execution.driver.close()
        if self.reports is not None:
            try:
                self.reports.close()
            except OSError:
                pass  # what was written is on its way to disk; nothing more to save
        return super().destroy_node()


def robot_name_from_parameters() -> str:
    """The `robot_name` parameter as given (-p, --params-file), read before the agent's node
    exists, because the node is named after it."""
    probe = Node(NAME_LOOKUP_NODE, start_parameter_services=False,
                 enable_rosout=False)
    try:
        robot = declare(probe, ROBOT_NAME)
    finally:
        probe.destroy_node()
    if not robot:
        raise ParameterError("parameter 'robot_name' is required "
                             '(e.g. --ros-args -p robot_name:=MARC1)')
    if not robot.replace('_', 'a').isalnum() or not robot[0].isalpha() \
            or not robot.isascii():
        raise ParameterError("parameter 'robot_name' must be usable in a ROS name (ASCII "
                             f'letters, digits, underscores, starting with a letter), got '
                             f'{shorten(robot, 80)!r}')
    return robot


def run(pinned_type: str = '', args=None) -> int:
    return run_node(lambda: RobotAgent(robot_name_from_parameters(), pinned_type),
                    'robot_agent', args)


def main(args=None):
    sys.exit(run('', args))


def assembler_main(args=None):
    sys.exit(run('Assembler', args))


def marc_main(args=None):
    sys.exit(run('MARC', args))


def lsms_main(args=None):
    sys.exit(run('LSMS', args))
