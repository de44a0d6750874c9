"""A keyless flood — as fast as a process can publish them, of robot states naming every robot
of the fleet and saying it failed, or of plans — is dropped without starving the fleet's own
messages: no robot is declared offline at the default heartbeat timeout, no job is done twice,
no re-plan, and the mission completes."""

from collections import Counter

import pytest

from fjsp_msgs.msg import MissionEvent, TaskEvent

import flooder
from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')
FLOOD_SECONDS = 20


def jobs_done(observer) -> Counter:
    return Counter(e.job for e in observer.events if e.kind == TaskEvent.KIND_JOB_DONE)


@pytest.mark.slow
@pytest.mark.parametrize('topic', ['robot_states', 'plan'])
def test_a_keyless_flood_starves_no_robot(fjsp_fleet, topic):
    """Found in the field: ~13 700 unsigned states a second made the planner declare its
    robots offline 17 times and a job was done three times. Forged plans from the start
    pushed the real plan out of the agents' histories: the mission stayed BLOCKED, its robots
    never taking revision 1."""
    fleet = fjsp_fleet(PAPER, time_scale=0.3, key=True)
    flood = flooder.start(FLOOD_SECONDS, topic, ROBOTS, fleet.env)
    try:
        fleet.start()
        observer = fleet.observer
        fleet.wait_for(lambda o: o.complete(), 120, 'the mission to complete under the flood')
        sent = int(flood.communicate(timeout=60)[0])
        # The observer, decoding every forged message, may hear the last events after the end.
        fleet.wait_for(lambda o: len(jobs_done(o)) == 12, 30, 'every job done')
    finally:
        flood.kill()
    with observer.lock:
        offline = [e.robot for e in observer.mission_events
                   if e.kind == MissionEvent.KIND_ROBOT_OFFLINE]
        done = jobs_done(observer)
        status = observer.status
    print(f'flood: {sent / FLOOD_SECONDS:,.0f} unsigned {topic} a second; the planner '
          f'refused {status.ignored_unauthenticated:,} messages')
    assert sent > 1000 * FLOOD_SECONDS, f'the flood did not flood: {sent} messages'
    assert offline == [], (f'robots declared offline under a flood of '
                           f'{sent / FLOOD_SECONDS:,.0f} {topic} a second: {offline}')
    assert sorted(done.values()) == [1] * 12, f'jobs done more or less than once: {done}'
    assert status.plan_revision == 1
    assert status.ignored_unauthenticated > 0
