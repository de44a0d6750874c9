"""Benchmark of the node network on the paper's one-panel mission (prints, never asserts).

For each time scale: planner + four agents started with `ros2 run` in a private domain;
plan publish -> every agent follows it (latency, from message stamps); per-node CPU and
resident memory during the mission and at idle afterwards (from /proc); executed vs planned
makespan in schedule units and the wall-clock overhead of the mission.

Run from the repository with the workspace sourced:
    source ros2_ws/env.sh && python bench/node_network.py [--time-scales 0.02 0.1]
"""

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from contextlib import closing
from pathlib import Path

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.time import Time

from fjsp_common.contract import (
    EVENTS_QOS,
    LATCHED_QOS,
    MISSION_STATUS_TOPIC,
    PLAN_TOPIC,
    ROBOT_STATES_TOPIC,
    TASK_EVENTS_TOPIC,
)
from fjsp_msgs.msg import MissionStatus, Plan, RobotState, TaskEvent

ROBOTS = (('Assembler', 'assembler_agent'), ('LSMS', 'lsms_agent'),
          ('MARC1', 'marc_agent'), ('MARC2', 'marc_agent'))
TICKS = os.sysconf('SC_CLK_TCK')
PAGE = os.sysconf('SC_PAGE_SIZE')


def cpu_seconds(pid) -> float:
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def rss_mb(pid) -> float:
    return int(Path(f'/proc/{pid}/statm').read_text().split()[1]) * PAGE / 1e6


class Recorder:
    def __init__(self, domain):
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = rclpy.create_node('bench_recorder', context=self.context)
        self.plan = None
        self.status = None
        self.followed = {}
        self.heard = set()
        self.last_job_done = None
        self.node.create_subscription(Plan, PLAN_TOPIC, self.on_plan, LATCHED_QOS)
        self.node.create_subscription(MissionStatus, MISSION_STATUS_TOPIC, self.on_status,
                                      LATCHED_QOS)
        self.node.create_subscription(RobotState, ROBOT_STATES_TOPIC, self.on_robot,
                                      LATCHED_QOS)
        self.node.create_subscription(TaskEvent, TASK_EVENTS_TOPIC, self.on_event, EVENTS_QOS)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self.spin, daemon=True)
        self.thread.start()

    def spin(self):
        while self.context.ok():
            try:
                self.executor.spin_once(timeout_sec=0.1)
            except Exception:  # noqa: BLE001  the context went down between checks
                if self.context.ok():
                    raise

    def on_plan(self, msg):
        self.plan = msg

    def on_status(self, msg):
        self.status = msg

    def on_robot(self, msg):
        self.heard.add(msg.robot)
        if msg.plan_revision >= 1 and msg.robot not in self.followed:
            self.followed[msg.robot] = Time.from_msg(msg.stamp)

    def on_event(self, msg):
        if msg.kind == TaskEvent.KIND_JOB_DONE:
            self.last_job_done = time.time()

    def wait(self, predicate, timeout):
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline:
                raise TimeoutError
            time.sleep(0.02)

    def close(self):
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


class Nodes:
    """Nodes started with `ros2 run` in one domain, each logging to `logs/<name>.log`;
    interrupted (then killed if need be) on leaving the `with` block."""

    def __init__(self, domain, logs):
        self.env = dict(os.environ, ROS_DOMAIN_ID=str(domain),
                        ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
        self.logs = logs
        self.processes = {}

    def start(self, name, package, executable, *params):
        command = ['ros2', 'run', package, executable, '--ros-args', '-r', f'__node:={name}']
        for key, value in params:
            command += ['-p', f'{key}:={value}']
        with (self.logs / f'{name}.log').open('w') as log:
            self.processes[name] = subprocess.Popen(
                command, env=self.env, stdout=log, stderr=subprocess.STDOUT,
                start_new_session=True)

    def start_agents(self):
        for robot, executable in ROBOTS:
            self.start(f'{robot.lower()}_agent', 'robot_agents', executable,
                       ('robot_name', robot))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for p in self.processes.values():
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGINT)
        for p in self.processes.values():
            try:
                p.wait(timeout=5)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()


def run(time_scale, domain, logs):
    with Nodes(domain, logs) as nodes, closing(Recorder(domain)) as recorder:
        processes = nodes.processes
        # The recorder must hear each agent before the plan exists: a late-matched recorder
        # would only get the latest (heartbeat) state, not the transition it measures.
        nodes.start_agents()
        recorder.wait(lambda: len(recorder.heard) == len(ROBOTS), 30)
        nodes.start('planner', 'fjsp_planner', 'planner_node', ('time_scale', time_scale))
        recorder.wait(lambda: recorder.plan is not None, 60)
        recorder.wait(lambda: len(recorder.followed) == len(ROBOTS), 30)
        published = Time.from_msg(recorder.plan.stamp)
        latency = {r: (t - published).nanoseconds / 1e6 for r, t in recorder.followed.items()}
        mission_start = Time.from_msg(recorder.plan.mission_start).nanoseconds / 1e9
        recorder.wait(lambda: time.time() >= mission_start, 10)
        before = {n: cpu_seconds(p.pid) for n, p in processes.items()}
        began = time.monotonic()
        recorder.wait(lambda: recorder.status is not None
                      and recorder.status.state == MissionStatus.STATE_COMPLETE, 120)
        busy = time.monotonic() - began
        during = {n: (cpu_seconds(p.pid) - before[n]) / busy for n, p in processes.items()}
        rss_during = {n: rss_mb(p.pid) for n, p in processes.items()}
        idle_window = 3.0
        before = {n: cpu_seconds(p.pid) for n, p in processes.items()}
        time.sleep(idle_window)
        idle = {n: (cpu_seconds(p.pid) - before[n]) / idle_window for n, p in processes.items()}
        planned = recorder.plan.makespan
        executed = recorder.status.projected_makespan
        wall = recorder.last_job_done - mission_start
        print(f'\n== time_scale {time_scale} s/unit ({len(ROBOTS)} agents, planner) ==')
        print('plan publish -> agent follows it (ms): '
              + ', '.join(f'{r} {ms:.1f}' for r, ms in sorted(latency.items()))
              + f'; all agents: {max(latency.values()):.1f}')
        print(f'{"node":<16}{"CPU mission":>12}{"CPU idle":>10}{"RSS MB":>9}')
        for n in processes:
            print(f'{n:<16}{during[n]:>11.1%}{idle[n]:>10.1%}{rss_during[n]:>9.1f}')
        print(f'makespan planned {planned:.2f}, executed {executed:.4f} schedule units '
              f'(overhead {(executed - planned) / planned:+.4%})')
        print(f'wall clock: mission start -> last job done {wall:.3f} s vs planned '
              f'{planned * time_scale:.3f} s (overhead {wall - planned * time_scale:+.3f} s, '
              f'{(wall / (planned * time_scale) - 1):+.1%})')


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--time-scales', type=float, nargs='+', default=[0.02, 0.1])
    parser.add_argument('--domain', type=int, default=90)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix='fjsp_bench_') as logs:
        for i, scale in enumerate(args.time_scales):
            run(scale, args.domain + i, Path(logs))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
