"""What the launcher believes of mission_status: only what the fleet's planner signed, and only
about the mission that planner runs; everything else is dropped, counted and named once."""

import copy

from fjsp_common.auth import Signer
from fjsp_msgs.msg import MissionStatus
from fjsp_planner.launcher.status import MissionWatch

KEY = bytes(range(32))
TOPIC = '/mission_status'


def status(state=MissionStatus.STATE_EXECUTING, mission='m1', done=3) -> MissionStatus:
    return MissionStatus(mission_id=mission, state=state, jobs_done=done, jobs_total=12)


def test_statuses_signed_by_the_planner_are_believed():
    watch, planner = MissionWatch(KEY, TOPIC), Signer(KEY, 'planner')
    assert watch.receive(planner.sign(status(), TOPIC)) == ''
    assert watch.latest.jobs_done == 3 and watch.mission_id == 'm1'
    # A planner started again signs with a new incarnation: believed at once.
    assert watch.receive(Signer(KEY, 'planner').sign(status(done=4), TOPIC)) == ''
    assert watch.latest.jobs_done == 4 and watch.tally() == ''


def test_forged_statuses_are_dropped_counted_and_named_once():
    watch, planner = MissionWatch(KEY, TOPIC), Signer(KEY, 'planner')
    watch.receive(planner.sign(status(), TOPIC))
    failed = status(MissionStatus.STATE_FAILED)
    forged = [
        (copy.deepcopy(failed), 'not signed'),
        (Signer(bytes(32), 'planner').sign(copy.deepcopy(failed), TOPIC), 'does not verify'),
        (Signer(KEY, 'MARC1').sign(copy.deepcopy(failed), TOPIC), "'MARC1' may not send this"),
        (planner.sign(copy.deepcopy(failed), '/other_topic'), 'does not verify'),
    ]
    warnings = [watch.receive(msg) for msg, _ in forged]
    assert 'does not verify with the fleet key (not signed)' in warnings[0]
    assert warnings[1:] == ['', '', '']  # the same kind: only counted
    assert watch.latest.state == MissionStatus.STATE_EXECUTING
    assert watch.tally() == 'mission statuses dropped: 4 that did not verify with the fleet key'


def test_a_replayed_status_is_dropped():
    watch, planner = MissionWatch(KEY, TOPIC), Signer(KEY, 'planner')
    old = planner.sign(status(done=1), TOPIC)
    watch.receive(old)
    watch.receive(planner.sign(status(done=2), TOPIC))
    assert 'replayed' in watch.receive(old)
    assert watch.latest.jobs_done == 2


def test_only_the_mission_its_planner_runs_counts():
    watch, planner = MissionWatch(KEY, TOPIC), Signer(KEY, 'planner')
    watch.receive(planner.sign(status(mission='m1'), TOPIC))
    warning = watch.receive(planner.sign(status(MissionStatus.STATE_COMPLETE, 'm2'), TOPIC))
    assert "is not about the mission its planner runs (mission 'm2', not 'm1')" in warning
    assert watch.latest.mission_id == 'm1' and watch.latest.state != MissionStatus.STATE_COMPLETE
    assert watch.tally() == 'mission statuses dropped: 1 of another mission'


def test_an_idle_planner_names_no_mission_yet():
    watch, planner = MissionWatch(KEY, TOPIC), Signer(KEY, 'planner')
    assert watch.receive(planner.sign(status(MissionStatus.STATE_IDLE, ''), TOPIC)) == ''
    assert watch.mission_id == ''
    watch.receive(planner.sign(status(mission='m1'), TOPIC))
    assert watch.mission_id == 'm1'


def test_without_a_key_every_status_is_believed():
    watch = MissionWatch(None, TOPIC)
    assert watch.receive(status(MissionStatus.STATE_FAILED)) == ''
    assert watch.latest.state == MissionStatus.STATE_FAILED
