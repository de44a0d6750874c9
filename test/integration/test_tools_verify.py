"""Tools that read the fleet's topics believe only what verifies with the fleet key, as the
planner and the agents do, and say how much they dropped."""

import os
import subprocess

import pytest

from fjsp_common.auth import Signer, new_key, read_key
from fjsp_common.contract import LATCHED_QOS, MISSION_STATUS_TOPIC
from fjsp_common.fleet import PLANNER_NODE
from fjsp_msgs.msg import MissionStatus
from fjsp_planner.launcher.listener import Listener
from fjsp_planner.launcher.supervision import find_executable


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
