"""No one else in charge: in a fleet with a key, forged, wrongly signed and replayed plans,
events, states and fault requests are dropped and counted, and the mission completes as
planned. Signing itself is checked first, without processes."""

import copy
import math
import time

import pytest

from fjsp_common.auth import FleetKeyError, Signer, Verifier, new_key, read_key
from fjsp_common.contract import (
    EVENTS_QOS,
    LATCHED_QOS,
    PLAN_TOPIC,
    ROBOT_STATES_TOPIC,
    TASK_EVENTS_TOPIC,
)
from fjsp_common.fleet import PLANNER_NODE
from fjsp_msgs.msg import MissionStatus, Plan, RobotState, TaskEvent
from fjsp_planner.faults import FaultError, inject_fault

from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')


@pytest.fixture
def key_file(tmp_path):
    return new_key(tmp_path / 'fleet.key')


# --- signing, without processes ------------------------------------------------------------

def test_a_signed_message_verifies_once_and_only_unchanged(key_file):
    key = read_key(key_file)
    signer, verifier = Signer(key, 'MARC1'), Verifier(key)
    state = signer.sign(RobotState(robot='MARC1', mode=RobotState.MODE_IDLE, busy_until=math.nan),
                        '/robot_states')
    assert verifier.check(state, '/robot_states', {'MARC1'}) == ''
    assert 'replayed' in verifier.check(state, '/robot_states', {'MARC1'})
    changed = copy.deepcopy(signer.sign(state, '/robot_states'))
    changed.mode = RobotState.MODE_FAILED
    assert 'does not verify' in verifier.check(changed, '/robot_states', {'MARC1'})
    other_topic = signer.sign(copy.deepcopy(state), '/robot_states')
    assert 'does not verify' in verifier.check(other_topic, '/cell2/robot_states')
    assert 'may not send' in verifier.check(signer.sign(state, '/robot_states'),
                                            '/robot_states', {'LSMS'})
    assert verifier.check(RobotState(robot='MARC1'), '/robot_states') == 'not signed'
    wrong = Signer(bytes(32), 'MARC1').sign(RobotState(robot='MARC1'), '/robot_states')
    assert 'does not verify' in verifier.check(wrong, '/robot_states')
    assert verifier.rejected == 6


def test_a_restarted_sender_counts_afresh_but_an_old_one_is_refused(key_file):
    key = read_key(key_file)
    verifier = Verifier(key)
    old = Signer(key, PLANNER_NODE)
    first = old.sign(Plan(revision=1), '/plan')
    time.sleep(0.001)
    new = Signer(key, PLANNER_NODE)
    assert verifier.check(new.sign(Plan(revision=2), '/plan'), '/plan') == ''
    assert 'replayed' in verifier.check(first, '/plan')


@pytest.mark.parametrize(('text', 'reason'), [
    ('', 'at least 32'), ('zz', 'hex text'), ('ab' * 8, 'at least 32'),
])
def test_bad_key_files(tmp_path, text, reason):
    path = tmp_path / 'key'
    path.write_text(text)
    with pytest.raises(FleetKeyError, match=reason):
        read_key(path)


def test_new_keys_are_private_and_distinct(tmp_path):
    a, b = new_key(tmp_path / 'a'), new_key(tmp_path / 'b')
    assert read_key(a) != read_key(b)
    assert oct(a.stat().st_mode & 0o777) == '0o600'


# --- a fleet under attack -------------------------------------------------------------------

def start_fleet(fjsp_fleet, key_file, **planner):
    fleet = fjsp_fleet(PAPER, time_scale=0.15,
                       planner={'fleet_key_file': key_file, **planner},
                       agents={'fleet_key_file': key_file}).start()
    fleet.wait_for(lambda o: o.status is not None and o.status.jobs_done >= 1, 40,
                   'the mission under way')
    return fleet, fleet.observer


def test_forged_plan_event_and_state_are_dropped(fjsp_fleet, key_file, tmp_path):
    fleet, observer = start_fleet(fjsp_fleet, key_file)
    plans = observer.node.create_publisher(Plan, PLAN_TOPIC, LATCHED_QOS)
    events = observer.node.create_publisher(TaskEvent, TASK_EVENTS_TOPIC, EVENTS_QOS)
    states = observer.node.create_publisher(RobotState, ROBOT_STATES_TOPIC, LATCHED_QOS)
    fleet.wait_for(lambda o: plans.get_subscription_count() >= 6
                      and events.get_subscription_count() >= 6
                      and states.get_subscription_count() >= 2, 15,
                      'the nodes to discover the forger')
    real = observer.plans[-1]
    mission = real.mission_id
    takeover = copy.deepcopy(real)
    takeover.revision, takeover.robots = 99, []
    plans.publish(takeover)                       # unsigned
    wrong_key = Signer(read_key(new_key(tmp_path / 'other.key')), PLANNER_NODE)
    plans.publish(wrong_key.sign(copy.deepcopy(takeover), '/plan'))
    remaining = [t.job for r in real.robots for t in r.tasks][-1]
    events.publish(TaskEvent(event_id='planner/x/1', mission_id=mission,
                             kind=TaskEvent.KIND_JOB_DONE, job=remaining, plan_revision=1,
                             time=1.0))
    for _ in range(3):
        states.publish(RobotState(robot='MARC1', mission_id=mission, mode=RobotState.MODE_FAILED,
                                  busy_until=math.nan))
        time.sleep(0.1)
    fleet.wait_for(lambda o: o.complete(), 60, 'the mission to complete as planned')
    status = observer.status
    assert status.plan_revision == 1, 'a forged message caused a re-plan'
    assert status.jobs_done == status.jobs_total == 12
    assert status.ignored_unauthenticated >= 4
    for robot in ROBOTS:
        assert observer.robots[robot].plan_revision == 1
        assert 'dropping an unauthenticated message' in fleet.log(f'agent_{robot}')
    started = {e.job for e in observer.events if e.kind == TaskEvent.KIND_STARTED}
    assert remaining in started, 'the forged job-done made the robots skip a job'
    assert observer.status.state == MissionStatus.STATE_COMPLETE


def test_fault_requests_need_the_key(fjsp_fleet, key_file, tmp_path):
    fleet, observer = start_fleet(fjsp_fleet, key_file, start_delay=3.0)
    with pytest.raises(FaultError, match='not signed with the fleet key'):
        inject_fault('LSMS', 'delay', 1.5, node=observer.node)
    other = new_key(tmp_path / 'other.key')
    with pytest.raises(FaultError, match='not signed with the fleet key'):
        inject_fault('LSMS', 'delay', 1.5, node=observer.node, key_file=other)
    assert 'LSMS' in inject_fault('LSMS', 'delay', 1.5, node=observer.node, key_file=key_file)
