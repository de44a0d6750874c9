"""A keyless flood of robot states — as fast as a process can publish them, naming every robot
of the fleet and saying it failed — is dropped without starving the robots' own states: no
robot is declared offline, no job is done twice, no re-plan, and the mission completes."""

import subprocess
import sys
from collections import Counter

import pytest

from fjsp_msgs.msg import MissionEvent, TaskEvent

from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')
FLOODER = """
import math, sys, time
import rclpy
from fjsp_common.contract import LATCHED_QOS, ROBOT_STATES_TOPIC
from fjsp_msgs.msg import RobotState
rclpy.init()
node = rclpy.create_node('flooder')
publisher = node.create_publisher(RobotState, ROBOT_STATES_TOPIC, LATCHED_QOS)
forged = [RobotState(robot=robot, mode=RobotState.MODE_FAILED, failures=1, busy_until=math.nan)
          for robot in sys.argv[2:]]
sent, end = 0, time.monotonic() + float(sys.argv[1])
while time.monotonic() < end:
    for msg in forged:
        publisher.publish(msg)
    sent += len(forged)
print(sent)
"""


@pytest.mark.slow
def test_a_keyless_flood_of_robot_states_starves_no_robot(fjsp_fleet):
    fleet = fjsp_fleet(PAPER, time_scale=0.3, key=True).start()
    observer = fleet.observer
    fleet.wait_for(lambda o: o.plans, 60, 'the first plan')
    flood = subprocess.Popen([sys.executable, '-c', FLOODER, '20', *ROBOTS], env=fleet.env,
                             stdout=subprocess.PIPE, text=True)
    try:
        fleet.wait_for(lambda o: o.complete(), 120, 'the mission to complete under the flood')
        sent = int(flood.communicate(timeout=60)[0])
    finally:
        flood.kill()
    with observer.lock:
        offline = [e.robot for e in observer.mission_events
                   if e.kind == MissionEvent.KIND_ROBOT_OFFLINE]
        done = Counter(e.job for e in observer.events if e.kind == TaskEvent.KIND_JOB_DONE)
    assert sent > 1000, 'the flood did not flood'
    assert offline == [], f'robots declared offline under the flood: {offline}'
    assert sorted(done.values()) == [1] * 12, f'jobs done more or less than once: {done}'
    assert observer.status.plan_revision == 1
    assert observer.status.ignored_unauthenticated > 0
