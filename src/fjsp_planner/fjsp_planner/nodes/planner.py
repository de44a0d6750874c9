"""The planner node: waits for the fleet, solves the scenario, publishes the plan latched,
tracks its execution from the robots' reports, and re-plans what remains when a robot fails,
goes silent, recovers or runs late (see docs/ros-interfaces.md)."""

import math
import secrets
import sys
import time
from concurrent.futures import Future, ThreadPoolExecutor
from datetime import UTC, datetime
from pathlib import Path

from ament_index_python.packages import PackageNotFoundError, get_package_share_directory
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.time import Time

from fjsp_common.contract import (
    EVENT_FROM_MSG,
    EVENTS_QOS,
    JOB_STATES_TOPIC,
    LATCHED_QOS,
    MISSION_STATUS_TOPIC,
    MODE_FROM_MSG,
    PLAN_TOPIC,
    ROBOT_STATES_QOS,
    ROBOT_STATES_TOPIC,
    TASK_EVENTS_TOPIC,
)
from fjsp_common.running import ParameterError, declare, run_node, shorten
from fjsp_common.vocabulary import RobotMode
from fjsp_msgs.msg import JobStates, MissionStatus, Plan, RobotState, TaskEvent
from fjsp_planner.core.problem import Problem, ProblemError
from fjsp_planner.core.replan import Replan, replan
from fjsp_planner.core.scenario import load_scenario
from fjsp_planner.core.schedule import Result, Schedule
from fjsp_planner.core.solve import SOLVERS, solve
from fjsp_planner.core.tracking import Ignored, MissionTracker
from fjsp_planner.core.validate import validate
from fjsp_planner.nodes.conversions import job_states, plan_msg


def new_mission_id(scenario: str) -> str:
    """Unique, and sorting by start time: `<scenario>-<UTC time>-<random>`."""
    stamp = datetime.now(UTC).strftime('%Y%m%dT%H%M%S')
    name = ''.join(c if c.isalnum() or c in '_-' else '_' for c in scenario)[:40]
    return f'{name}-{stamp}-{secrets.token_hex(2)}'


def default_scenario() -> str:
    try:
        share = get_package_share_directory('fjsp_planner')
    except PackageNotFoundError:
        raise ParameterError("parameter 'scenario' not given and package 'fjsp_planner' "
                             'is not installed; pass -p scenario:=<path>') from None
    return str(Path(share) / 'scenarios' / 'solar_panel.yaml')


class PlannerNode(Node):
    def __init__(self):
        super().__init__('planner')
        scenario = declare(self, 'scenario', '',
                           'scenario file of the mission to run at start-up') \
            or default_scenario()
        panels = declare(self, 'panels', 0, "panels of the scenario's job set; 0: the file's",
                         low=0, high=50)
        shift = declare(self, 'shift', -1.0,
                        "distance added per panel apart; negative: the file's", low=-1.0,
                        high=1e6)
        self.solver = declare(self, 'solver', 'cpsat', 'solver of the first plan',
                              constraints='one of: ' + ', '.join(SOLVERS))
        if self.solver not in SOLVERS:
            raise ParameterError(f"parameter 'solver' must be one of {', '.join(SOLVERS)}, "
                                 f'got {shorten(self.solver, 80)!r}')
        declare(self, 'time_limit', 10.0, 'seconds the first plan may take', low=0.01,
                high=3600.0, read_only=False)
        declare(self, 'replan_time_limit', 1.0, 'seconds a re-plan may take', low=0.01,
                high=600.0, read_only=False)
        declare(self, 'workers', 2, 'CP-SAT search workers', low=1, high=64, read_only=False)
        declare(self, 'heartbeat_timeout', 1.0,
                'seconds without a robot state before a robot is offline', low=0.05,
                high=600.0, read_only=False)
        declare(self, 'delay_threshold', 2.0,
                'schedule units an operation may run late before a re-plan', low=0.0,
                high=1e6, read_only=False)
        self.time_scale = declare(self, 'time_scale', 0.05,
                                  'wall seconds per schedule unit', low=1e-4, high=1000.0)
        self.robot_wait_timeout = declare(
            self, 'robot_wait_timeout', 15.0,
            'seconds to wait for every robot to report before planning without it',
            low=0.0, high=3600.0)
        self.start_delay = declare(self, 'start_delay', 0.5,
                                   'seconds from the first plan to the mission start',
                                   low=0.0, high=3600.0)
        status_period = declare(self, 'status_period', 0.5,
                                'seconds between periodic status publications', low=0.01,
                                high=60.0)
        try:
            self.problem: Problem = load_scenario(scenario, panels=panels or None,
                                                  shift=shift if shift >= 0 else None)
        except ProblemError as error:
            raise ParameterError(f"parameter 'scenario': cannot use '{scenario}':\n"
                                 + '\n'.join(error.problems)) from None
        log = self.get_logger()
        log.info(f"scenario '{self.problem.name}' from {scenario}: "
                 f'{len(self.problem.jobs)} jobs, robots '
                 + ', '.join(r.name for r in self.problem.robots))

        self.mission_id = new_mission_id(self.problem.name)
        self.tracker = MissionTracker(self.problem)
        self.state = MissionStatus.STATE_WAITING_FOR_ROBOTS
        self.blocked: list[str] = []
        self.plan: Plan | None = None
        self.schedule: Schedule | None = None
        self.mission_start: Time | None = None
        self.job_done_ids: set[str] = set()
        self.foreign_missions: set[str] = set()
        self.solving: Future | None = None
        self.planned_health: frozenset[str] = frozenset()
        """The robots the current plan (or the blocked verdict) took as healthy."""
        self.solving_health: frozenset[str] = frozenset()
        self.last_heard: dict[str, float] = {}
        self.last_tick = time.monotonic()
        # One worker thread: the solve runs there so the executor keeps serving callbacks.
        self.pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix='solver')
        self.waiting_since = self.get_clock().now()

        self.plan_pub = self.create_publisher(Plan, PLAN_TOPIC, LATCHED_QOS)
        self.status_pub = self.create_publisher(MissionStatus, MISSION_STATUS_TOPIC, LATCHED_QOS)
        self.jobs_pub = self.create_publisher(JobStates, JOB_STATES_TOPIC, LATCHED_QOS)
        self.event_pub = self.create_publisher(TaskEvent, TASK_EVENTS_TOPIC, EVENTS_QOS)
        self.create_subscription(RobotState, ROBOT_STATES_TOPIC, self.on_robot_state,
                                 ROBOT_STATES_QOS)
        self.create_subscription(TaskEvent, TASK_EVENTS_TOPIC, self.on_event, EVENTS_QOS)
        self.create_subscription(Plan, PLAN_TOPIC, self.on_plan, LATCHED_QOS)
        self.create_timer(0.1, self.tick)
        self.create_timer(status_period, self.publish_periodic)
        self.publish_status()

    # Parameters the node honours when they are set at run time: read at each use.
    time_limit = property(lambda self: self.get_parameter('time_limit').value)
    replan_time_limit = property(lambda self: self.get_parameter('replan_time_limit').value)
    workers = property(lambda self: self.get_parameter('workers').value)
    heartbeat_timeout = property(lambda self: self.get_parameter('heartbeat_timeout').value)
    delay_threshold = property(lambda self: self.get_parameter('delay_threshold').value)

    # --- time ------------------------------------------------------------------------

    def now_units(self) -> float:
        """Schedule time since the mission start (negative before it, 0 without a plan)."""
        if self.mission_start is None:
            return 0.0
        elapsed = (self.get_clock().now() - self.mission_start).nanoseconds * 1e-9
        return elapsed / self.time_scale

    # --- planning --------------------------------------------------------------------

    def tick(self) -> None:
        self.check_heartbeats()
        if self.state == MissionStatus.STATE_WAITING_FOR_ROBOTS:
            missing = self.tracker.missing_robots
            waited = (self.get_clock().now() - self.waiting_since).nanoseconds * 1e-9
            # Discovery is per direction: hearing a robot does not mean it hears the plan
            # topic yet, and a plan it gets a second late makes it start late.
            unmatched = self.plan_pub.get_subscription_count() < len(self.problem.robots)
            if (missing or unmatched) and waited < self.robot_wait_timeout:
                return
            if missing:
                self.get_logger().warning(
                    f'planning without a report from {", ".join(missing)} after waiting '
                    f'{self.robot_wait_timeout:g} s; they get the plan when they join')
            self.start_solve()
        elif self.solving is not None:
            if self.solving.done():
                future, self.solving = self.solving, None
                if self.state == MissionStatus.STATE_PLANNING:
                    self.finish_solve(future)
                else:
                    self.finish_replan(future)
        elif self.state in (MissionStatus.STATE_EXECUTING, MissionStatus.STATE_BLOCKED):
            reasons = self.replan_reasons()
            if reasons:
                self.start_replan(reasons)

    def start_solve(self) -> None:
        self.state = MissionStatus.STATE_PLANNING
        self.get_logger().info(f'solving with {self.solver}, time limit {self.time_limit:g} s, '
                               f'{self.workers} workers')
        # Plans for every robot; one already known to be out is re-planned away at once.
        self.solving_health = frozenset(r.name for r in self.problem.robots)
        self.solving = self.pool.submit(solve, self.problem, solver=self.solver,
                                        time_limit=self.time_limit, workers=self.workers)
        self.publish_status()

    def finish_solve(self, future: Future) -> None:
        try:
            result: Result = future.result()
        except ValueError as error:
            self.fail([f'solver: {error}'])
            return
        if result.schedule is None:
            self.fail([f"no plan: solver '{result.solver}' answered {result.status} "
                       f'within {self.time_limit:g} s'])
            return
        problems = validate(self.problem, result.schedule)
        if problems:
            self.fail([f'solver returned an invalid schedule: {p}' for p in problems])
            return
        self.planned_health = self.solving_health
        self.publish_plan(self.problem, result)

    # --- re-planning -----------------------------------------------------------------

    def replan_reasons(self) -> list[str]:
        """Why the current plan (or blocked verdict) no longer fits the fleet; empty if it
        does. Late operations count only while executing: a blocked mission waits for a
        robot to come back."""
        tracker = self.tracker
        healthy = tracker.healthy
        reasons = [f"robot '{r}' {tracker.robots[r].mode}"
                   for r in sorted(self.planned_health - healthy)]
        reasons += [f"robot '{r}' back in service" for r in sorted(healthy - self.planned_health)]
        if self.state == MissionStatus.STATE_EXECUTING:
            reasons += [f"job '{j}' aborted" for j in sorted(tracker.aborted)]
            reasons += tracker.overruns(self.delay_threshold)
        return reasons

    def start_replan(self, reasons: list[str]) -> None:
        self.state = MissionStatus.STATE_REPLANNING
        now = self.now_units()
        self.get_logger().warning(f're-planning at t={now:.2f}: ' + '; '.join(reasons))
        try:
            state = self.tracker.execution_state(now)
        except ValueError as error:
            self.block([f'cannot tell the execution state: {error}'])
            return
        self.solving_health = self.tracker.healthy
        self.solving = self.pool.submit(replan, self.problem, self.schedule, state,
                                        time_limit=self.replan_time_limit,
                                        workers=self.workers)
        self.publish_status()

    def finish_replan(self, future: Future) -> None:
        log = self.get_logger()
        if self.tracker.complete:
            self.state = MissionStatus.STATE_COMPLETE
            return
        if self.tracker.healthy != self.solving_health:
            # The fleet changed while solving: this plan would give work to a robot that is
            # out, or leave out one that is back. The next tick re-plans from the new state.
            log.warning('discarding the re-plan: the fleet changed while it was solved')
            self.state = MissionStatus.STATE_EXECUTING
            return
        self.planned_health = self.solving_health
        try:
            outcome: Replan = future.result()
        except ValueError as error:
            self.block([f're-planning failed: {error}'])
            return
        residual = outcome.residual
        if residual.complete:
            self.state = MissionStatus.STATE_EXECUTING
            return
        if residual.blocked:
            self.block(residual.blocked)
            return
        result = outcome.result
        if result.schedule is None:
            self.block([f"no plan for what remains: solver '{result.solver}' answered "
                        f'{result.status} within {self.replan_time_limit:g} s'])
            return
        if outcome.problems:
            self.block([f're-planned schedule is invalid: {p}' for p in outcome.problems])
            return
        for what, jobs in (('redone', residual.aborted), ('voided', residual.voided),
                           ('kept held', residual.kept)):
            if jobs:
                log.info(f'  {what}: {", ".join(jobs)}')
        self.blocked = []
        self.publish_plan(residual.problem, result, frozenset(residual.problem.fixed))

    def publish_plan(self, posed: Problem, result: Result, continued=frozenset()) -> None:
        """Publish `result` (a schedule of `posed`) as the next revision and follow it."""
        log = self.get_logger()
        revision = self.tracker.revision + 1
        self.tracker.set_plan(result.schedule, revision, continued)
        self.schedule = result.schedule
        now = self.get_clock().now()
        if self.mission_start is None:
            self.mission_start = now + Duration(nanoseconds=int(self.start_delay * 1e9))
        self.plan = plan_msg(self.problem, posed, result.schedule, result, self.mission_id,
                             revision, self.mission_start.to_msg(), self.time_scale,
                             now.to_msg(), continued)
        self.plan_pub.publish(self.plan)
        self.state = MissionStatus.STATE_EXECUTING
        gap = f', gap {result.gap:.1%}' if result.gap is not None else ''
        log.info(f'published plan revision {revision}: makespan {float(result.makespan):g} '
                 f'({result.status}{gap}, {result.solve_seconds:.2f} s)'
                 + (f'; mission starts in {self.start_delay:g} s at {self.time_scale:g} s '
                    'per unit' if revision == 1 else f' at t={self.now_units():.2f}'))
        for robot_plan in self.plan.robots:
            log.info(f'  {robot_plan.robot}: '
                     + (' -> '.join(t.job for t in robot_plan.tasks) or 'no task'))
        self.publish_jobs()
        self.publish_status()

    def block(self, reasons: list[str]) -> None:
        """Nothing can be planned until the fleet changes; the current plan stays, so the
        robots finish what they can of it."""
        self.state = MissionStatus.STATE_BLOCKED
        self.blocked = reasons
        for reason in reasons:
            self.get_logger().error(f'blocked: {reason}')
        self.publish_status()

    def check_heartbeats(self) -> None:
        now = time.monotonic()
        starved, self.last_tick = now - self.last_tick > 0.25, now
        if starved:
            # The executor could not take messages for a while: the heartbeats it has not
            # processed yet come first, before any robot is judged silent.
            return
        for robot, heard in self.last_heard.items():
            record = self.tracker.robots[robot]
            if record.mode != RobotMode.OFFLINE and now - heard > self.heartbeat_timeout:
                self.tracker.mark_offline(robot)
                self.get_logger().error(f"robot '{robot}' offline: no state for "
                                        f'{now - heard:.1f} s; treated as failed')

    def fail(self, reasons: list[str]) -> None:
        self.state = MissionStatus.STATE_FAILED
        self.blocked = reasons
        for reason in reasons:
            self.get_logger().error(reason)
        self.publish_status()

    # --- reports ---------------------------------------------------------------------

    def ignored(self, outcome, what: str) -> None:
        self.get_logger().warning(f'ignoring {outcome.ignored} {what}: {outcome.reason}')
        self.publish_status()

    def on_robot_state(self, msg: RobotState) -> None:
        mode = MODE_FROM_MSG.get(msg.mode)
        if mode is None:
            self.tracker.ignored[Ignored.UNKNOWN] += 1
            return
        was_offline = msg.robot in self.tracker.robots \
            and self.tracker.robots[msg.robot].mode == RobotMode.OFFLINE
        outcome = self.tracker.record_robot_state(msg.robot, mode, msg.location,
                                                  msg.destination, msg.busy_until,
                                                  msg.current_job)
        if outcome.ignored:
            if not outcome.repeated:
                self.ignored(outcome, 'robot state')
            return
        self.last_heard[msg.robot] = time.monotonic()
        if was_offline:
            self.get_logger().warning(f"robot '{msg.robot}' reports again ({mode})")

    def on_event(self, msg: TaskEvent) -> None:
        if msg.mission_id != self.mission_id:
            self.tracker.ignored[Ignored.STALE] += 1
            if msg.mission_id not in self.foreign_missions:
                self.foreign_missions.add(msg.mission_id)
                self.get_logger().warning(
                    f"ignoring events of mission '{shorten(msg.mission_id, 80)}': this planner "
                    f"runs mission '{self.mission_id}'")
            self.publish_status()
            return
        if msg.kind == TaskEvent.KIND_JOB_DONE:
            if msg.event_id not in self.job_done_ids:
                self.tracker.ignored[Ignored.UNKNOWN] += 1
                self.get_logger().warning(f"ignoring unknown job-done event '{msg.event_id}':"
                                          ' only the planner declares jobs done')
                self.publish_status()
            return
        if msg.kind not in EVENT_FROM_MSG:
            self.tracker.ignored[Ignored.UNKNOWN] += 1
            self.get_logger().warning(f"ignoring unknown event '{msg.event_id}': kind "
                                      f'{msg.kind} is not a TaskEvent kind')
            self.publish_status()
            return
        outcome = self.tracker.record_event(msg.event_id, EVENT_FROM_MSG[msg.kind], msg.robot,
                                            msg.job, msg.plan_revision, msg.time)
        if outcome.ignored:
            self.ignored(outcome, 'event')
            return
        if outcome.job_done is not None:
            job, end = outcome.job_done
            event_id = f'planner/{self.mission_id}/{job}/job_done/{self.tracker.revision}'
            self.job_done_ids.add(event_id)
            self.event_pub.publish(TaskEvent(
                stamp=self.get_clock().now().to_msg(), event_id=event_id,
                mission_id=self.mission_id, kind=TaskEvent.KIND_JOB_DONE, job=job,
                plan_revision=self.tracker.revision, time=end))
            done = len(self.tracker.done)
            self.get_logger().info(f'job {job} done at t={end:.2f} ({done}/'
                                   f'{len(self.tracker.jobs)})')
            if self.tracker.complete:
                self.state = MissionStatus.STATE_COMPLETE
                self.get_logger().info(
                    f'mission complete: executed makespan '
                    f'{float(self.tracker.projected_makespan(0)):.2f}, planned '
                    f'{self.plan.makespan:g}')
        self.publish_jobs()
        self.publish_status()

    def on_plan(self, msg: Plan) -> None:
        if self.plan is not None and msg.revision == self.plan.revision \
                and msg.stamp == self.plan.stamp:
            return
        current = self.tracker.revision
        kind = Ignored.STALE if msg.revision <= current else Ignored.UNKNOWN
        self.tracker.ignored[kind] += 1
        self.get_logger().warning(f'ignoring {kind} plan revision {msg.revision} from another '
                                  f'publisher: this planner owns the plan (revision {current})')
        self.publish_status()

    # --- publishing ------------------------------------------------------------------

    def publish_periodic(self) -> None:
        self.publish_status()
        if self.tracker.plan is not None:
            self.publish_jobs()

    def publish_jobs(self) -> None:
        self.jobs_pub.publish(JobStates(stamp=self.get_clock().now().to_msg(),
                                        mission_id=self.mission_id,
                                        plan_revision=self.tracker.revision,
                                        jobs=job_states(self.tracker)))

    def publish_status(self) -> None:
        tracker = self.tracker
        now = self.now_units()
        planned = self.plan.makespan if self.plan is not None else math.nan
        projected = float(tracker.projected_makespan(now)) if tracker.plan else math.nan
        blocked = list(self.blocked)
        if self.state == MissionStatus.STATE_WAITING_FOR_ROBOTS:
            blocked = [f"waiting for robot '{r}' to report" for r in tracker.missing_robots]
        self.status_pub.publish(MissionStatus(
            stamp=self.get_clock().now().to_msg(), mission_id=self.mission_id, state=self.state,
            plan_revision=tracker.revision, scenario_id=self.problem.name,
            jobs_done=len(tracker.done), jobs_running=len(tracker.running),
            jobs_total=len(tracker.jobs), planned_makespan=planned,
            projected_makespan=projected, elapsed=max(now, 0.0), blocked_reasons=blocked,
            ignored_stale=tracker.ignored[Ignored.STALE],
            ignored_duplicate=tracker.ignored[Ignored.DUPLICATE],
            ignored_unknown=tracker.ignored[Ignored.UNKNOWN]))

    def destroy_node(self):
        self.pool.shutdown(wait=False, cancel_futures=True)
        return super().destroy_node()


def main(args=None):
    sys.exit(run_node(PlannerNode, 'planner', args))
