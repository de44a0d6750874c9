"""Integration harness: real node processes started with `ros2 run`, over real Fast DDS.

Each test gets its own ROS_DOMAIN_ID (discovery stays on localhost), an observer node in the
test process that records every public topic, and a launcher whose processes are stopped
(SIGINT, then SIGKILL of the whole process group) whatever the test does.
"""

import fcntl
import os
import random
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from collections import defaultdict
from contextlib import contextmanager
from fractions import Fraction
from pathlib import Path

import pytest

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

if shutil.which('ros2') is None or 'AMENT_PREFIX_PATH' not in os.environ:
    pytest.exit('integration tests need the built workspace: run `bash ros2_ws/test.sh`, or '
                '`bash ros2_ws/bootstrap.sh && source ros2_ws/env.sh` before pytest', 4)

import rclpy  # noqa: E402  (after the environment check, for a clear message)
from rclpy.executors import SingleThreadedExecutor  # noqa: E402

from fjsp_common.contract import (  # noqa: E402
    EVENTS_QOS,
    JOB_STATES_TOPIC,
    LATCHED_QOS,
    MISSION_STATUS_TOPIC,
    PLAN_TOPIC,
    ROBOT_STATES_TOPIC,
    TASK_EVENTS_TOPIC,
)
from fjsp_msgs.msg import JobStates, MissionStatus, Plan, RobotState, TaskEvent  # noqa: E402
from fjsp_planner.core.schedule import JobAssignment, Schedule  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
SCENARIO = REPO / 'config' / 'scenarios' / 'solar_panel.yaml'
ROBOTS = (('Assembler', 'assembler_agent'), ('LSMS', 'lsms_agent'),
          ('MARC1', 'marc_agent'), ('MARC2', 'marc_agent'))
TIME_SCALE = 0.03
"""Wall seconds per schedule unit: the 32-unit mission takes about a second."""

DOMAINS = range(1, 101)
"""ROS domain ids Fast DDS can use on one host (each maps to its own ports)."""


@contextmanager
def private_domain():
    """A ROS domain id no other test process on this machine holds while the block runs:
    each is claimed with an exclusive lock on a file, released when the block ends or the
    process dies. Without it, two test runs at once (two checkouts, CI and a developer) can
    share a domain and see each other's robots."""
    start = random.randrange(len(DOMAINS))
    for index in range(len(DOMAINS)):
        domain = DOMAINS[(start + index) % len(DOMAINS)]
        lock = open(f'{tempfile.gettempdir()}/fjsp-ros-domain-{domain}.lock', 'w')  # noqa: SIM115
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            lock.close()
            continue
        try:
            yield domain
        finally:
            lock.close()
        return
    raise RuntimeError(f'every ROS domain id {DOMAINS.start}..{DOMAINS.stop - 1} is in use '
                       'by other test processes on this machine')


class Launcher:
    """Starts executables with `ros2 run` in their own process groups; stops them all."""

    def __init__(self, domain: int, logs: Path):
        self.env = dict(os.environ, ROS_DOMAIN_ID=str(domain), PYTHONUNBUFFERED='1')
        self.logs = logs
        self.processes: dict[str, subprocess.Popen] = {}

    def start(self, name, package, executable, params=(), extra=()):
        command = ['ros2', 'run', package, executable, *extra, '--ros-args',
                   '-r', f'__node:={name}']
        for key, value in params:
            if value is not None:
                command += ['-p', f'{key}:={value}']
        log = (self.logs / f'{name}.log').open('w')
        self.processes[name] = subprocess.Popen(command, env=self.env, stdout=log,
                                                stderr=subprocess.STDOUT,
                                                start_new_session=True)
        log.close()
        return self.processes[name]

    def start_planner(self, **params):
        params = {'scenario': SCENARIO, 'time_scale': TIME_SCALE, 'time_limit': 5.0,
                  'start_delay': 0.3, **params}
        return self.start('planner', 'fjsp_planner', 'planner_node', params.items())

    def start_agent(self, robot, executable=None, **params):
        executable = executable or dict(ROBOTS)[robot]
        return self.start(f'{robot.lower()}_agent', 'robot_agents', executable,
                          [('robot_name', robot), *params.items()])

    def log(self, name) -> str:
        return (self.logs / f'{name}.log').read_text()

    def kill(self, name) -> None:
        """SIGKILL, as a crash would: the process gets no chance to say goodbye."""
        os.killpg(self.processes[name].pid, signal.SIGKILL)
        self.processes[name].wait(timeout=5)

    def inject_fault(self, robot, *args, timeout=10):
        """`ros2 run fjsp_planner inject_fault ROBOT ...`, as a user's test script would."""
        return subprocess.run(['ros2', 'run', 'fjsp_planner', 'inject_fault', robot, *args],
                              env=self.env, capture_output=True, text=True, timeout=timeout)

    def stop(self, name=None, timeout=5.0) -> dict[str, int]:
        """SIGINT the process groups, SIGKILL what outlives `timeout`; the exit codes."""
        names = [name] if name else list(self.processes)
        for n in names:
            if self.processes[n].poll() is None:
                os.killpg(self.processes[n].pid, signal.SIGINT)
        deadline = time.monotonic() + timeout
        codes = {}
        for n in names:
            p = self.processes[n]
            try:
                codes[n] = p.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
                codes[n] = 'killed'
        return codes


class Observer:
    """An rclpy node in the test process recording the public topics of one domain."""

    def __init__(self, domain: int):
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = rclpy.create_node('test_observer', context=self.context)
        self.lock = threading.Condition()
        self.plans: list[Plan] = []
        self.events: list[TaskEvent] = []
        self.status: MissionStatus | None = None
        self.robots: dict[str, RobotState] = {}
        self.robot_history: list[RobotState] = []
        self.job_states: JobStates | None = None
        node = self.node
        node.create_subscription(Plan, PLAN_TOPIC, self._add('plans'), LATCHED_QOS)
        node.create_subscription(TaskEvent, TASK_EVENTS_TOPIC, self._add('events'),
                                 EVENTS_QOS)
        node.create_subscription(MissionStatus, MISSION_STATUS_TOPIC,
                                 self._set('status'), LATCHED_QOS)
        node.create_subscription(JobStates, JOB_STATES_TOPIC, self._set('job_states'),
                                 LATCHED_QOS)
        node.create_subscription(RobotState, ROBOT_STATES_TOPIC, self._robot, LATCHED_QOS)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(node)
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _spin(self):
        while self.context.ok():
            try:
                self.executor.spin_once(timeout_sec=0.1)
            except Exception:  # noqa: BLE001  the context went down between checks
                if self.context.ok():
                    raise

    def _add(self, name):
        def callback(msg):
            with self.lock:
                getattr(self, name).append(msg)
                self.lock.notify_all()
        return callback

    def _set(self, name):
        def callback(msg):
            with self.lock:
                setattr(self, name, msg)
                self.lock.notify_all()
        return callback

    def _robot(self, msg):
        with self.lock:
            self.robots[msg.robot] = msg
            self.robot_history.append(msg)
            self.lock.notify_all()

    def wait_for(self, predicate, timeout, what):
        """Wait until predicate(self) holds; fail naming `what` after `timeout` seconds."""
        with self.lock:
            if not self.lock.wait_for(lambda: predicate(self), timeout=timeout):
                pytest.fail(f'timed out after {timeout:g} s waiting for {what}; last mission '
                            f'status: {self.status}')

    def publisher(self, msg_type, topic, qos):
        return self.node.create_publisher(msg_type, topic, qos)

    def complete(self) -> bool:
        return self.status is not None and self.status.state == MissionStatus.STATE_COMPLETE

    def close(self):
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        self.thread.join(timeout=2.0)


def restart_revisions(plans) -> dict[str, int]:
    """Per job, the last plan revision that (re)started it: its reports under older ones are
    void (PlanTask.continued)."""
    since = {}
    for plan in plans:
        for robot in plan.robots:
            for task in robot.tasks:
                if not task.continued:
                    since[task.job] = max(since.get(task.job, 0), plan.revision)
    return since


def valid_events(plans, events) -> list[TaskEvent]:
    """The events of each job's last attempt, the one that counts."""
    since = restart_revisions(plans)
    return [e for e in events if e.plan_revision >= since.get(e.job, 0)]


def executed_timeline(problem, plans, events) -> Schedule:
    """The schedule the robots actually ran, rebuilt from their task events alone (the last
    attempt of each job), with each robot's operation as the plans that ran it gave it."""
    started, operation_done = defaultdict(dict), defaultdict(dict)
    for e in valid_events(plans, events):
        if e.kind == TaskEvent.KIND_STARTED:
            started[e.job][e.robot] = e.time
        elif e.kind == TaskEvent.KIND_OPERATION_DONE:
            operation_done[e.job][e.robot] = e.time
    tasks = {(r.robot, t.job): t for plan in plans for r in plan.robots for t in r.tasks}
    jobs = {}
    for job, robots in started.items():
        if set(operation_done[job]) != set(robots):
            continue
        ops = {robot: tasks[robot, job].operation_type for robot in robots}
        plan = tasks[next(iter(robots)), job].process_plan
        end = max(operation_done[job].values())
        jobs[job] = JobAssignment(job, plan, Fraction(min(robots.values())), Fraction(end), ops)
    sequences = {r.name: tuple(sorted((j for j, a in jobs.items() if r.name in a.robots),
                                      key=lambda j: jobs[j].start))
                 for r in problem.robots}
    return Schedule(jobs, sequences)
