"""Missions as a service over real processes: successive missions on one fleet, cancel,
rejected goals, jobs added mid-mission, and a planner killed and restarted mid-mission."""

import time

import pytest
import yaml

from fjsp_common.fleet import agent_node_name
from fjsp_msgs.msg import MissionStatus, RobotState, TaskEvent
from fjsp_planner.missions import MissionClient, MissionError
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.testing import Observer

from mission_checks import check_done_once, of_mission
from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')

SLOW = 0.1
"""Wall seconds per schedule unit: one panel takes about 3 s."""


@pytest.fixture
def idle_fleet(fjsp_fleet):
    """An idle planner (no scenario: it waits for goals) and the paper's four agents."""
    fleet = fjsp_fleet(PAPER, time_scale=SLOW)
    fleet.start_planner(scenario='')
    for robot in ROBOTS:
        fleet.start_agent(robot)
    fleet.wait_for(lambda o: len(o.robots) == 4, 30, 'the four agents')
    return fleet


@pytest.fixture
def client(idle_fleet):
    with MissionClient(domain_id=idle_fleet.domain) as client:
        yield client


@pytest.fixture
def observer(idle_fleet):
    return idle_fleet.observer


def fleet_is_idle(observer):
    return all(r.mode == RobotState.MODE_IDLE and not r.current_job
               for r in observer.robots.values())


def test_an_idle_planner_says_so(idle_fleet):
    """Before any mission the planner's status is IDLE, so `mission status` (and monitors,
    and recorders) know it is there rather than time out asking whether it runs."""
    idle_fleet.wait_for(lambda o: o.status is not None, 30, "the idle planner's status")
    assert idle_fleet.observer.status.state == MissionStatus.STATE_IDLE
    assert idle_fleet.observer.status.mission_id == ''
    done = idle_fleet.run('fjsp_planner', 'mission', 'status', timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.strip() == 'idle: no mission yet, the planner waits for one'


def test_successive_missions_on_one_fleet(client, observer):
    first = client.run(PAPER, timeout=90)
    assert first.complete, first
    assert (first.jobs_done, first.jobs_total) == (12, 12)
    assert abs(first.makespan - 32) < 1e-3
    check_done_once(load_scenario(PAPER), observer, first.mission_id)

    second = client.run(PAPER, panels=2, timeout=120)
    assert second.complete, second
    assert second.mission_id != first.mission_id and second.jobs_done == 24
    check_done_once(load_scenario(PAPER, panels=2), observer, second.mission_id)
    # Revisions count per mission, and nothing of the first leaked into the second.
    plans, _ = of_mission(observer, second.mission_id)
    assert plans[0].revision == 1


def test_goal_that_will_not_wait_and_broken_goal_are_rejected(client, observer):
    running = client.submit(PAPER)
    with pytest.raises(MissionError, match='one mission per fleet') as busy:
        client.submit(PAPER, queue=False)
    assert running.mission_id in str(busy.value)
    broken = {'operation_types': {0: 'weld'}, 'robot_types': {'W': {'weld': 1}},
              'robots': [{'name': 'R1', 'type': 'Welder'}],
              'jobs': [{'name': 'A', 'plans': [['weld']]}, {'name': 'B', 'plans': [['glue']]}],
              'precedence': [['A', 'B'], ['B', 'A']]}
    with pytest.raises(MissionError) as bad:
        client.submit(scenario_yaml=yaml.safe_dump(broken))
    text = '\n'.join(bad.value.problems)
    assert "unknown robot type 'Welder'" in text and "'glue'" in text, text
    assert 'precedence cycle' in text, text
    assert running.result(timeout=60).complete  # the running mission was untouched


def test_cancel_leaves_the_fleet_idle_for_the_next_mission(client, observer):
    mission = client.submit(PAPER)
    observer.wait_for(lambda o: o.status is not None
                      and o.status.mission_id == mission.mission_id
                      and o.status.jobs_done >= 2, 30, 'the mission under way')
    mission.cancel()
    result = mission.result(timeout=30)
    assert result.state == 'cancelled' and result.jobs_done < 12
    observer.wait_for(lambda o: o.status.state == MissionStatus.STATE_CANCELLED
                      and fleet_is_idle(o), 15, 'an idle fleet')
    # Every operation started ended: done, or aborted because the mission was cancelled.
    _, events = of_mission(observer, mission.mission_id)
    ended = {(e.robot, e.job): e for e in events
             if e.kind in (TaskEvent.KIND_OPERATION_DONE, TaskEvent.KIND_ABORTED)}
    for start in (e for e in events if e.kind == TaskEvent.KIND_STARTED):
        end = ended.get((start.robot, start.job))
        assert end is not None, f'{start.robot} never ended {start.job}'
        assert end.kind == TaskEvent.KIND_OPERATION_DONE or end.reason == 'mission cancelled', end
    third = client.run(PAPER, timeout=90)
    assert third.complete and third.jobs_done == 12
    check_done_once(load_scenario(PAPER), observer, third.mission_id)


class _SlowToRegister:
    """An action client's handle that pauses after sending each request: the time an answer
    has to come back before rclpy's action client files the request it answers."""

    def __init__(self, handle):
        self._handle = handle

    def __getattr__(self, name):
        found = getattr(self._handle, name)
        if not name.startswith('send_'):
            return found

        def send(*args):
            sequence_number = found(*args)
            time.sleep(0.5)
            return sequence_number
        return send

    def __enter__(self):
        return self._handle.__enter__()

    def __exit__(self, *exc):
        return self._handle.__exit__(*exc)


def test_an_answer_back_before_its_request_is_filed_still_counts(client, observer):
    """Found by CI: a cancel was answered, but the answer was dropped ("Ignoring unexpected
    cancel response") and `cancel()` gave up after 10 s. rclpy's action client files a
    request only after sending it (ros2/rclpy#1123); an answer the client's executor thread
    takes in between is lost, for a goal, a cancel or a result alike."""
    client._action._client_handle = _SlowToRegister(client._action._client_handle)
    mission = client.submit(PAPER, timeout=5)
    mission.cancel(timeout=5)
    assert mission.result(timeout=10).state == 'cancelled'


SECOND_PANEL = PAPER.parents[1] / 'fragments' / 'solar_panel_second_panel.yaml'


def test_a_second_panel_added_mid_mission(client, observer):
    mission = client.submit(PAPER)
    observer.wait_for(lambda o: o.status is not None
                      and o.status.mission_id == mission.mission_id
                      and o.status.jobs_done >= 1, 30, 'the first panel under way')
    with pytest.raises(MissionError) as bad:
        client.add_jobs(fragment_yaml=yaml.safe_dump({'jobs': [{'name': 'X', 'plans': [[0]]}],
                                                     'precedence': [['X', 'Nowhere']]}))
    assert any('Nowhere' in p for p in bad.value.problems), bad.value.problems
    added = client.add_jobs(SECOND_PANEL)
    assert len(added) == 12
    result = mission.result(timeout=120)
    assert result.complete and (result.jobs_done, result.jobs_total) == (24, 24), result
    _, events = of_mission(observer, mission.mission_id)
    extended = load_scenario(PAPER, panels=1)
    from fjsp_planner.model.extension import extend

    extended, _ = extend(extended, SECOND_PANEL.read_text())
    check_done_once(extended, observer, mission.mission_id)


def test_planner_killed_mid_mission_resumes_it(fjsp_fleet, tmp_path):
    problem = load_scenario(PAPER)
    fleet = fjsp_fleet(PAPER, time_scale=0.15,
                       planner={'journal_dir': tmp_path / 'journal'}).start()
    observer = fleet.observer
    fleet.wait_for(lambda o: o.status is not None and o.status.jobs_done >= 3, 40,
                   'the mission under way')
    mission_id = observer.status.mission_id
    fleet.kill('planner')
    time.sleep(0.5)
    fleet.start_planner()
    fleet.wait_for(lambda o: o.status.state == MissionStatus.STATE_COMPLETE
                   and o.status.mission_id == mission_id, 90,
                   'the same mission completed by the restarted planner')
    assert 'resuming mission' in fleet.log('planner')
    check_done_once(problem, observer, mission_id)
    # Restarted once more after the end: it does not run the mission again.
    fleet.stop('planner')
    fleet.start_planner()
    deadline = time.monotonic() + 30
    while 'not starting' not in fleet.log('planner') and time.monotonic() < deadline:
        time.sleep(0.2)
    assert 'not starting' in fleet.log('planner')
    time.sleep(1)
    assert {p.mission_id for p in observer.plans} == {mission_id}


def test_a_restarted_planner_publishes_its_last_plan_again(fjsp_fleet, tmp_path):
    """Killed while publishing a plan, the planner may have reached some subscribers and not
    others: restarted, it publishes that revision again, as it was, before re-planning."""
    fleet = fjsp_fleet(PAPER, time_scale=SLOW,
                       planner={'journal_dir': tmp_path / 'journal', 'robot_wait_timeout': 60.0})
    fleet.start()
    fleet.wait_for(lambda o: o.status is not None and o.status.jobs_done >= 1, 40,
                   'the mission under way')
    last = fleet.observer.plans[-1]
    fleet.kill('planner')
    for robot in ROBOTS:  # no robot to report: the restarted planner cannot re-plan yet
        fleet.kill(agent_node_name(robot))
    late = Observer(fleet.domain)
    try:
        fleet.start_planner()
        late.wait_for(lambda o: o.plans, 30, 'a plan from the restarted planner')
        first = late.plans[0]
        assert (first.mission_id, first.revision, first.stamp, first.robots) == (
            last.mission_id, last.revision, last.stamp, last.robots)
    finally:
        late.close()
