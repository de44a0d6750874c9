"""Benchmark of watching a mission (prints, never asserts): the monitor's and the recorder's
CPU and memory during a mission, and the live page's update latency.

Starts the planner, the paper's four robots, the monitor (with its web page) and the recorder
in a private domain, opens the page in headless Chromium, fails MARC1 at a third of the plan
and recovers it a while later, and measures:

- CPU (mean over the mission, from /proc) and resident memory (peak and at the end) of the
  monitor and the recorder processes;
- the page's latency: for each line of the story, from the publication of the fact it tells
  (the message's stamp) to the moment the page first showed it; and for each change of a
  robot's mode or job, from the stamp of the robot state that changed it to the moment the
  robots table showed it (the page notes Date.now() for both; browser and nodes share this
  host's clock);
- the recording's size and message count.

`--screenshots DIR` also saves the page mid-mission (after the re-plan) and at the end.
The machine is shared: figures measured while others work are noisy.

Run from the repository with the workspace sourced:
    source ros2_ws/env.sh && nice -n 10 python bench/observe.py [--panels 5] [--time-scale 0.05]
"""

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / 'test' / 'integration'))

from fjsp_common.contract import (  # noqa: E402
    LATCHED_READER_QOS,
    MODE_FROM_MSG,
    ROBOT_STATES_TOPIC,
)
from fjsp_msgs.msg import MissionStatus, RobotState  # noqa: E402
from fjsp_planner.testing import FleetHarness  # noqa: E402

from browser import (  # noqa: E402
    find_chromium,
    free_port,
    headless_browser,
    wait_listening,
)

SCENARIO = REPO / 'config' / 'scenarios' / 'solar_panel.yaml'

TICKS = os.sysconf('SC_CLK_TCK')
PAGE = os.sysconf('SC_PAGE_SIZE')


def cpu_seconds(pid: int) -> float:
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def memory_mb(pid: int) -> tuple[float, float]:
    """(resident now, peak resident) in MB."""
    status = dict(line.split(':', 1) for line in
                  Path(f'/proc/{pid}/status').read_text().splitlines() if ':' in line)
    return (int(status['VmRSS'].split()[0]) / 1024, int(status['VmHWM'].split()[0]) / 1024)


def record_robot_states(observer) -> list:
    """Every robot state, as the monitor reads them (the harness's observer keeps only the
    latest of each writer, and would miss short-lived states)."""
    states = []
    observer.node.create_subscription(RobotState, ROBOT_STATES_TOPIC, states.append,
                                      LATCHED_READER_QOS)
    return states


def robot_changes_shown(history, shown) -> list[tuple[float, str]]:
    """Seconds from each robot state that changed a robot's mode or job to the page showing
    the change (changes the page never showed, being shorter than an update, are left out)."""
    changes = {}
    last = {}
    for state in history:
        key = (str(MODE_FROM_MSG.get(state.mode)), state.current_job)
        if last.get(state.robot) != key:
            last[state.robot] = key
            stamp = state.stamp.sec + state.stamp.nanosec * 1e-9
            changes.setdefault((state.robot, *key), []).append(stamp)
    latencies = []
    for robot, mode, job, at in shown:
        stamps = [s for s in changes.get((robot, mode, job), []) if s <= at / 1000]
        if stamps:
            latencies.append((at / 1000 - max(stamps), f'{robot} {mode} {job}'.strip()))
    return latencies


def percentile(values, share):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(share * len(ordered)))]


def run(args, out: Path) -> None:
    port = free_port()
    fleet = FleetHarness(SCENARIO, out=out, time_scale=args.time_scale, panels=args.panels,
                         planner={'time_limit': args.time_limit,
                                  'replan_time_limit': args.replan_time_limit})
    observer = fleet.observer
    robot_states = record_robot_states(observer)
    page = None
    browser = None
    try:
        recorder = fleet.start_node('recorder', 'fjsp_planner', 'recorder',
                                    {'out_dir': out, 'file_name': 'bench.mcap'})
        monitor = fleet.start_monitor(out_dir=out, web_port=port)
        if find_chromium() is not None:
            if not wait_listening(port, 30):
                raise TimeoutError(f'nothing serves port {port}')
            browser = headless_browser()
            page = browser.__enter__()
            page.get(f'http://127.0.0.1:{port}/')
        else:
            print('Chromium not found: no latency figures (apt-get install chromium '
                  'chromium-driver)')
        # The page is open before the mission starts, so it sees all of it.
        fleet.start_planner()
        for robot in fleet.problem.robots:
            fleet.start_agent(robot.name)
        observer.wait_for(lambda o: o.plans and o.status.state == MissionStatus.STATE_EXECUTING,
                          args.timeout, 'the first plan')
        planned = observer.plans[0].makespan
        samples = {'monitor': monitor.pid, 'recorder': recorder.pid}
        start_cpu = {name: cpu_seconds(pid) for name, pid in samples.items()}
        started = time.monotonic()
        peaks = {name: 0.0 for name in samples}
        fault_at, recover_at = planned / 3, planned / 3 + planned / 8
        phase = 'fail'
        shot_mid = False
        while not observer.complete():
            if time.monotonic() - started > args.timeout:
                raise TimeoutError(f'the mission did not complete in {args.timeout:g} s')
            for name, pid in samples.items():
                peaks[name] = max(peaks[name], memory_mb(pid)[1])
            elapsed = observer.status.elapsed
            if phase == 'fail' and elapsed >= fault_at:
                fleet.inject_fault('MARC1', 'fail')
                phase = 'recover'
            elif phase == 'recover' and elapsed >= recover_at:
                fleet.inject_fault('MARC1', 'recover')
                phase = 'done'
            if page is not None and args.screenshots and not shot_mid and phase != 'fail' \
                    and max(p.revision for p in observer.plans) >= 2:
                time.sleep(1.5)
                args.screenshots.mkdir(parents=True, exist_ok=True)
                page.save_screenshot(str(args.screenshots / 'dashboard-mid-mission.png'))
                shot_mid = True
            time.sleep(0.5)
        wall = time.monotonic() - started
        cpu = {name: cpu_seconds(pid) - start_cpu[name] for name, pid in samples.items()}
        memory = {name: memory_mb(pid) for name, pid in samples.items()}
        time.sleep(3.0)  # the page shows the end; the monitor draws it
        latencies, robot_latencies = [], []
        if page is not None:
            robot_latencies = robot_changes_shown(
                list(robot_states), page.execute_script('return window.fjspRobotsShown'))
            shown = page.execute_script('return window.fjspShown')
            story = page.execute_script('return window.fjspData.story') or []
            for item in story:
                # An offline line is inferred from messages that did not come: no stamp to
                # measure from.
                if item['key'] in shown and item['stamp'] is not None \
                        and item['kind'] != 'robot offline':
                    latencies.append((shown[item['key']] / 1000 - item['stamp'],
                                      item['kind'], item['text']))
            if args.screenshots:
                page.save_screenshot(str(args.screenshots / 'dashboard-end.png'))
        fleet.stop('recorder')
        status = observer.status
        print(f'{args.panels}-panel mission at {args.time_scale:g} s/unit: '
              f'{status.jobs_done}/{status.jobs_total} jobs, makespan planned {planned:.1f} '
              f'(revision 1), executed {status.projected_makespan:.1f}, '
              f'{status.plan_revision} revisions, {wall:.1f} s of wall time')
        print(f"{'process':<10} {'CPU % (mean)':>13} {'CPU s':>7} {'RSS MB peak':>12} "
              f"{'RSS MB end':>11}")
        for name in samples:
            print(f'{name:<10} {100 * cpu[name] / wall:>13.1f} {cpu[name]:>7.2f} '
                  f'{max(peaks[name], memory[name][1]):>12.1f} {memory[name][0]:>11.1f}')
        recording = out / 'bench.mcap'
        if recording.is_file():
            print(f'recording: {recording.stat().st_size / 1024:.0f} KiB; '
                  + fleet.log('recorder').strip().splitlines()[-1].split(']: ', 1)[-1])
        if latencies:
            values = [lat for lat, _, _ in latencies]
            print(f'page latency, fact published -> line shown ({len(values)} lines): '
                  f'p50 {1000 * statistics.median(values):.0f} ms, '
                  f'p95 {1000 * percentile(values, 0.95):.0f} ms, '
                  f'max {1000 * max(values):.0f} ms')
            for lat, kind, text in sorted(latencies, key=lambda x: -x[0])[:args.show]:
                print(f'  {1000 * lat:7.0f} ms  {kind}: {text}')
        if robot_latencies:
            values = [lat for lat, _ in robot_latencies]
            print(f'page latency, robot state published -> robots table shows it '
                  f'({len(values)} changes): p50 {1000 * statistics.median(values):.0f} ms, '
                  f'p95 {1000 * percentile(values, 0.95):.0f} ms, '
                  f'max {1000 * max(values):.0f} ms')
            for lat, change in sorted(robot_latencies, reverse=True)[:args.show]:
                print(f'  {1000 * lat:7.0f} ms  {change}')
    finally:
        if browser is not None:
            browser.__exit__(None, None, None)
        fleet.close()


def main(argv) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--panels', type=int, default=5)
    parser.add_argument('--time-scale', type=float, default=0.05,
                        help='wall seconds per schedule unit (default 0.05)')
    parser.add_argument('--time-limit', type=float, default=10.0,
                        help='first solve, seconds (default 10)')
    parser.add_argument('--replan-time-limit', type=float, default=2.5,
                        help='re-plans, seconds (default 2.5, as the re-plan benches)')
    parser.add_argument('--timeout', type=float, default=300.0)
    parser.add_argument('--screenshots', type=Path, default=None,
                        help='save the page mid-mission and at the end into this directory')
    parser.add_argument('--show', type=int, default=5, help='slowest lines to list')
    parser.add_argument('--out', type=Path, default=None,
                        help='keep the recording and the charts in this directory')
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix='fjsp-bench-observe-') as scratch:
        run(args, args.out or Path(scratch) / 'out')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
