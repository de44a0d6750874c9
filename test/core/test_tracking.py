"""The planner's view of execution, from reports, on the paper's instance."""

from fractions import Fraction
from pathlib import Path

import pytest

from fjsp_planner.core.replan import replan, simulated_state
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


def run_plan(tracker: MissionTracker, schedule: Schedule, until=None, revision=1):
    """Report every job of the plan exactly as planned (up to jobs starting before `until`).

    Events of a job already started under an earlier revision (a continued one) are the
    duplicates an agent would never send again, so they are skipped. Times stay exact, as the
    agents' grid-rounded ones are for the validator.
    """
    done = []
    for name, a in sorted(schedule.jobs.items(), key=lambda kv: kv[1].start):
        if until is not None and a.start >= until:
            break
        record = tracker.jobs[name]
        if record.end is not None:
            continue
        for robot, q in a.robots.items():
            if robot not in record.started:
                for kind in (EventKind.ARRIVED, EventKind.STARTED):
                    tracker.record_event(f'{robot}/{name}/{kind}/{revision}', kind, robot,
                                         name, revision, a.start)
            end = a.start + tracker.problem.duration(robot, q)
            if until is None or end <= until:
                outcome = tracker.record_event(f'{robot}/{name}/operation_done/{revision}',
                                               EventKind.OPERATION_DONE, robot, name,
                                               revision, end)
                if outcome.job_done:
                    done.append(outcome.job_done)
    return done


def report_positions(tracker, problem, schedule, now):
    """Every robot reports where executing `schedule` as planned has brought it at `now`."""
    for name, robot in simulated_state(problem, schedule, Fraction(now)).robots.items():
        travelling = robot.free_at > now and not any(
            name in a.robots for a in schedule.jobs.values() if a.start <= now < a.end)
        tracker.record_robot_state(name, 'travelling' if travelling else 'idle', '',
                                   robot.location if travelling else '',
                                   float(robot.free_at), '')
        if not travelling:
            tracker.robots[name].location = robot.location or ''


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


def test_health_follows_reports_and_heartbeat_loss(planned):
    problem, _ = planned
    tracker = MissionTracker(problem)
    everyone = {r.name for r in problem.robots}
    assert tracker.healthy == everyone        # not reported yet: given its tasks when it joins
    tracker.record_robot_state('MARC1', 'failed', 'M1', '', float('nan'))
    tracker.mark_offline('LSMS')
    assert tracker.healthy == everyone - {'MARC1', 'LSMS'}
    tracker.record_robot_state('LSMS', 'idle', 'M1', '', float('nan'))
    assert tracker.healthy == everyone - {'MARC1'}


def test_a_restarted_job_forgets_what_was_reported_under_older_revisions(planned):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    first = sorted(schedule.jobs.items(), key=lambda kv: kv[1].start)
    restarted, kept = first[0][0], first[1][0]
    for name in (restarted, kept):
        robot = next(iter(schedule.jobs[name].robots))
        tracker.record_event(f'{robot}/{name}/started/1', EventKind.STARTED, robot, name, 1, 0.0)
    tracker.set_plan(schedule, 2, continued={kept})
    assert tracker.running == {kept}
    robot = next(iter(schedule.jobs[restarted].robots))
    late = tracker.record_event('late', EventKind.OPERATION_DONE, robot, restarted, 1, 3.0)
    assert late.ignored == Ignored.STALE and 'started' in late.reason
    again = tracker.record_event('again', EventKind.STARTED, robot, restarted, 2, 3.0)
    assert again.ignored is None and tracker.jobs[restarted].start == 3


def test_an_aborted_job_waits_for_a_new_revision(planned):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    name, a = min(schedule.jobs.items(), key=lambda kv: kv[1].start)
    robot = next(iter(a.robots))
    tracker.record_event('s', EventKind.STARTED, robot, name, 1, 0.0)
    tracker.record_event('x', EventKind.ABORTED, robot, name, 1, 1.0)
    assert tracker.aborted == {name} and name not in tracker.running
    late = tracker.record_event('d', EventKind.OPERATION_DONE, robot, name, 1, 2.0)
    assert late.ignored == Ignored.STALE and 'aborted' in late.reason
    tracker.set_plan(schedule, 2)
    assert not tracker.aborted


def test_only_a_reported_overrun_beyond_the_threshold_is_late(planned):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    name, a = min(schedule.jobs.items(), key=lambda kv: kv[1].start)
    robot, q = max(a.robots.items(), key=lambda rq: problem.duration(*rq))
    for r in a.robots:
        tracker.record_event(f'{r}/s', EventKind.STARTED, r, name, 1, float(a.start))
    end = float(a.start + problem.duration(robot, q))
    tracker.record_robot_state(robot, 'working', name, '', end + 1.5, name)
    assert tracker.overruns(2.0) == []
    tracker.record_robot_state(robot, 'working', name, '', end + 2.5, name)
    [late] = tracker.overruns(2.0)
    assert f"job '{name}'" in late and '2.50 after its plan' in late


def test_failure_replan_and_completion_give_a_valid_executed_timeline(planned):
    """A holder fails after its jig job is done and before the held job is: the jig job is
    voided and redone by the others, and the whole executed timeline is valid."""
    problem, schedule = planned
    jig, held, q = problem.holding[0]
    holder = next(r for r, t in schedule.jobs[jig].robots.items() if t == q)
    now = (schedule.jobs[jig].end + schedule.jobs[held].end) / 2
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    run_plan(tracker, schedule, until=now)
    report_positions(tracker, problem, schedule, now)
    tracker.record_robot_state(holder, 'failed', '', '', float('nan'))
    for name in tracker.running:
        if holder in schedule.jobs[name].robots:
            tracker.record_event('abort', EventKind.ABORTED, holder, name, 1, now)
    outcome = replan(problem, schedule, tracker.execution_state(now), time_limit=5)
    assert outcome.residual.voided == [jig]
    assert outcome.problems == [] and outcome.schedule is not None
    assert not any(holder in a.robots for a in outcome.schedule.jobs.values())
    tracker.set_plan(outcome.schedule, 2, continued=set(outcome.residual.problem.fixed))
    run_plan(tracker, outcome.schedule, revision=2)
    assert tracker.complete and not tracker.ignored
    executed = tracker.executed_schedule()
    assert sorted(executed.jobs) == sorted(j.name for j in problem.jobs)
    assert validate(problem, executed) == []
    assert executed.jobs[jig].start >= now and holder not in executed.jobs[jig].robots
    assert tracker.projected_makespan(0) == executed.makespan
