"""Run one mission: planner, the paper's four robots and the monitor, via `ros2 run`.

`launch` is not on PyPI, so this small launcher stands in for a launch file: it starts each
node in its own process group, waits for the monitor to report the mission complete, and
stops every process it started, whatever happens. Node logs go to ros2_ws/log/demo/.
"""

import argparse
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

WS = Path(__file__).resolve().parent
REPO = WS.parent
ROBOTS = (('Assembler', 'assembler_agent'), ('LSMS', 'lsms_agent'),
          ('MARC1', 'marc_agent'), ('MARC2', 'marc_agent'))


def positive(text):
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f'must be > 0, got {text}')
    return value


def parse(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--time-scale', type=positive, default=0.2,
                        help='wall seconds per schedule unit (default 0.2)')
    parser.add_argument('--scenario', default='',
                        help='scenario file (default: the installed one-panel solar panel)')
    parser.add_argument('--timeout', type=positive, default=60.0,
                        help='give up after this many seconds (default 60)')
    parser.add_argument('--out', type=Path, default=REPO / 'out' / 'demo',
                        help='where the Gantt chart goes (default out/demo)')
    return parser.parse_args(argv)


def stop(processes):
    """SIGINT each process group, then SIGKILL what is still alive after 5 s."""
    for p in processes:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGINT)
    deadline = time.monotonic() + 5
    for p in processes:
        try:
            p.wait(timeout=max(0.1, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()


def main(argv):
    args = parse(argv)
    logs = WS / 'log' / 'demo'
    logs.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ)
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    env['PYTHONUNBUFFERED'] = '1'
    processes, files = [], []

    def start(name, package, executable, *params, log=True):
        command = ['ros2', 'run', package, executable, '--ros-args', '-r', f'__node:={name}']
        for key, value in params:
            command += ['-p', f'{key}:={value}']
        out = (logs / f'{name}.log').open('w') if log else None
        files.extend([out] if out else [])
        processes.append(subprocess.Popen(command, env=env, stdout=out,
                                          stderr=subprocess.STDOUT if log else None,
                                          start_new_session=True))
        return processes[-1]

    # A SIGTERM (e.g. from CI) must still stop every node, like Ctrl-C does.
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    try:
        planner_params = [('time_scale', args.time_scale)]
        if args.scenario:
            planner_params.append(('scenario', Path(args.scenario).resolve()))
        start('planner', 'fjsp_planner', 'planner_node', *planner_params)
        for robot, executable in ROBOTS:
            start(f'{robot.lower()}_agent', 'robot_agents', executable,
                  ('robot_name', robot))
        print(f'demo: planner and agents started (logs in {logs}); monitor output follows',
              flush=True)
        monitor = start('monitor', 'fjsp_planner', 'monitor_node',
                        ('out_dir', args.out.resolve()), ('exit_on_complete', 'true'),
                        log=False)
        try:
            code = monitor.wait(timeout=args.timeout)
        except subprocess.TimeoutExpired:
            print(f'demo: the mission did not complete within {args.timeout:g} s; '
                  f'see the logs in {logs}', file=sys.stderr)
            return 1
        if code != 0:
            print(f'demo: the monitor exited with code {code}; see the logs in {logs}',
                  file=sys.stderr)
            return 1
        charts = sorted(args.out.glob('*.png'), key=lambda p: p.stat().st_mtime)
        if charts:
            print(f'demo: Gantt chart of planned vs executed timelines: {charts[-1]}')
        return 0
    except KeyboardInterrupt:
        return 130
    finally:
        stop(processes)
        for f in files:
            f.close()


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
