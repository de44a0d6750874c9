"""A mock robot: follows its task sequence of the latest plan in simulated time.

One process per robot (`robot_name` parameter); the three executables differ only in the robot
type they accept, so a plan that gives MARC1 to an assembler_agent is refused, not executed.
Faults are injected through its `<robot_name>/inject_fault` service (`fjsp_planner.faults`).
"""

import sys

from rclpy.exceptions import InvalidServiceNameException
from rclpy.node import Node
from rclpy.time import Time as RosTime

from fjsp_msgs.msg import Plan, RobotState, TaskEvent
from fjsp_msgs.srv import InjectFault
from fjsp_planner.nodes.interfaces import (
    EVENTS_QOS,
    INJECT_FAULT_SERVICE,
    LATCHED_QOS,
    PLAN_TOPIC,
    ROBOT_STATES_TOPIC,
    TASK_EVENTS_TOPIC,
)
from fjsp_planner.nodes.running import ParameterError, declared, run_node
from robot_agents.execution import EventKind, FaultResult, Mode, RobotExecution, Task

MODE_TO_MSG = {
    Mode.IDLE: RobotState.MODE_IDLE,
    Mode.TRAVELLING: RobotState.MODE_TRAVELLING,
    Mode.WAITING: RobotState.MODE_WAITING,
    Mode.WORKING: RobotState.MODE_WORKING,
    Mode.HOLDING: RobotState.MODE_HOLDING,
    Mode.FAILED: RobotState.MODE_FAILED,
}
KIND_TO_MSG = {
    EventKind.ARRIVED: TaskEvent.KIND_ARRIVED,
    EventKind.STARTED: TaskEvent.KIND_STARTED,
    EventKind.OPERATION_DONE: TaskEvent.KIND_OPERATION_DONE,
    EventKind.ABORTED: TaskEvent.KIND_ABORTED,
}


class RobotAgent(Node):
    def __init__(self, robot_type: str):
        super().__init__(f'{robot_type.lower()}_agent')
        self.robot_type = robot_type
        self.robot = declared(self, 'robot_name', '')
        self.time_scale = declared(self, 'time_scale', 0.0)
        tick_period = declared(self, 'tick_period', 0.01)
        heartbeat_period = declared(self, 'heartbeat_period', 0.2)
        if not self.robot:
            raise ParameterError("parameter 'robot_name' is required "
                                 '(e.g. --ros-args -p robot_name:=MARC1)')
        if not self.time_scale >= 0:
            raise ParameterError(f"parameter 'time_scale' must be >= 0 (0: the plan's), "
                                 f'got {self.time_scale}')
        for name, value in (('tick_period', tick_period),
                            ('heartbeat_period', heartbeat_period)):
            if not value > 0:
                raise ParameterError(f"parameter '{name}' must be > 0 seconds, got {value}")

        self.execution = RobotExecution(self.robot)
        self.mission_start: RosTime | None = None
        self.scale = self.time_scale
        self.last_state = None

        self.state_pub = self.create_publisher(RobotState, ROBOT_STATES_TOPIC, LATCHED_QOS)
        self.event_pub = self.create_publisher(TaskEvent, TASK_EVENTS_TOPIC, EVENTS_QOS)
        self.create_subscription(Plan, PLAN_TOPIC, self.on_plan, LATCHED_QOS)
        self.create_subscription(TaskEvent, TASK_EVENTS_TOPIC, self.on_event, EVENTS_QOS)
        try:
            self.create_service(InjectFault, f'{self.robot}/{INJECT_FAULT_SERVICE}',
                                self.on_fault)
        except InvalidServiceNameException:
            raise ParameterError(f"parameter 'robot_name' must be usable in a ROS name "
                                 f'(letters, digits, underscores), got {self.robot!r}') from None
        self.create_timer(tick_period, self.tick)
        self.create_timer(heartbeat_period, self.publish_state)
        self.publish_state()
        self.get_logger().info(f"robot '{self.robot}' ({robot_type}) ready, waiting for a plan")

    def now_units(self) -> float | None:
        """Schedule time since the mission start, or None before the first plan."""
        if self.mission_start is None:
            return None
        elapsed = (self.get_clock().now() - self.mission_start).nanoseconds * 1e-9
        return elapsed / self.scale

    def on_plan(self, msg: Plan) -> None:
        log = self.get_logger()
        if msg.revision <= self.execution.revision:
            if msg.revision < self.execution.revision:
                log.warning(f'ignoring stale plan revision {msg.revision}: following '
                            f'revision {self.execution.revision}')
            return
        mine = [r for r in msg.robots if r.robot == self.robot]
        if not mine:
            log.warning(f"plan revision {msg.revision} has no robot '{self.robot}'; "
                        'staying idle')
            return
        if mine[0].robot_type != self.robot_type:
            log.error(f"plan revision {msg.revision} makes '{self.robot}' a "
                      f"'{mine[0].robot_type}' but this agent is a '{self.robot_type}'; "
                      'ignoring the plan')
            return
        if not msg.time_scale > 0:
            log.error(f'plan revision {msg.revision} has time_scale {msg.time_scale}; '
                      'ignoring the plan')
            return
        if self.time_scale and self.time_scale != msg.time_scale:
            log.warning(f'running at time_scale {self.time_scale} s/unit while the plan '
                        f'assumes {msg.time_scale}: this robot runs off the planned pace')
        self.scale = self.time_scale or msg.time_scale
        self.mission_start = RosTime.from_msg(msg.mission_start)
        job_robots, continued = {}, set()
        for robot_plan in msg.robots:
            for t in robot_plan.tasks:
                job_robots.setdefault(t.job, set()).add(robot_plan.robot)
                if t.continued:
                    continued.add(t.job)
        tasks = [Task(job=t.job, operation_type=t.operation_type, location=t.location,
                      travel_start=t.travel_start, arrival=t.arrival, start=t.start,
                      operation_end=t.operation_end, end=t.end,
                      co_workers=tuple(t.co_workers), predecessors=tuple(t.predecessors),
                      held_into_next=t.held_into_next)
                 for t in mine[0].tasks]
        now = self.now_units()
        if now >= 0:
            # What was due before the new revision happened under the old one.
            self.publish_events(self.execution.step(now))
        self.execution.set_plan(msg.revision, tasks, job_robots, max(now, 0.0),
                                continued=continued)
        log.info(f'following plan revision {msg.revision}: '
                 + (' -> '.join(t.job for t in tasks) or 'no task'))
        self.publish_state()  # a new revision is a transition, even before the mission start
        self.tick()

    def on_event(self, msg: TaskEvent) -> None:
        if msg.robot == self.robot and msg.kind != TaskEvent.KIND_JOB_DONE:
            return
        execution, revision = self.execution, msg.plan_revision
        if msg.kind == TaskEvent.KIND_ARRIVED:
            used = execution.arrived(msg.robot, msg.job, msg.time, revision)
        elif msg.kind == TaskEvent.KIND_OPERATION_DONE:
            used = execution.operation_done(msg.robot, msg.job, msg.time, revision)
        elif msg.kind == TaskEvent.KIND_JOB_DONE:
            used = execution.job_done(msg.job, msg.time, revision)
        elif msg.kind == TaskEvent.KIND_ABORTED:
            used = execution.aborted(msg.job, revision)
        else:
            return
        if not used:
            self.get_logger().debug(f"ignoring event '{msg.event_id}' of revision {revision}: "
                                    f"job '{msg.job}' was restarted since")
        self.tick()

    def on_fault(self, request, response):
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
        if result.accepted:
            self.get_logger().warning(f'fault injected: {result.message}')
            self.publish_state()
        else:
            self.get_logger().warning(result.message)
        response.success, response.message = result.accepted, result.message
        return response

    def tick(self) -> None:
        now = self.now_units()
        if now is None or now < 0:
            return
        self.publish_events(self.execution.step(now))
        state = (self.execution.mode, self.execution.current_job, self.execution.location,
                 self.execution.revision)
        if state != self.last_state:
            self.publish_state()

    def publish_events(self, events) -> None:
        for e in events:
            kind = e.kind.value
            self.event_pub.publish(TaskEvent(
                stamp=self.get_clock().now().to_msg(),
                event_id=f'{self.robot}/{e.job}/{kind}/{e.attempt}',
                kind=KIND_TO_MSG[e.kind], robot=self.robot, job=e.job,
                plan_revision=self.execution.revision, time=e.time, reason=e.reason))
            self.get_logger().info(f'{kind} {e.job} at t={e.time:.2f}'
                                   + (f' ({e.reason})' if e.reason else ''))

    def publish_state(self) -> None:
        now = self.now_units()
        execution = self.execution
        self.last_state = (execution.mode, execution.current_job, execution.location,
                           execution.revision)
        self.state_pub.publish(RobotState(
            stamp=self.get_clock().now().to_msg(), robot=self.robot,
            robot_type=self.robot_type, mode=MODE_TO_MSG[execution.mode],
            plan_revision=execution.revision, current_job=execution.current_job,
            location=execution.location, destination=execution.destination,
            progress=execution.progress(now) if now is not None else 0.0,
            busy_until=execution.busy_until))


def run(robot_type: str, args=None) -> int:
    return run_node(lambda: RobotAgent(robot_type), f'{robot_type.lower()}_agent', args)


def assembler_main(args=None):
    sys.exit(run('Assembler', args))


def marc_main(args=None):
    sys.exit(run('MARC', args))


def lsms_main(args=None):
    sys.exit(run('LSMS', args))

