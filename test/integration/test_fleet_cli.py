"""`ros2 run fjsp_planner fleet`: a complete mission exits 0, a bad scenario starts nothing,
no node outlives the launcher, whether it is interrupted or killed, and a node interrupted
while it starts ends without a traceback."""

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

from fjsp_msgs.msg import MissionStatus
from fjsp_planner.testing import Observer

from repo_paths import PAPER

NODES = 6
"""The planner, the paper's four robots and the monitor."""


def launcher(out: Path, *args, domain: int) -> subprocess.Popen:
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               PYTHONUNBUFFERED='1')
    return subprocess.Popen(['ros2', 'run', 'fjsp_planner', 'fleet', *args, '--out', str(out)],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def identity(pid: int) -> tuple[int, str] | None:
    """(pid, start time) of a live process, None if it is gone or a zombie."""
    try:
        fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    except OSError:
        return None
    return None if fields[0] in 'ZX' else (pid, fields[19])


def children(pid: int) -> set[tuple[int, str]]:
    found = set()
    for entry in Path('/proc').iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / 'stat').read_text().rsplit(')', 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid and fields[0] not in 'ZX':
                found.add((int(entry.name), fields[19]))
    return found


def wait_for_nodes(process: subprocess.Popen, timeout: float = 30.0) -> set:
    deadline = time.monotonic() + timeout
    while len(nodes := children(process.pid)) < NODES:
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, f'only {len(nodes)} nodes after {timeout:g} s'
        time.sleep(0.1)
    return nodes


def still_running(nodes, timeout: float) -> set:
    """The nodes still alive after waiting up to `timeout` seconds for them to go."""
    deadline = time.monotonic() + timeout
    while (alive := {n for n in nodes if identity(n[0]) == n}) and time.monotonic() < deadline:
        time.sleep(0.1)
    return alive


def test_a_complete_mission_exits_0(tmp_path, ros_domain):
    process = launcher(tmp_path, str(PAPER), '--exit-on-complete', '--time-scale', '0.03',
                       '--timeout', '120', domain=ros_domain)
    nodes = wait_for_nodes(process)
    out, err = process.communicate(timeout=180)
    assert process.returncode == 0, out + err
    assert "mission 'solar_panel-" in out and 'complete: 12/12 jobs done' in out
    assert '[monitor]' in out  # the monitor's view is streamed
    assert 'Traceback' not in out + err
    assert len(list(tmp_path.glob('solar_panel-*.png'))) == 1
    assert len(list(tmp_path.glob('fjsp_*.mcap'))) == 1  # the flight recording
    assert (tmp_path / 'fleet.key').is_file() and 'authenticated with the key' in out
    assert sorted(p.name for p in (tmp_path / 'logs').iterdir()) == [
        'agent_Assembler.log', 'agent_LSMS.log', 'agent_MARC1.log', 'agent_MARC2.log',
        'monitor.log', 'planner.log', 'recorder.log']
    assert not still_running(nodes, 1.0)


@pytest.mark.parametrize('how', [signal.SIGINT, signal.SIGKILL], ids=lambda s: s.name)
def test_no_node_outlives_the_launcher(tmp_path, how, ros_domain):
    domain = ros_domain
    observer = Observer(domain)
    try:
        process = launcher(tmp_path, str(PAPER), '--time-scale', '0.1', domain=domain)
        nodes = wait_for_nodes(process)
        observer.wait_for(lambda o: o.status is not None and o.status.jobs_done >= 1
                          and o.status.state == MissionStatus.STATE_EXECUTING, 60,
                          'the mission to be under way')
        process.send_signal(how)
        out, err = process.communicate(timeout=30)
    finally:
        observer.close()
    if how == signal.SIGINT:
        assert process.returncode == 130, out + err
        assert 'stopped by SIGINT before the mission ended' in err
        assert 'Traceback' not in out + err
    else:
        assert process.returncode == -signal.SIGKILL
    # SIGINT: the launcher stops each node; SIGKILL: the kernel does (parent-death signal).
    assert not still_running(nodes, 10.0)


def test_a_bad_scenario_starts_nothing(tmp_path, ros_domain):
    scenario = tmp_path / 'bad.yaml'
    scenario.write_text("""
operation_types: {0: weld, 1: locomote}
robot_types: {Bot: {weld: 1, locomote: 1}}
robots:
  - {name: R1, type: Bot}
  - {name: R2, type: Nope}
jobs:
  - {name: A, location: a, plans: [[weld]]}
  - {name: B, location: b, plans: [[weld]]}
""")
    process = launcher(tmp_path / 'out', str(scenario), '--exit-on-complete', domain=ros_domain)
    out, err = process.communicate(timeout=60)
    assert process.returncode == 2, out + err
    assert "robot 'R2': unknown robot type 'Nope'" in err
    assert 'no distances are given, but robots travel' in err
    assert not (tmp_path / 'out').exists()

    # Robot names become node and service names: one that cannot is refused before anything.
    scenario.write_text(scenario.read_text().replace('type: Nope', 'type: Bot')
                        .replace('name: R1', 'name: R-1') + 'distances: {pairs: [[a, b, 1]]}\n')
    process = launcher(tmp_path / 'out', str(scenario), '--exit-on-complete', domain=ros_domain)
    out, err = process.communicate(timeout=60)
    assert process.returncode == 2, out + err
    assert "robot 'R-1': its name must be usable in ROS names" in err
    assert not (tmp_path / 'out').exists()


def test_a_node_stopped_while_starting_ends_without_a_traceback(fjsp_fleet):
    fleet = fjsp_fleet()
    fleet.start_agent('MARC1')
    # At once: the agent is still importing its modules. It ignores SIGINT until it can
    # stop cleanly, and is killed after the grace period if it is not there yet.
    codes = fleet.stop()
    assert codes['agent_MARC1'] in (0, -signal.SIGKILL), codes
    assert 'Traceback' not in fleet.log('agent_MARC1')
