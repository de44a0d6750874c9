"""`ros2 run fjsp_planner fleet`: a complete mission exits 0, a bad scenario starts nothing,
no node outlives the launcher, whether it is interrupted or killed, a node interrupted while
it starts ends without a traceback, and only the fleet's planner can end the launcher."""

import copy
import os
import re
import signal
import subprocess
import time

import pytest

from fjsp_common.auth import Signer, new_key, read_key
from fjsp_common.contract import LATCHED_QOS, MISSION_STATUS_TOPIC
from fjsp_common.fleet import PLANNER_NODE
from fjsp_msgs.msg import Auth, MissionStatus
from fjsp_planner.testing import Observer

import flooder
from fleet_command import launcher, still_running, wait_for_nodes
from repo_paths import PAPER


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


def test_forged_mission_statuses_do_not_end_the_fleet(tmp_path, ros_domain):
    observer = Observer(ros_domain)
    try:
        process = launcher(tmp_path / 'out', str(PAPER), '--exit-on-complete', '--time-scale',
                           '0.15', '--timeout', '120', domain=ros_domain)
        forger = observer.node.create_publisher(MissionStatus, MISSION_STATUS_TOPIC,
                                                LATCHED_QOS)

        def readers_matched(o) -> bool:
            readers = o.node.get_subscriptions_info_by_topic('/mission_status')
            return any(r.node_name.startswith('fleet_') for r in readers) \
                and forger.get_subscription_count() >= len(readers)
        observer.wait_for(lambda o: o.status.jobs_done >= 1
                          and o.status.state == MissionStatus.STATE_EXECUTING
                          and readers_matched(o), 60,
                          "the mission under way, the forger matched to the launcher's reader")
        wrong_key = Signer(read_key(new_key(tmp_path / 'other.key')), PLANNER_NODE)
        real = copy.deepcopy(observer.status)
        for state in (MissionStatus.STATE_FAILED, MissionStatus.STATE_COMPLETE):
            forged = copy.deepcopy(real)
            forged.state, forged.jobs_done, forged.jobs_total = state, 12, 12
            forged.projected_makespan = forged.planned_makespan = 1.25
            forged.blocked_reasons, forged.auth = ['a forger says so'], Auth()
            for message in (forged, wrong_key.sign(copy.deepcopy(forged), '/mission_status')):
                forger.publish(message)
                time.sleep(0.3)
            assert process.poll() is None, process.communicate()
        out, err = process.communicate(timeout=180)
    finally:
        observer.close()
    assert process.returncode == 0, out + err
    assert 'complete: 12/12 jobs done' in out and 'makespan 1.25' not in out
    assert 'a forger says so' not in out + err
    first = re.search(r'does not verify with the fleet key \((.*?)\); further ones', err)
    assert first and first.group(1) == 'not signed', err
    assert 'mission statuses dropped: 4 that did not verify with the fleet key' in err, err


def test_a_flood_of_forged_statuses_does_not_hide_the_real_end(tmp_path, ros_domain):
    """Unsigned COMPLETE statuses, as fast as a process can publish them from before the fleet
    starts: the launcher still hears the planner's own, and ends with the mission."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(ros_domain),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    flood = flooder.start(40, 'mission_status', ['a'] * 4, env)
    try:
        # Without the recorder and the live page, which this test does not look at and which
        # would spend the two cores decoding the flood too.
        process = launcher(tmp_path, str(PAPER), '--exit-on-complete', '--time-scale', '0.1',
                           '--timeout', '90', '--no-recording', '--web-port', '0',
                           domain=ros_domain)
        out, err = process.communicate(timeout=150)
    finally:
        flood.kill()
    assert process.returncode == 0, out + err
    assert 'complete: 12/12 jobs done' in out
    dropped = re.search(r'mission statuses dropped: (\d+) that did not verify', err)
    assert dropped and int(dropped.group(1)) > 1000, err


def test_a_cancelled_mission_still_gets_its_summary_and_chart(tmp_path, ros_domain):
    observer = Observer(ros_domain)
    try:
        # 0.5 s per unit: the mission lasts 16 s, long enough for the `mission` tool to start.
        process = launcher(tmp_path, str(PAPER), '--exit-on-complete', '--time-scale', '0.5',
                           '--web-port', '0', '--timeout', '120', domain=ros_domain)
        observer.wait_for(lambda o: o.status.jobs_done >= 1, 60, 'the mission under way')
        cancel = subprocess.run(
            ['ros2', 'run', 'fjsp_planner', 'mission', 'cancel', '--reason', 'operator stop',
             '--key-file', str(tmp_path / 'fleet.key')], capture_output=True, text=True,
            timeout=60, env=dict(os.environ, ROS_DOMAIN_ID=str(ros_domain),
                                 ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST'))
        assert cancel.returncode == 0, cancel.stdout + cancel.stderr
        out, err = process.communicate(timeout=120)
    finally:
        observer.close()
    assert process.returncode == 1, out + err
    assert 'was cancelled: operator stop' in err
    assert 'cancelled: ' in out and 'Gantt chart:' in out  # the monitor's summary
    assert len(list(tmp_path.glob('solar_panel-*.png'))) == 1
