"""A keyless flood of robot states — as fast as a process can publish them, naming every robot
of the fleet and saying it failed — is dropped without starving the robots' own states: no
robot is declared offline at the default heartbeat timeout, no job is done twice, no re-plan,
and the mission completes."""

import subprocess
import sys
from collections import Counter

import pytest

from fjsp_msgs.msg import MissionEvent, TaskEvent

from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')
FLOOD_SECONDS = 20
FLOODER = """
import math, sys, time
import rclpy
from fjsp_common.contract import ROBOT_STATES, publisher
from fjsp_msgs.msg import RobotState
rclpy.init()
node = rclpy.create_node('flooder')
out = publisher(node, ROBOT_STATES)
forged = [RobotState(robot=robot, mode=RobotState.MODE_FAILED, failures=1, busy_until=math.nan)
          for robot in sys.argv[2:]]
sent, end = 0, time.monotonic() + float(sys.argv[1])
while time.monotonic() < end:
    for msg in forged:
        out.publish(msg)
    sent += len(forged)
print(sent)
"""


def jobs_done(observer) -> Counter:
    return Counter(e.job for e in observer.events if e.kind == TaskEvent.KIND_JOB_DONE)


@pytest.mark.slow
def test_a_keyless_flood_of_robot_states_starves_no_robot(fjsp_fleet):
    """Found in the field: ~13 700 unsigned states a second made the planner declare its
    robots offline 17 times and a job was done three times."""
    fleet = fjsp_fleet(PAPER, time_scale=0.3, key=True).start()
    observer = fleet.observer
    fleet.wait_for(lambda o: o.plans, 60, 'the first plan')
    flood = subprocess.Popen([sys.executable, '-c', FLOODER, str(FLOOD_SECONDS), *ROBOTS],
                             env=fleet.env, stdout=subprocess.PIPE, text=True)
    try:
        fleet.wait_for(lambda o: o.complete(), 120, 'the mission to complete under the flood')
        sent = int(flood.communicate(timeout=60)[0])
        # The observer, decoding every forged state, may hear the last events after the end.
        fleet.wait_for(lambda o: len(jobs_done(o)) == 12, 30, 'every job done')
    finally:
        flood.kill()
    with observer.lock:
        offline = [e.robot for e in observer.mission_events
                   if e.kind == MissionEvent.KIND_ROBOT_OFFLINE]
        done = jobs_done(observer)
        status = observer.status
    print(f'flood: {sent / FLOOD_SECONDS:,.0f} unsigned robot states a second; the planner '
          f'refused {status.ignored_unauthenticated:,} messages')
    assert sent > 1000 * FLOOD_SECONDS, f'the flood did not flood: {sent} states'
    assert offline == [], (f'robots declared offline under a flood of '
                           f'{sent / FLOOD_SECONDS:,.0f} states a second: {offline}')
    assert sorted(done.values()) == [1] * 12, f'jobs done more or less than once: {done}'
    assert status.plan_revision == 1
    assert status.ignored_unauthenticated > 0
