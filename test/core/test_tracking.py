"""The planner's view of execution, from reports, on the paper's instance."""

from fractions import Fraction
from pathlib import Path

import pytest

from fjsp_planner.core.scenario import load_scenario
from fjsp_planner.core.schedule import Schedule
from fjsp_planner.core.tracking import EventKind, Ignored, MissionTracker
from fjsp_planner.core.validate import validate

SCENARIO = Path(__file__).resolve().parents[2] / 'config' / 'scenarios' / 'solar_panel.yaml'


@pytest.fixture(scope='module')
def planned():
    from fjsp_planner.core.solve import solve

    problem = load_scenario(SCENARIO)
    return problem, solve(problem, time_limit=10).schedule


def run_plan(tracker: MissionTracker, schedule: Schedule, until=None):
    """Report every job of the plan exactly as planned (up to jobs starting before `until`)."""
    done = []
    for name, a in sorted(schedule.jobs.items(), key=lambda kv: kv[1].start):
        if until is not None and a.start >= until:
            break
        for robot, q in a.robots.items():
            for kind, t in ((EventKind.ARRIVED, a.start), (EventKind.STARTED, a.start)):
                tracker.record_event(f'{robot}/{name}/{kind}/1', kind, robot, name, 1, float(t))
            end = a.start + tracker.problem.duration(robot, q)
            if until is None or end <= until:
                outcome = tracker.record_event(f'{robot}/{name}/operation_done/1',
                                               EventKind.OPERATION_DONE, robot, name, 1,
                                               float(end))
                if outcome.job_done:
                    done.append(outcome.job_done)
    return done


def test_planned_execution_completes_and_validates(planned):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    done = run_plan(tracker, schedule)
    assert sorted(job for job, _ in done) == sorted(schedule.jobs)
    assert tracker.complete and not tracker.ignored
    executed = tracker.executed_schedule()
    assert validate(problem, executed) == []
    assert tracker.projected_makespan(100) == schedule.makespan


def test_execution_state_mid_mission(planned):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    run_plan(tracker, schedule, until=10)
    state = tracker.execution_state(10.0)
    assert state.now == 10
    assert state.done == frozenset(j for j, a in schedule.jobs.items() if a.end <= 10)
    for job, a in state.running.items():
        assert a.start == schedule.jobs[job].start and a.end == schedule.jobs[job].end
        for robot in a.robots:
            assert state.robots[robot].free_at == a.end
    assert set(state.robots) == {r.name for r in problem.robots}


@pytest.mark.parametrize(('event', 'ignored', 'reason'), [
    (('x', EventKind.STARTED, 'R2D2', 'M1', 1, 0.0), Ignored.UNKNOWN, "unknown robot 'R2D2'"),
    (('x', EventKind.STARTED, 'LSMS', 'Zz', 1, 0.0), Ignored.UNKNOWN, "unknown job 'Zz'"),
    (('x', EventKind.STARTED, 'LSMS', 'M1', 7, 0.0), Ignored.UNKNOWN, 'never published'),
    (('x', EventKind.STARTED, 'LSMS', 'M1', 1, -1.0), Ignored.UNKNOWN, 'invalid time'),
])
def test_unusable_events_are_classified(planned, event, ignored, reason):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    outcome = tracker.record_event(*event)
    assert outcome.ignored == ignored and reason in outcome.reason
    assert tracker.ignored[ignored] == 1


def test_duplicates_are_ignored(planned):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    robot = next(iter(schedule.jobs['M1'].robots))
    assert tracker.record_event('a', EventKind.STARTED, robot, 'M1', 1, 0.0).ignored is None
    assert tracker.record_event('a', EventKind.STARTED, robot, 'M1', 1, 0.0).ignored \
        == Ignored.DUPLICATE
    assert tracker.record_event('b', EventKind.STARTED, robot, 'M1', 1, 0.0).ignored \
        == Ignored.DUPLICATE
    assert tracker.jobs['M1'].start == Fraction(0)


def test_unknown_robot_heartbeats_count_once(planned):
    problem, _ = planned
    tracker = MissionTracker(problem)
    first = tracker.record_robot_state('R2D2', 'idle', '', '', 0.0)
    again = tracker.record_robot_state('R2D2', 'idle', '', '', 0.0)
    assert first.ignored == again.ignored == Ignored.UNKNOWN
    assert (first.repeated, again.repeated) == (False, True)
    assert tracker.ignored[Ignored.UNKNOWN] == 1
