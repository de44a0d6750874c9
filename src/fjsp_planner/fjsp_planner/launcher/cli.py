"""`ros2 run fjsp_planner fleet`: a scenario run on the node network from the command line,
until Ctrl-C or the end of the mission, its outcome as the exit code. It starts again a node
that ended (`launcher.respawn` decides when) and believes only the mission statuses its
planner signed (`launcher.status`)."""

import argparse
import math
import signal
import sys
import time
from pathlib import Path

from fjsp_common.auth import KEY_FILE_VARIABLE, read_key
from fjsp_common.contract import MISSION_STATUS
from fjsp_common.decimals import decimals
from fjsp_common.fleet import PLANNER_NODE
from fjsp_msgs.msg import MissionStatus
from fjsp_planner.launcher.listener import Listener
from fjsp_planner.launcher.respawn import RespawnPolicy, Supervisor
from fjsp_planner.launcher.status import MissionWatch
from fjsp_planner.launcher.supervision import (
    DEFAULT_TIME_SCALE,
    EXIT_BAD_INPUT,
    EXIT_FAILED,
    MONITOR_FINISH,
    MONITOR_NODE,
    MONITOR_PORT_PARAMETER,
    Fleet,
    FleetError,
)
from fjsp_planner.model.scenario import scenario_warnings
from fjsp_planner.workspace import default_out_dir

POLICY = RespawnPolicy()
"""When the nodes of a fleet that ended are started again."""


class _SignalError(Exception):
    """SIGINT or SIGTERM reached the launcher."""

    def __init__(self, signum):
        super().__init__(signal.Signals(signum).name)
        self.code = 128 + signum


def _stop_signal(signum, frame):
    raise _SignalError(signum)


def _positive(kind):
    def parse(text):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f'expected a number > 0, got {text!r}') from None
        if not (math.isfinite(value) and value > 0):
            raise argparse.ArgumentTypeError(f'must be > 0, got {text}')
        return value
    return parse


def _port(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'expected a port number, got {text!r}') from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f'must be within [0, 65535], got {text}')
    return value


def parse_arguments(argv) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog='fleet',
        description='Run a scenario on the node network: the planner, one robot_agent per '
                    'robot of the scenario and the monitor, until Ctrl-C (or the end of the '
                    'mission with --exit-on-complete). Exit 0 when the mission completes.')
    parser.add_argument('scenario', help='scenario file (YAML), or the name of an installed '
                                         'one (e.g. truss)')
    parser.add_argument('--panels', type=_positive(int), metavar='N',
                        help="repeat the scenario's jobs N times (default: the file's)")
    parser.add_argument('--time-scale', type=_positive(float), metavar='S',
                        help="wall seconds per schedule unit (default: the params file's, "
                             f'else {DEFAULT_TIME_SCALE:g})')
    parser.add_argument('--params-file', type=Path, metavar='FILE',
                        help='ROS parameters file passed to every node '
                             '(e.g. config/params/paper_demo.yaml)')
    parser.add_argument('--out', type=Path, metavar='DIR',
                        help=f"where the monitor's outputs and the node logs go (default: "
                             f'{default_out_dir()})')
    parser.add_argument('--exit-on-complete', action='store_true',
                        help='stop the fleet and exit once the mission has ended')
    parser.add_argument('--timeout', type=_positive(float), metavar='S',
                        help='give up (exit 1) if the mission has not ended after S seconds')
    parser.add_argument('--unauthenticated', action='store_true',
                        help='run without a fleet key (by default a fresh one is written to '
                             '<out>/fleet.key and given to every node; docs/security.md)')
    parser.add_argument('--no-recording', action='store_true',
                        help='do not record the mission topics to <out>/fjsp_<time>.mcap')
    parser.add_argument('--no-respawn', action='store_true',
                        help='end the fleet (exit 1) when any node ends, rather than start it '
                             f'again after {POLICY.delay:g} s (given up on after {POLICY.limit} '
                             f'ends within {POLICY.window:g} s)')
    parser.add_argument('--web-port', type=_port, metavar='PORT',
                        help="port of the monitor's live page (default: the params file's, "
                             'else 8080; 0: no page)')
    parser.add_argument('--sim-robots', action='store_true',
                        help='drive every robot through its action servers, served by a '
                             'simulated robot (sim_robot) per robot; its noise and failures '
                             'come from the params file (spread, bias, failure_rate, seed; '
                             'docs/robot-drivers.md)')
    return parser.parse_args(argv)


def _summary(status: MissionStatus | None) -> str:
    if status is None:
        return 'no mission status received'
    state = {v: k[len('STATE_'):].lower() for k, v in vars(MissionStatus).items()
             if k.startswith('STATE_')}.get(status.state, f'state {status.state}')
    return f'{state}, {status.jobs_done}/{status.jobs_total} jobs done'


def run(args: argparse.Namespace) -> int:
    monitor = {}
    if args.exit_on_complete:
        monitor['exit_on_complete'] = True
    if args.web_port is not None:
        monitor[MONITOR_PORT_PARAMETER] = args.web_port
    try:
        fleet = Fleet(args.scenario, panels=args.panels, time_scale=args.time_scale,
                      params_file=args.params_file, out=args.out, monitor=monitor,
                      key=not args.unauthenticated, resumable=True,
                      sim_robots={} if args.sim_robots else None)
    except FleetError as error:
        print(f'fleet: cannot run {args.scenario}:', file=sys.stderr)
        for problem in error.problems:
            print(f'  - {problem}', file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        watch = Listener(name='fleet')
    except RuntimeError as error:  # rclpy's RCLError, e.g. a bad ROS_DOMAIN_ID
        print(f'fleet: could not start ROS: {error}', file=sys.stderr)
        return EXIT_FAILED
    statuses = MissionWatch(read_key(fleet.key_file) if fleet.key_file else None,
                            watch.node.resolve_topic_name(MISSION_STATUS.name))

    def receive(msg):
        if warning := statuses.receive(msg):
            print(f'fleet: {warning}', file=sys.stderr, flush=True)
    watch.subscribe(MISSION_STATUS.type, MISSION_STATUS.name, MISSION_STATUS.qos, receive,
                    statuses.verifier)
    supervisor = Supervisor(None if args.no_respawn else POLICY, essential={PLANNER_NODE},
                            may_finish={MONITOR_NODE} if args.exit_on_complete else ())
    ended: list[int] = []
    """The mission's exit code, once it has ended."""
    previous = {sig: signal.signal(sig, _stop_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        for warning in scenario_warnings(fleet.problem):
            print(f'fleet: warning: {warning}', file=sys.stderr, flush=True)
        fleet.start(stream_monitor=True, recorder=not args.no_recording)
        robots = ', '.join(r.name for r in fleet.problem.robots)
        print(f"fleet: scenario '{fleet.problem.name}' ({fleet.scenario}): planner, agents "
              f'of {robots} and monitor started; node logs in {fleet.logs}', flush=True)
        if fleet.key_file is not None:
            print(f'fleet: authenticated with the key in {fleet.key_file}; tools need it too: '
                  f'export {KEY_FILE_VARIABLE}={fleet.key_file}', flush=True)
        else:
            print('fleet: unauthenticated (--unauthenticated): any node on this ROS domain can '
                  'publish mission statuses this launcher believes, and plans the robots '
                  'follow', flush=True)
        return _watch(fleet, statuses, supervisor, ended, args)
    except _SignalError as stopped:
        if ended:
            return ended[0]
        print(f'fleet: stopped by {stopped} before the mission ended '
              f'({_summary(statuses.latest)})', file=sys.stderr)
        return stopped.code
    finally:
        # Stopping is bounded (SIGKILL after the grace period); a second Ctrl-C must not
        # leave nodes behind by interrupting it.
        for sig in previous:
            signal.signal(sig, signal.SIG_IGN)
        fleet.stop()
        watch.close()
        if tally := statuses.tally():
            print(f'fleet: {tally}', file=sys.stderr)
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _watch(fleet: Fleet, statuses: MissionWatch, supervisor: Supervisor, ended: list,
           args) -> int:
    """Until the outcome is decided: the exit code, its reason printed. Without
    --exit-on-complete only the loss of a node the fleet cannot go on without, or the
    timeout, decides; Ctrl-C ends it."""
    began = time.monotonic()
    ended_at = None
    while True:
        time.sleep(0.1)
        now = time.monotonic()
        status = statuses.latest
        for name, code in fleet.exited().items():
            if not supervisor.watches(name):
                continue
            verdict = supervisor.ended(name, code, now)
            if verdict.finished:
                continue  # the monitor, its summary written; the mission status decides
            print(f'fleet: {verdict.describe(now)} ({_summary(status)}); its log: '
                  f'{fleet.logs / name}.log', file=sys.stderr, flush=True)
            if verdict.ends_fleet:
                return EXIT_FAILED
        for name in supervisor.due(now):
            print(f"fleet: node '{name}' started again (pid {fleet.restart(name).pid})",
                  file=sys.stderr, flush=True)
        if not ended and status is not None:
            code = _ended(status)
            if code is not None:
                ended.append(code)
                ended_at = now
                if not args.exit_on_complete:
                    print('fleet: the fleet stays up; Ctrl-C stops it', flush=True)
        # Once the mission ended, complete or not, the monitor writes its summary and chart,
        # then exits; a monitor that died meanwhile is started again to write them.
        if ended and args.exit_on_complete and (
                supervisor.settled(MONITOR_NODE) or MONITOR_NODE not in fleet.processes
                or now - ended_at > MONITOR_FINISH):
            return ended[0]
        if args.timeout and not ended and now - began > args.timeout:
            print(f'fleet: the mission did not end within {args.timeout:g} s '
                  f'({_summary(status)})', file=sys.stderr)
            return EXIT_FAILED


def _ended(status: MissionStatus) -> int | None:
    """The exit code a mission that has ended with `status` gives (reason printed), or None
    while it goes on."""
    mission = status.mission_id or status.scenario_id
    if status.state == MissionStatus.STATE_COMPLETE:
        print(f"fleet: mission '{mission}' complete: {status.jobs_done}/{status.jobs_total} "
              'jobs done, makespan {} (planned {}) schedule units'.format(
                  *decimals(status.projected_makespan, status.planned_makespan)), flush=True)
        return 0
    if status.state in (MissionStatus.STATE_FAILED, MissionStatus.STATE_CANCELLED):
        word = 'failed' if status.state == MissionStatus.STATE_FAILED else 'was cancelled'
        reasons = '; '.join(status.blocked_reasons) or 'no reason given'
        print(f"fleet: mission '{mission}' {word}: {reasons}", file=sys.stderr)
        return EXIT_FAILED
    return None


def main(argv=None) -> int:
    return run(parse_arguments(sys.argv[1:] if argv is None else argv))


if __name__ == '__main__':
    sys.exit(main())
