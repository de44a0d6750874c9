"""The harness's check of a mission on a real fleet: one that ends without completing fails
the test at once, naming how it ended and why, instead of waiting out its timeout."""

import time

import pytest

from fjsp_msgs.msg import MissionStatus


def test_a_cancelled_mission_fails_the_check_at_once(fjsp_fleet):
    fleet = fjsp_fleet(time_scale=0.2).start()
    fleet.wait_for(lambda o: o.status.state == MissionStatus.STATE_EXECUTING, 60,
                   'the mission to execute')
    cancel = fleet.run('fjsp_planner', 'mission', 'cancel', '--reason', 'operator stop')
    assert cancel.returncode == 0, cancel.stdout + cancel.stderr
    began = time.monotonic()
    with pytest.raises(pytest.fail.Exception) as failure:
        fleet.check_mission_complete(timeout=120)
    # Printed, not asserted: how long the check took against its 120 s timeout.
    print(f'check_mission_complete failed after {time.monotonic() - began:.1f} s')
    assert 'ended CANCELLED instead of completing' in str(failure.value)
    assert 'operator stop' in str(failure.value)
