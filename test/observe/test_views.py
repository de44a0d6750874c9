"""What a person is shown (no ROS): the mission line, robot rows with what they wait for, the
timeline drawn by the page and the PNG, terminal frames printed only on change."""

import math

import pytest

from fjsp_common.vocabulary import EventKind, MissionState, RobotMode
from fjsp_planner.observe import text, views
from fjsp_planner.observe.history import FleetHistory
from fjsp_planner.observe.mission_chart import write_mission

from mission_facts import (
    MISSION,
    at,
    event,
    faulty_mission,
    heartbeats,
    plan,
    state,
    status,
    task,
    work,
)


def fleet_of(facts) -> FleetHistory:
    fleet = FleetHistory()
    for fact in facts:
        fleet.add(fact)
    return fleet


def row_of(rows, robot):
    return next(r for r in rows if r['robot'] == robot)


def test_the_mission_line_counts_every_revision():
    fleet = fleet_of(faulty_mission())
    header = views.header(fleet.missions[MISSION], at(20))
    assert (header['jobs_done'], header['jobs_total'], header['status_jobs']) == (3, 3, [3, 3])
    assert header['agrees'] and header['ended']
    assert (header['aborted_attempts'], header['voided_attempts']) == (1, 1)
    assert header['revision'] == 2
    assert header['replan_reasons'] == ["robot 'C' failed", "job 'J2' aborted"]
    # Once ended, the clock stops where the planner said it ended.
    assert header['time'] == 13


def test_the_timeline_holds_every_attempt_span_and_revision():
    fleet = fleet_of(faulty_mission())
    timeline = views.timeline(fleet, fleet.missions[MISSION], at(20))
    work = {(w['robot'], w['job'], w['attempt'], w['outcome']) for w in timeline['work']}
    assert ('C', 'J2', 1, 'aborted') in work
    assert ('A', 'J1', 1, 'voided') in work and ('A', 'J1', 2, 'done') in work
    assert ('A', 'J3', 1, 'done') in work
    assert [(h['robot'], h['kind']) for h in timeline['health']] == [('C', 'failed'),
                                                                      ('A', 'offline')]
    assert [r['number'] for r in timeline['revisions']] == [1, 2]
    assert [p['revision'] for p in timeline['plans']] == [1, 2]
    assert timeline['robots'] == ['A', 'B', 'C']
    modes = {a['mode'] for a in timeline['activities']}
    assert 'holding' in modes and 'working' not in modes


def test_a_waiting_robot_says_what_it_waits_for():
    facts = [plan(1, 0, [task('A', 'J1', 0, 2), task('A', 'J2', 4, 6, co_workers=['B'],
                                                      predecessors=['J1']),
                         task('B', 'J2', 4, 6, co_workers=['A'], predecessors=['J1'])])]
    facts += work(['A'], 'J1', 1, 0, 2, done=False)
    facts += [event(EventKind.ARRIVED, 'B', 'J2', 1, 3),
              state('B', 3.5, mode=RobotMode.WAITING, job='J2', location='at_J2')]
    fleet = fleet_of(facts)
    b = row_of(views.robot_rows(fleet, fleet.missions[MISSION], at(3.6)), 'B')
    assert b['detail'] == 'J2: waits for A to arrive, J1 to be done, planned start t=4'


def test_a_predecessor_done_before_the_revision_is_not_waited_for():
    # A monitor started after J1 ended never saw it done; revision 2 leaves it out, as
    # the planner leaves out every job done before a revision, and still names it.
    facts = [plan(2, 0, [task('A', 'J2', 4, 6, co_workers=['B'], predecessors=['J1']),
                         task('B', 'J2', 4, 6, co_workers=['A'], predecessors=['J1'])])]
    facts += [event(EventKind.ARRIVED, 'B', 'J2', 2, 3),
              state('B', 3.5, mode=RobotMode.WAITING, job='J2', location='at_J2', revision=2)]
    fleet = fleet_of(facts)
    b = row_of(views.robot_rows(fleet, fleet.missions[MISSION], at(3.6)), 'B')
    assert b['detail'] == 'J2: waits for A to arrive, planned start t=4'


def test_a_holding_robot_says_whom_it_waits_for_to_finish():
    facts = [plan(1, 0, [task('A', 'J1', 1, 3, co_workers=['B']),
                         task('B', 'J1', 1, 5, co_workers=['A'])])]
    facts += work(['A', 'B'], 'J1', 1, 1, 5, done=False)
    facts += [event(EventKind.OPERATION_DONE, 'A', 'J1', 1, 3),
              state('A', 3.2, mode=RobotMode.HOLDING, job='J1')]
    fleet = fleet_of(facts)
    a = row_of(views.robot_rows(fleet, fleet.missions[MISSION], at(3.3)), 'A')
    assert a['detail'] == 'J1: waits for B to finish (holding its part)'


def test_a_silent_robot_shows_offline_until_it_reports():
    facts = [plan(1, 0, [task('A', 'J1', 0, 5)])] + heartbeats('A', 0, 2)
    fleet = fleet_of(facts)
    mission = fleet.missions[MISSION]
    assert row_of(views.robot_rows(fleet, mission, at(2.5)), 'A')['mode'] == 'idle'
    row = row_of(views.robot_rows(fleet, mission, at(4)), 'A')
    assert (row['mode'], row['healthy']) == ('offline', False)
    assert [i['text'] for i in views.story(fleet, mission, at(4))][-1] == \
        'A offline: heartbeat lost'


def test_robots_without_a_mission_are_shown_too():
    fleet = fleet_of([state('A', 1, mission='')])
    [row] = views.robot_rows(fleet, None, at(1.5))
    assert (row['robot'], row['mode']) == ('A', 'idle')
    shown, _ = text.frame(None, [row])
    assert shown.splitlines()[0] == 'no mission yet (is the planner running?)'
    assert 'A          idle' in shown


def test_a_frame_is_new_only_when_something_noticeable_changed():
    facts = [plan(1, 0, [task('A', 'J1', 0, 5)])]
    facts += work(['A'], 'J1', 1, 0, 5, done=False)
    fleet = fleet_of(facts + [state('A', 1, mode=RobotMode.WORKING, job='J1', progress=0.2)])
    mission = fleet.missions[MISSION]

    def frame(now):
        return text.frame(views.header(mission, now), views.robot_rows(fleet, mission, now))

    first, key = frame(at(1.1))
    assert 'A          working    job J1      20%' in first
    fleet.add(state('A', 1.3, mode=RobotMode.WORKING, job='J1', progress=0.6))
    moved, same = frame(at(1.4))
    assert '60%' in moved and same == key
    fleet.add(state('A', 1.5, mode=RobotMode.FAILED))
    _, changed = frame(at(1.6))
    assert changed != key


@pytest.mark.parametrize(('state', 'label'), [
    (MissionState.FAILED, 'Failed'),
    (MissionState.CANCELLED, 'Cancelled'),
    (MissionState.BLOCKED, 'Blocked'),
    (MissionState.WAITING_FOR_ROBOTS, 'Waiting'),
])
def test_the_reasons_are_labelled_by_what_the_mission_is_in(state, label):
    """A failed mission's reason is why it failed, a cancel's why it was cancelled: neither
    is a block."""
    facts = [plan(1, 0, [task('A', 'J1', 0, 5)]),
             status(2, state, 0, 1, blocked=["job 'J1' cannot be staffed"])]
    fleet = fleet_of(facts)
    mission = fleet.missions[MISSION]
    header = views.header(mission, at(3))
    assert header['reasons_label'] == label
    shown, _ = text.frame(header, views.robot_rows(fleet, mission, at(3)))
    assert f"  {label.lower()}: job 'J1' cannot be staffed" in shown.splitlines()


def test_story_lines_carry_their_schedule_time():
    assert text.story_line({'time': 5.5, 'text': 'revision 2 planned'}) == \
        't=   5.500  revision 2 planned'
    assert text.story_line({'time': 5, 'text': 'job J1 done'}) == 't=       5  job J1 done'
    assert text.story_line({'time': None, 'text': 'x'}).endswith('?  x')


def test_the_summary_says_when_counts_disagree():
    facts = [f for f in faulty_mission()
             if not (getattr(f, 'kind', None) == EventKind.JOB_DONE and f.job == 'J3')]
    summary = text.summary(fleet_of(facts).missions[MISSION])
    assert '2/3 jobs done (planner: 3/3, DISAGREES)' in summary


def test_views_are_json_ready(tmp_path):
    import json

    fleet = fleet_of(faulty_mission())
    mission = fleet.missions[MISSION]
    for part in (views.header(mission, at(20)), views.timeline(fleet, mission, at(20)),
                 views.robot_rows(fleet, mission, at(20)), views.story(fleet, mission, at(20)),
                 views.missions(fleet)):
        json.dumps(part, allow_nan=False)
    png = tmp_path / 'chart.png'
    write_mission(fleet, mission, at(20), png)
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    data = json.loads(png.with_suffix('.json').read_text())
    assert data['mission']['jobs_done'] == 3
    assert not math.isnan(data['timeline']['end'])
