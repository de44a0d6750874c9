"""Re-plan latency over the node network: fault injected -> every agent follows the new plan.

For each panel count: planner + four agents started by the fleet launcher in a private domain,
missions run one after another; during each, a robot is failed, or the failed one recovered,
at random moments (seeded) through its `inject_fault` service. Latency is measured from
sending the request to the last agent (all four, the failed one included) reporting the new
plan revision, as this recorder receives it; so it includes detection, the re-plan and both
message hops. Also printed: the revisions' solver status and makespan.

Quality against a 60 s cold solve of the same residual problem is measured by
bench/replan_core.py, which poses the same residual problems in-process.

Prints figures and never asserts. Run with the workspace sourced:
    source ros2_ws/env.sh && python bench/replan_network.py [--panels 1 2 5] [--faults 20]
"""

import argparse
import random
import statistics
import sys
import tempfile
import time
from contextlib import closing
from pathlib import Path

from node_network import Recorder, fleet

from fjsp_common.contract import INJECT_FAULT_SERVICE
from fjsp_msgs.msg import MissionStatus
from fjsp_msgs.srv import InjectFault
from fjsp_planner.testing import DomainClaim

TIME_SCALE = {1: 0.25, 2: 0.1, 5: 0.05}
"""Wall seconds per schedule unit, so that each mission lasts some 8 to 16 s."""
REPLAN_LIMIT = {1: 1.0, 2: 2.0, 5: 2.5}
"""The planner's replan_time_limit, seconds."""
PLAN_LIMIT = {1: 5.0, 2: 10.0, 5: 15.0}


class FaultRecorder(Recorder):
    """Also keeps when each robot was first heard following each revision, and the plans."""

    def __init__(self, domain, robots):
        self.following = {}
        self.plans = {}
        super().__init__(domain)
        self.clients = {robot: self.node.create_client(InjectFault,
                                                       f'{robot}/{INJECT_FAULT_SERVICE}')
                        for robot in robots}

    def on_plan(self, msg):
        self.plans[msg.revision] = msg
        super().on_plan(msg)

    def on_robot(self, msg):
        super().on_robot(msg)
        self.following.setdefault((msg.robot, msg.plan_revision), time.monotonic())

    def inject(self, robot, fault) -> tuple[float, bool, str]:
        """Send the request; returns when it was sent and the agent's answer.

        Clients made once up front, not `faults.inject_fault`, which makes a node and a
        client per call: their discovery (5-90 ms) would count in every latency."""
        sent = time.monotonic()
        future = self.clients[robot].call_async(InjectFault.Request(fault=fault))
        self.wait(future.done, 10)
        answer = future.result()
        return sent, answer.success, answer.message


def run_mission(panels, args, domain, logs, rng, rows):
    nodes = fleet(domain, logs, TIME_SCALE[panels], panels=panels,
                  time_limit=PLAN_LIMIT[panels],
                  replan_time_limit=args.replan_limit or REPLAN_LIMIT[panels],
                  workers=args.workers)
    robots = [r.name for r in nodes.problem.robots]
    with nodes, closing(FaultRecorder(domain, robots)) as recorder:
        for robot in robots:
            nodes.start_agent(robot)
        recorder.wait(lambda: len(recorder.heard) == len(robots), 30)
        nodes.start_planner()
        for client in recorder.clients.values():
            if not client.wait_for_service(timeout_sec=30):
                raise TimeoutError('an agent does not serve inject_fault')
        recorder.wait(lambda: recorder.plan is not None, 60)
        failed = None
        while len(rows) < args.faults:
            time.sleep(rng.uniform(0.3, 2.0))
            status = recorder.status
            if status.state == MissionStatus.STATE_COMPLETE \
                    or status.jobs_done + 3 > status.jobs_total:
                break
            if status.state != MissionStatus.STATE_EXECUTING:
                continue
            if failed is None:
                robot, fault, kind = rng.choice(robots), InjectFault.Request.FAULT_FAIL, 'fail'
            else:
                robot, fault, kind = failed, InjectFault.Request.FAULT_RECOVER, 'recover'
            before = max(recorder.plans)
            sent, success, message = recorder.inject(robot, fault)
            if not success:
                print(f'  refused: {message}')
                continue
            failed = robot if kind == 'fail' else None
            try:
                recorder.wait(lambda before=before: max(recorder.plans) > before and all(
                    (r, max(recorder.plans)) in recorder.following for r in robots), 30)
            except TimeoutError:
                rows.append((kind, robot, None, None))
                print(f'  {kind} {robot}: no new revision followed by every agent in 30 s')
                continue
            revision = max(recorder.plans)
            latency = max(recorder.following[r, revision] for r in robots) - sent
            plan = recorder.plans[revision]
            rows.append((kind, robot, latency, plan))
            print(f'  {kind:<8}{robot:<10} revision {revision:>2}: {latency * 1000:7.0f} ms, '
                  f'makespan {plan.makespan:8.2f} ({plan.solver_status})')


def percentile(values, q):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--panels', type=int, nargs='+', default=[1, 2, 5])
    parser.add_argument('--faults', type=int, default=20, help='faults per panel count')
    parser.add_argument('--replan-limit', type=float, default=None,
                        help='planner replan_time_limit (default: by panel count)')
    parser.add_argument('--workers', type=int, default=2)
    parser.add_argument('--domain', type=int, default=None,
                        help='ROS domain id (default: one no test or bench on this machine '
                             'holds)')
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args(argv)
    claim = DomainClaim() if args.domain is None else None
    if claim is not None:
        args.domain = claim.domain
    rng = random.Random(args.seed)
    summary = []
    with tempfile.TemporaryDirectory() as logs:
        for panels in args.panels:
            print(f'\n== {panels} panel(s): time scale {TIME_SCALE[panels]} s/unit, re-plan '
                  f'limit {args.replan_limit or REPLAN_LIMIT[panels]} s ==')
            rows, missions = [], 0
            while len(rows) < args.faults:
                missions += 1
                run_mission(panels, args, args.domain, Path(logs), rng, rows)
            latencies = [r[2] for r in rows if r[2] is not None]
            summary.append((panels, missions, len(rows), latencies,
                            sum(r[2] is None for r in rows)))
    print(f'\n{"panels":>6}{"missions":>9}{"faults":>7}{"p50 s":>8}{"p95 s":>8}{"max s":>8}'
          f'{"lost":>6}')
    for panels, missions, faults, latencies, lost in summary:
        print(f'{panels:>6}{missions:>9}{faults:>7}{statistics.median(latencies):>8.3f}'
              f'{percentile(latencies, 0.95):>8.3f}{max(latencies):>8.3f}{lost:>6}')
    print('\nlatency: request sent -> the last of the four agents heard following the new '
          'revision (fail and recover faults alike)')


if __name__ == '__main__':
    main(sys.argv[1:])
