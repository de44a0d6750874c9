"""The mission history on hand-made fact sequences: attempts (done, aborted, voided), health
spans, counts against the planner's status, the story, and independence from arrival order."""

import random

import pytest

from fjsp_common.vocabulary import EventKind, MissionEventKind, MissionState, RobotMode
from fjsp_planner.observe.history import FleetHistory, Outcome
from fjsp_planner.observe.story import story

from mission_facts import (
    MISSION,
    START,
    at,
    event,
    faulty_mission,
    heartbeats,
    mission_event,
    plan,
    state,
    status,
    task,
    work,
)


def history_of(facts, timeout=1.0) -> FleetHistory:
    fleet = FleetHistory(heartbeat_timeout=timeout)
    for fact in facts:
        fleet.add(fact)
    return fleet


def attempts_by_job(mission):
    table = {}
    for a in mission.attempts():
        table.setdefault(a.job, []).append((a.number, a.outcome, a.start, a.finish,
                                            a.outcome_time))
    return table


def test_each_attempt_of_each_job_with_how_it_ended():
    mission = history_of(faulty_mission()).missions[MISSION]
    assert attempts_by_job(mission) == {
        'J3': [(1, Outcome.DONE, 0, 2, 2)],
        # Done at 3, voided when revision 2 (published at 5.5) restarted it, redone 6..8.
        'J1': [(1, Outcome.VOIDED, 2, 3, 5.5), (2, Outcome.DONE, 6, 8, 8)],
        # C failed on it at 5: aborted there, redone 8..10 under revision 2.
        'J2': [(1, Outcome.ABORTED, 4, 5, 5), (2, Outcome.DONE, 8, 10, 10)],
    }
    aborted = next(a for a in mission.attempts() if a.outcome == Outcome.ABORTED)
    assert aborted.reason == "robot 'C' failed"
    assert aborted.robots == ('B', 'C')
    voided = next(a for a in mission.attempts() if a.outcome == Outcome.VOIDED)
    assert voided.reason == 'redone from revision 2'


def test_counts_cover_every_revision_and_agree_with_the_planner():
    mission = history_of(faulty_mission()).missions[MISSION]
    counts = mission.counts()
    # J3 is in revision 1 only: a view of the last plan alone would say 2/2.
    assert (counts.done, counts.running, counts.total) == (3, 0, 3)
    assert (counts.aborted, counts.voided) == (1, 1)
    assert mission.agrees_with_status()
    assert mission.executed_makespan() == 10


def test_counts_disagreeing_with_the_planner_are_noticed():
    facts = [f for f in faulty_mission() if not (
        getattr(f, 'kind', None) == EventKind.JOB_DONE and f.job == 'J3')]
    mission = history_of(facts).missions[MISSION]
    assert mission.counts().done == 2
    assert not mission.agrees_with_status()


def test_failed_and_offline_spans_from_the_robots_states():
    mission = history_of(faulty_mission()).missions[MISSION]
    spans = [(s.robot, s.kind, round(s.start, 6), s.end and round(s.end, 6))
             for s in mission.spans()]
    # C reported FAILED from t=5 and never recovered; A was last heard at 10.4, next at 13.
    assert spans == [('C', 'failed', 5.0, None), ('A', 'offline', 10.4, 13.0)]


def test_a_robot_silent_now_has_an_open_offline_span():
    facts = [plan(1, 0, [task('A', 'J1', 0, 5)])] + heartbeats('A', 0, 2)
    fleet = history_of(facts)
    mission = fleet.missions[MISSION]
    assert fleet.silent(mission, at(2.5)) == {}
    silent = fleet.silent(mission, at(3.5))
    assert silent == {'A': at(2)}
    [span] = mission.spans(silent)
    assert (span.robot, span.kind, round(span.start, 6), span.end) == ('A', 'offline', 2.0,
                                                                        None)


def test_gaps_within_the_heartbeat_timeout_are_no_offline_span():
    facts = [plan(1, 0, [task('A', 'J1', 0, 5)])] + heartbeats('A', 0, 2, period=0.9)
    assert history_of(facts).missions[MISSION].spans() == []


def test_recovery_closes_the_failed_span():
    facts = [plan(1, 0, [task('A', 'J1', 0, 5)])]
    facts += heartbeats('A', 0, 1) + heartbeats('A', 1.2, 3, mode=RobotMode.FAILED)
    facts += heartbeats('A', 3.2, 4)
    [span] = history_of(facts).missions[MISSION].spans()
    assert (span.kind, round(span.start, 6), round(span.end, 6)) == ('failed', 1.2, 3.2)


def test_the_same_history_whatever_order_the_topics_arrive_in():
    facts = faulty_mission()
    expected = history_of(facts).missions[MISSION]
    robot_states = [f for f in facts if hasattr(f, 'mode')]
    others = [f for f in facts if not hasattr(f, 'mode')]
    for seed in range(5):
        random.Random(seed).shuffle(others)
        # Each robot's own states stay in order, as one writer's messages do.
        mission = history_of(others + robot_states).missions[MISSION]
        assert mission.attempts() == expected.attempts()
        assert mission.spans() == expected.spans()
        assert mission.counts() == expected.counts()
        assert [i.key for i in story(mission)] == [i.key for i in story(expected)]


def test_a_late_joiner_without_the_first_plan_groups_attempts_by_revision():
    facts = [f for f in faulty_mission() if getattr(f, 'revision', None) != 1
             or not hasattr(f, 'tasks')]
    mission = history_of(facts).missions[MISSION]
    table = attempts_by_job(mission)
    assert [a[1] for a in table['J2']] == [Outcome.ABORTED, Outcome.DONE]
    assert [a[1] for a in table['J1']] == [Outcome.VOIDED, Outcome.DONE]
    assert mission.counts().total == 3


def test_a_running_job_restarted_by_a_revision_is_aborted_there():
    # A robot going offline mid-job sends no ABORTED: the re-plan restarting the job ends it.
    facts = [plan(1, 0, [task('A', 'J1', 1, 4), task('B', 'J1', 1, 4)]),
             plan(2, 2.5, [task('B', 'J1', 3, 6)], reasons=["robot 'A' offline"])]
    facts += work(['A', 'B'], 'J1', 1, 1, 4, done=False)
    facts += work(['B'], 'J1', 2, 3, 6)
    mission = history_of(facts).missions[MISSION]
    assert attempts_by_job(mission)['J1'] == [(1, Outcome.ABORTED, 1, 2.5, 2.5),
                                              (2, Outcome.DONE, 3, 6, 6)]
    assert mission.attempts()[0].reason == 'restarted by revision 2'


def test_a_continued_job_keeps_its_attempt():
    facts = [plan(1, 0, [task('A', 'J1', 1, 4)]),
             plan(2, 2, [task('A', 'J1', 1, 4, continued=True)], reasons=['late'])]
    facts += work(['A'], 'J1', 1, 1, 4, done=False)
    facts += [event(EventKind.OPERATION_DONE, 'A', 'J1', 2, 4),
              event(EventKind.JOB_DONE, '', 'J1', 2, 4)]
    assert attempts_by_job(history_of(facts).missions[MISSION]) == {
        'J1': [(1, Outcome.DONE, 1, 4, 4)]}


def test_a_late_joiner_takes_a_restart_it_missed_from_the_plan_that_continues_it():
    # Revision 2 restarted J1 and A arrived under it, revisions 3 and 4 kept J1 as it was, A
    # started it under 3. A monitor that only got revision 4 still sees two attempts, not one
    # (revision 2 unknown) nor three (a start under a revision it has no plan of).
    facts = [plan(4, 6.5, [task('A', 'J1', 6, 8, continued=True, restarted_in=2)])]
    facts += work(['A'], 'J1', 1, 1, 4, done=False)
    facts += [event(EventKind.ARRIVED, 'A', 'J1', 2, 5),
              event(EventKind.STARTED, 'A', 'J1', 3, 6),
              event(EventKind.OPERATION_DONE, 'A', 'J1', 4, 8),
              event(EventKind.JOB_DONE, '', 'J1', 4, 8)]
    attempts = history_of(facts).missions[MISSION].attempts()
    assert [(a.number, a.revision, a.start) for a in attempts] == [(1, 1, 1), (2, 2, 6)]
    assert attempts[1].outcome == Outcome.DONE


def test_the_planners_mission_events_decide_aborts_and_voids():
    facts = [plan(1, 0, [task('A', 'J1', 1, 2), task('A', 'J2', 3, 6)])]
    facts += work(['A'], 'J1', 1, 1, 2) + work(['A'], 'J2', 1, 3, 6, done=False)
    facts += [mission_event(MissionEventKind.JOB_VOIDED, 4, job='J1', reasons=['hold lost']),
              mission_event(MissionEventKind.JOB_ABORTED, 4, job='J2',
                            reasons=["robot 'A' offline"])]
    table = attempts_by_job(history_of(facts).missions[MISSION])
    assert table == {'J1': [(1, Outcome.VOIDED, 1, 2, 4)],
                     'J2': [(1, Outcome.ABORTED, 3, 4, 4)]}


def test_the_story_is_derived_when_the_planner_tells_none():
    mission = history_of(faulty_mission()).missions[MISSION]
    lines = [(round(i.time, 6), i.text) for i in story(mission)]
    assert lines == [
        (-0.5, 'revision 1 planned: makespan 10 (optimal)'),
        (5.0, 'C failed'),
        (5.0, "job J2 aborted: robot 'C' failed"),
        (5.5, "revision 2 planned: robot 'C' failed; job 'J2' aborted"),
        (5.5, 'job J1 voided: redone from revision 2'),
        (10.4, 'A offline: heartbeat lost'),
        (13.0, 'A back in service'),
        (13.0, 'mission complete: 3/3 jobs done'),
    ]


def test_the_story_is_the_planners_when_it_tells_one():
    facts = faulty_mission() + [
        mission_event(MissionEventKind.MISSION_STARTED, 0, reasons=['from demo.yaml']),
        mission_event(MissionEventKind.ROBOT_FAILED, 5.1, robot='C'),
        mission_event(MissionEventKind.PLAN_PUBLISHED, 5.5, revision=2,
                      reasons=["robot 'C' failed"])]
    lines = [i.text for i in story(history_of(facts).missions[MISSION])]
    assert lines == ['mission started: from demo.yaml', 'C failed',
                     "revision 2 planned: robot 'C' failed"]


def test_blocks_and_warnings_are_told_once_each():
    warning = "robot 'Z' is not in the scenario"
    facts = [plan(1, 0, [task('A', 'J1', 1, 2)]),
             status(1, MissionState.EXECUTING, 0, 1, warnings=[warning]),
             status(1.5, MissionState.EXECUTING, 0, 1, warnings=[warning]),
             status(2, MissionState.BLOCKED, 0, 1, blocked=["job 'J1' cannot be staffed"]),
             status(2.5, MissionState.BLOCKED, 0, 1, blocked=["job 'J1' cannot be staffed"])]
    lines = [i.text for i in story(history_of(facts).missions[MISSION])]
    assert lines[1:] == ["warning: robot 'Z' is not in the scenario",
                         "blocked: job 'J1' cannot be staffed"]


def test_missions_one_after_another_are_kept_apart():
    first = faulty_mission()
    second = [plan(1, 20, [task('A', 'K1', 21, 22)], mission='demo-2')]
    second += work(['A'], 'K1', 1, 21, 22)
    second = [type(f)(**{**f.__dict__, 'mission_id': 'demo-2'}) for f in second]
    second.append(status(23, MissionState.COMPLETE, 1, 1, mission='demo-2'))
    fleet = history_of(first + second)
    assert set(fleet.missions) == {MISSION, 'demo-2'}
    assert fleet.current().mission_id == 'demo-2'
    assert fleet.missions['demo-2'].counts().total == 1
    assert fleet.missions[MISSION].counts().total == 3


def test_duplicates_change_nothing():
    facts = faulty_mission()
    fleet = history_of(facts)
    version = fleet.missions[MISSION].version
    for fact in facts:
        if not hasattr(fact, 'mode'):
            assert not fleet.add(fact)
    assert fleet.missions[MISSION].version == version


@pytest.mark.parametrize('mode, job, expected', [
    (RobotMode.WORKING, 'J1', None),
    (RobotMode.TRAVELLING, '', None),
])
def test_activities_follow_the_state_changes(mode, job, expected):
    facts = [plan(1, 0, [task('A', 'J1', 1, 4)])]
    facts += heartbeats('A', 0, 1, mode=RobotMode.IDLE)
    facts += heartbeats('A', 1.2, 2, mode=mode, job=job)
    activities = history_of(facts).missions[MISSION].activities()
    assert [(a.mode, round(a.start, 6), a.end and round(a.end, 6)) for a in activities] == [
        (RobotMode.IDLE, 0.0, 1.2), (mode, 1.2, expected)]


def test_stamps_are_placed_on_the_schedule_clock():
    mission = history_of([plan(1, 0, [])]).missions[MISSION]
    assert mission.units(START + 7.5) == 7.5
    assert history_of([state('A', 1)]).missions[MISSION].units(START) is None
