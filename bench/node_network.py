"""Benchmark of the node network on the paper's one-panel mission (prints, never asserts).

For each time scale: planner + four agents started by the fleet launcher
(`fjsp_planner.launcher.supervision.Fleet`) in a private domain; plan publish -> every agent
follows it (latency, from message stamps); per-node CPU and resident memory during the mission
and at idle afterwards (from /proc); executed vs planned makespan in schedule units and the
wall-clock overhead of the mission.

Run from the repository with the workspace sourced:
    source ros2_ws/env.sh && python bench/node_network.py [--time-scales 0.02 0.1]
"""

import argparse
import os
import sys
import tempfile
import time
from contextlib import closing
from pathlib import Path

from rclpy.time import Time

from fjsp_common.contract import (
    EVENTS_QOS,
    LATCHED_QOS,
    LATCHED_READER_QOS,
    MISSION_STATUS_TOPIC,
    PLAN_TOPIC,
    ROBOT_STATES_TOPIC,
    TASK_EVENTS_TOPIC,
)
from fjsp_msgs.msg import MissionStatus, Plan, RobotState, TaskEvent
from fjsp_planner.launcher.listener import Listener
from fjsp_planner.launcher.supervision import Fleet
from fjsp_planner.testing import DomainClaim

LOCALHOST = {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST'}
TICKS = os.sysconf('SC_CLK_TCK')
PAGE = os.sysconf('SC_PAGE_SIZE')


def cpu_seconds(pid) -> float:
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def rss_mb(pid) -> float:
    return int(Path(f'/proc/{pid}/statm').read_text().split()[1]) * PAGE / 1e6


def fleet(domain, logs, time_scale=None, panels=None, **planner) -> Fleet:
    """The paper's fleet (planner and four generic agents, no monitor) in `domain`."""
    return Fleet(domain=domain, out=logs, env=LOCALHOST, time_scale=time_scale,
                 panels=panels, planner=planner)


class Recorder(Listener):
    def __init__(self, domain):
        super().__init__(domain, name='bench_recorder', discovery_range='LOCALHOST')
        self.plan = None
        self.status = None
        self.followed = {}
        self.heard = set()
        self.last_job_done = None
        self.subscribe(Plan, PLAN_TOPIC, LATCHED_QOS, self.on_plan)
        self.subscribe(MissionStatus, MISSION_STATUS_TOPIC, LATCHED_QOS, self.on_status)
        self.subscribe(RobotState, ROBOT_STATES_TOPIC, LATCHED_READER_QOS, self.on_robot)
        self.subscribe(TaskEvent, TASK_EVENTS_TOPIC, EVENTS_QOS, self.on_event)

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


def run(time_scale, domain, logs):
    with fleet(domain, logs, time_scale) as nodes, closing(Recorder(domain)) as recorder:
        processes = nodes.processes
        robots = [r.name for r in nodes.problem.robots]
        # The recorder must hear each agent before the plan exists: a late-matched recorder
        # would only get the latest (heartbeat) state, not the transition it measures.
        for robot in robots:
            nodes.start_agent(robot)
        recorder.wait(lambda: len(recorder.heard) == len(robots), 30)
        nodes.start_planner()
        recorder.wait(lambda: recorder.plan is not None, 60)
        recorder.wait(lambda: len(recorder.followed) == len(robots), 30)
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
        print(f'\n== time_scale {time_scale} s/unit ({len(robots)} agents, planner) ==')
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
    parser.add_argument('--domain', type=int, default=None,
                        help='ROS domain id (default: one no test or bench on this machine '
                             'holds)')
    args = parser.parse_args(argv)
    claim = DomainClaim() if args.domain is None else None
    try:
        with tempfile.TemporaryDirectory(prefix='fjsp_bench_') as logs:
            for scale in args.time_scales:
                run(scale, args.domain if claim is None else claim.domain, Path(logs))
    finally:
        if claim is not None:
            claim.release()
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
