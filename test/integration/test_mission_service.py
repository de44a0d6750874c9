"""Missions as a service that cannot be confused, over real processes: requests name the
mission they are for, every client is heard whatever other clients did, missions sent while
one runs wait their turn in a queue a restarted planner keeps, and `mission submit --wait`
gives up once the planner is gone. A second planner on the domain stands by."""

import copy
import subprocess
import time

import pytest

from fjsp_msgs.action import RunMission
from fjsp_msgs.msg import MissionEvent, MissionStatus
from fjsp_msgs.srv import CancelMission
from fjsp_planner.launcher.supervision import find_executable
from fjsp_planner.missions import MissionClient, MissionError
from fjsp_planner.model.scenario import load_scenario

from mission_checks import check_done_once, of_mission
from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')

SLOW = 0.1
"""Wall seconds per schedule unit: one panel takes about 3 s."""


def idle_fleet(fjsp_fleet, key=False, **planner):
    """An idle planner (no scenario: it waits for goals) and the paper's four agents."""
    fleet = fjsp_fleet(PAPER, time_scale=SLOW, key=key, planner=planner)
    fleet.start_planner(scenario='')
    for robot in ROBOTS:
        fleet.start_agent(robot)
    fleet.wait_for(lambda o: len(o.robots) == 4 and o.status is not None, 30,
                   'the four agents and the idle planner')
    return fleet


def client_of(fleet) -> MissionClient:
    return MissionClient(domain_id=fleet.domain, key_file=fleet.key_file)


# --- item E: clients do not lock each other out -------------------------------------------

def test_an_old_client_is_heard_after_a_newer_one_used_the_planner(fjsp_fleet):
    """Found in the field: every client signed as 'mission_client', and replay protection
    orders a sender's messages by process start, so once a newer client had spoken, a
    long-lived older one was refused ('the goal is not signed with the fleet key')."""
    fleet = idle_fleet(fjsp_fleet, key=True)
    with client_of(fleet) as old:
        old.status()
        time.sleep(0.01)
        with client_of(fleet) as new:
            for client in (new, old, new):
                mission = client.submit(PAPER)
                client.cancel(mission.mission_id, reason='next client')
                assert mission.result(timeout=30).state == 'cancelled'
            last = old.run(PAPER, timeout=90)
    assert last.complete, last
    assert fleet.observer.status.ignored_unauthenticated == 0


# --- item D: a request names its mission ----------------------------------------------------

def test_a_cancel_replayed_after_a_planner_restart_cannot_cancel_a_newer_mission(
        fjsp_fleet, tmp_path):
    """Found in the field: `mission cancel` sent no mission id, so a signed cancel recorded
    by a listener without the key and replayed to a restarted planner (which has not heard
    the client before) cancelled whatever mission ran then."""
    fleet = idle_fleet(fjsp_fleet, key=True, journal_dir=tmp_path / 'journal')
    recorded = []
    with client_of(fleet) as client:
        sign = client._signer.sign

        def recording(msg, name):
            signed = sign(msg, name)
            recorded.append(copy.deepcopy(signed))
            return signed

        client._signer.sign = recording
        first = client.submit(PAPER)
        client.cancel(reason='operator stop')  # as `mission cancel` does: no id given
        assert first.result(timeout=30).state == 'cancelled'
        (cancel,) = [m for m in recorded if isinstance(m, CancelMission.Request)]
        assert cancel.mission_id == first.mission_id
        # Replayed to the planner that heard it: refused, saying so.
        goal = next(m for m in recorded if isinstance(m, RunMission.Goal))
        rejected = replay_goal(client, copy.deepcopy(goal))
        assert rejected.state == RunMission.Result.STATE_REJECTED
        assert rejected.reasons[0].startswith("refused: replayed message of 'mission_client/")

    fleet.kill('planner')
    fleet.start_planner(scenario='')
    with client_of(fleet) as client:
        second = client.submit(PAPER, timeout=30)
        with pytest.raises(MissionError, match="no mission 'elsewhere'"):
            client.cancel('elsewhere')  # the new planner answers this client: it hears it
        replayed = call(client, copy.deepcopy(cancel))
        assert not replayed.success
        assert f"no mission '{first.mission_id}' is running" in replayed.message
        result = second.result(timeout=120)
    assert result.complete, result
    assert 'refused' in fleet.log('planner')


def until(predicate, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            pytest.fail(f'timed out after {timeout:g} s waiting for {what}', pytrace=False)
        time.sleep(0.05)


def replay_goal(client: MissionClient, goal) -> RunMission.Result:
    """Send `goal` as it is (signed already), once; its result."""
    accepted = client._sent(lambda: client._action.send_goal_async(goal))
    assert client._wait(accepted, 10), 'the planner did not answer the goal'
    result = client._sent(accepted.result().get_result_async)
    assert client._wait(result, 10), 'the planner did not answer with a result'
    return result.result().result


def call(client: MissionClient, request):
    """Send `request` as it is (signed already), once; the planner's answer."""
    future = client._cancel.call_async(request)
    assert client._wait(future, 10), 'the planner did not answer'
    return future.result()


def test_cancel_and_add_name_the_mission_they_are_for(fjsp_fleet):
    fleet = idle_fleet(fjsp_fleet)
    with client_of(fleet) as client:
        with pytest.raises(MissionError, match='no mission runs: the planner waits for one'):
            client.cancel()
        # Slow (32 s): it is cancelled long before, however slowly the CLI starts.
        mission = client.submit(PAPER, time_scale=1.0)
        with pytest.raises(MissionError, match="no mission 'earlier' is running or waits in "
                                               f"the queue \\(running: '{mission.mission_id}'"):
            client.add_jobs(fragment_yaml='jobs: []\n', mission_id='earlier')
        done = fleet.run('fjsp_planner', 'mission', 'cancel', '--reason', 'by the CLI',
                         timeout=60)
        assert done.returncode == 0, done.stdout + done.stderr
        assert done.stdout.strip() == f"mission '{mission.mission_id}' cancelled"
        assert mission.result(timeout=30).state == 'cancelled'


# --- the queue --------------------------------------------------------------------------------

def test_missions_wait_their_turn_and_a_queued_one_can_be_cancelled(fjsp_fleet):
    fleet = idle_fleet(fjsp_fleet)
    observer = fleet.observer
    with client_of(fleet) as client:
        # Long enough (32 units of 0.5 s) for the queue to be looked at and changed.
        running = client.submit(PAPER, time_scale=0.5)
        queued = [client.submit(PAPER) for _ in range(3)]
        assert running.queue_position == 0
        assert [m.queue_position for m in queued] == [1, 2, 3]
        fleet.wait_for(lambda o: o.status.mission_id == running.mission_id
                       and len(o.status.queue) == 3, 20, 'the queue in the status')
        assert list(observer.status.queue) == [m.mission_id for m in queued]
        shown = fleet.run('fjsp_planner', 'mission', 'status', timeout=60)
        assert shown.returncode == 0, shown.stdout + shown.stderr
        assert [line.split()[-1] for line in shown.stdout.splitlines() if 'queued' in line] \
            == [m.mission_id for m in queued]
        second, third, fourth = queued
        assert client.cancel(third.mission_id) == \
            f"mission '{third.mission_id}' taken out of the queue"
        assert third.result(timeout=10).state == 'cancelled'
        ends = [m.result(timeout=180) for m in (running, second, fourth)]
    assert all(r.complete for r in ends), ends
    problem = load_scenario(PAPER)
    for mission in (running, second, fourth):
        check_done_once(problem, observer, mission.mission_id)
    assert of_mission(observer, third.mission_id) == ([], [])
    with observer.lock:
        story = [(e.mission_id, e.kind) for e in observer.mission_events
                 if e.kind in (MissionEvent.KIND_MISSION_STARTED,
                               MissionEvent.KIND_MISSION_COMPLETE)]
    order = [(m.mission_id, kind) for m in (running, second, fourth)
             for kind in (MissionEvent.KIND_MISSION_STARTED, MissionEvent.KIND_MISSION_COMPLETE)]
    assert story == order


def test_a_goal_that_asks_not_to_wait_and_a_full_queue_are_refused(fjsp_fleet):
    fleet = idle_fleet(fjsp_fleet, queue_limit=1)
    with client_of(fleet) as client:
        running = client.submit(PAPER)
        with pytest.raises(MissionError, match='one mission per fleet at a time') as busy:
            client.submit(PAPER, queue=False)
        assert running.mission_id in str(busy.value)
        queued = client.submit(PAPER)
        with pytest.raises(MissionError, match=r'the queue is full: 1 missions wait their '
                                               r'turn \(queue_limit 1\)'):
            client.submit(PAPER)
        for mission in (running, queued):
            client.cancel(mission.mission_id)


def test_a_restarted_planner_keeps_its_queue(fjsp_fleet, tmp_path):
    fleet = idle_fleet(fjsp_fleet, journal_dir=tmp_path / 'journal')
    observer = fleet.observer
    with client_of(fleet) as client:
        running = client.submit(PAPER)
        queued = client.submit(PAPER, panels=2)
    fleet.wait_for(lambda o: o.status.mission_id == running.mission_id
                   and o.status.jobs_done >= 2, 60, 'the first mission under way')
    fleet.kill('planner')
    fleet.start_planner(scenario='')
    fleet.wait_for(lambda o: o.status.mission_id == queued.mission_id
                   and o.status.state == MissionStatus.STATE_COMPLETE, 180,
                   'the queued mission completed after the resumed one')
    log = fleet.log('planner')
    assert f"mission '{queued.mission_id}' waits in the queue again (position 1)" in log
    check_done_once(load_scenario(PAPER), observer, running.mission_id)
    check_done_once(load_scenario(PAPER, panels=2), observer, queued.mission_id)


# --- item I: `mission submit --wait` and a planner that dies -------------------------------

def test_submit_wait_gives_up_with_a_reason_once_the_planner_is_gone(fjsp_fleet):
    fleet = idle_fleet(fjsp_fleet)
    submit = subprocess.Popen(
        [str(find_executable('fjsp_planner', 'mission')), 'submit', str(PAPER), '--wait',
         '--timeout', '5'], env=fleet.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)
    try:
        fleet.wait_for(lambda o: o.status.jobs_done >= 1, 60, 'the mission under way')
        fleet.kill('planner')
        out, err = submit.communicate(timeout=60)
    finally:
        if submit.poll() is None:
            submit.kill()
            submit.communicate()
    assert submit.returncode == 1, out + err
    assert 'the planner has said nothing of mission' in err, err


# --- item H: one planner per domain ---------------------------------------------------------

def test_a_second_planner_on_the_domain_stands_by_and_takes_over_when_alone(fjsp_fleet):
    """Found in the field: two keyed planners on one domain both accepted a goal; one ran
    the mission, the other stayed BLOCKED for good calling healthy robots failed, and
    `mission submit --wait` printed both one's and the other's feedback."""
    fleet = idle_fleet(fjsp_fleet, key=True, rival_timeout=3.0)
    second = 'planner_second'
    fleet.start_node(second, 'fjsp_planner', 'planner_node',
                     {**fleet.extra['planner'], 'scenario': '', 'time_scale': SLOW,
                      'rival_timeout': 3.0}, ros_args=('-r', f'__node:={second}'))
    until(lambda: 'standing by' in fleet.log(second), 30, 'the second planner to stand by')
    assert f'incarnation {fleet.observer.status.auth.incarnation})' in fleet.log(second)
    done = fleet.run('fjsp_planner', 'mission', 'submit', str(PAPER), '--wait', timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    shown = {line.split(':')[0] for line in done.stdout.splitlines()
             if not line.startswith('mission ')}
    (mission_id,) = {p.mission_id for p in fleet.observer.plans}
    assert shown == {mission_id}, done.stdout
    assert 'accepted' not in fleet.log(second)
    first = fleet.observer.status.auth.incarnation
    assert {e.auth.incarnation for e in fleet.observer.mission_events} == {first}

    fleet.kill('planner')
    until(lambda: 'in charge of the fleet: no other planner heard for 3 s'
          in fleet.log(second), 30, 'the second planner to take charge')
    with client_of(fleet) as client:
        result = client.run(PAPER, timeout=120)
    assert result.complete, result
