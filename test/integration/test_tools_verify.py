"""Tools that read the fleet's topics believe only what verifies with the fleet key, as the
planner and the agents do, and say how much they dropped."""

import copy
import math
import os
import subprocess

import pytest

from fjsp_common.auth import Signer, new_key, read_key
from fjsp_common.contract import (
    EVENTS_QOS,
    LATCHED_QOS,
    MISSION_STATUS_TOPIC,
    PLAN_TOPIC,
    TASK_EVENTS_TOPIC,
)
from fjsp_common.fleet import PLANNER_NODE
from fjsp_msgs.msg import MissionStatus, Plan, TaskEvent
from fjsp_planner.launcher.listener import Listener
from fjsp_planner.launcher.supervision import find_executable
from fjsp_planner.observe.recording import replay
from fjsp_planner.observe.replay import main as replay_main

from repo_paths import PAPER


@pytest.fixture
def publisher_node(ros_domain):
    listener = Listener(ros_domain, name='forger', discovery_range='LOCALHOST')
    yield listener.node
    listener.close()


def mission_status(env) -> subprocess.CompletedProcess:
    return subprocess.run([str(find_executable('fjsp_planner', 'mission')), 'status',
                           '--timeout', '5'], env=env, capture_output=True, text=True,
                          timeout=60)


def test_mission_status_prints_only_a_status_that_verifies(tmp_path, ros_domain,
                                                           publisher_node):
    key = new_key(tmp_path / 'fleet.key')
    env = dict(os.environ, ROS_DOMAIN_ID=str(ros_domain), FJSP_FLEET_KEY_FILE=str(key),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    forger = publisher_node.create_publisher(MissionStatus, MISSION_STATUS_TOPIC, LATCHED_QOS)
    forger.publish(MissionStatus(mission_id='forged', state=MissionStatus.STATE_COMPLETE,
                                 jobs_done=24, jobs_total=24))
    alone = mission_status(env)
    assert alone.returncode == 1, alone.stdout + alone.stderr
    assert 'forged' not in alone.stdout
    assert ('ignored 1 mission status message(s) that do not verify with the fleet key: '
            '1 not signed') in alone.stderr

    planner = publisher_node.create_publisher(MissionStatus, MISSION_STATUS_TOPIC, LATCHED_QOS)
    planner.publish(Signer(read_key(key), PLANNER_NODE).sign(MissionStatus(
        mission_id='real', state=MissionStatus.STATE_EXECUTING, jobs_done=3, jobs_total=12),
        '/' + MISSION_STATUS_TOPIC))
    both = mission_status(env)
    assert both.returncode == 0, both.stdout + both.stderr
    assert 'executing 3/12  mission real' in both.stdout and 'forged' not in both.stdout


def test_the_recording_holds_what_verifies_and_its_replay_tells_the_mission_run(
        fjsp_fleet, tmp_path, capsys):
    """A keyless hijack attempt the fleet ignored: the recorder drops it too (and says how
    many), so the replay tells the mission the fleet ran, not the forger's."""
    fleet = fjsp_fleet(PAPER, time_scale=0.15, key=True).start(recorder=True)
    observer = fleet.observer
    fleet.wait_for(lambda o: o.status.jobs_done >= 1, 60, 'the mission under way')
    plans = observer.node.create_publisher(Plan, PLAN_TOPIC, LATCHED_QOS)
    events = observer.node.create_publisher(TaskEvent, TASK_EVENTS_TOPIC, EVENTS_QOS)
    fleet.wait_for(lambda o: plans.get_subscription_count() >= 7
                   and events.get_subscription_count() >= 7, 15,
                   'the fleet and its recorder to discover the forger')
    real = observer.plans[-1]
    takeover = copy.deepcopy(real)
    takeover.revision, takeover.robots = 99, []
    plans.publish(takeover)
    last = [t.job for r in real.robots for t in r.tasks][-1]
    events.publish(TaskEvent(event_id='planner/x/1', mission_id=real.mission_id,
                             kind=TaskEvent.KIND_JOB_DONE, job=last, plan_revision=1,
                             time=math.inf))
    # The observer heard the forged job-done too: the status says how the mission ended.
    fleet.wait_for(lambda o: o.complete(), 90, 'the mission to complete')
    fleet.stop('recorder')
    assert 'dropped 2 messages that do not verify with the fleet key' in fleet.log('recorder')
    (recording,) = fleet.out.glob('*.mcap')
    history, reading = replay(recording, key=read_key(fleet.key_file))
    assert reading.dropped_by_recorder == {'/plan': 1, '/task_events': 1}
    assert not reading.unverified
    mission = history.missions[real.mission_id]
    assert sorted(mission.plans) == [1] and mission.agrees_with_status()
    assert replay_main([str(recording), '--no-chart']) == 0
    out = capsys.readouterr().out
    assert 'complete: 12/12 jobs done (planner: 12/12)' in out
    assert '/plan: the recorder dropped 1 message(s) that did not verify' in out


@pytest.mark.parametrize(('node', 'key', 'message'), [
    ('recorder', 'missing', 'cannot read the fleet key'),
    ('planner_node', 'world-readable', 'readable or writable by others (mode 0644); it must '
                                       'be private to its owner: chmod 600'),
    ('monitor_node', 'world-readable', 'readable or writable by others'),
])
def test_a_key_file_that_cannot_be_used_stops_the_node_at_start(tmp_path, ros_domain, node,
                                                                 key, message):
    path = tmp_path / 'fleet.key'
    if key == 'world-readable':
        new_key(path).chmod(0o644)
    env = dict(os.environ, ROS_DOMAIN_ID=str(ros_domain),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    done = subprocess.run([str(find_executable('fjsp_planner', node)), '--ros-args',
                           '-p', f'fleet_key_file:={path}', '-p', f'out_dir:={tmp_path}'],
                          env=env, capture_output=True, text=True, timeout=60)
    output = done.stdout + done.stderr
    assert done.returncode == 2, output
    assert f"parameter 'fleet_key_file': {path}: " in output and message in output
    assert 'Traceback' not in output
