"""The planner's view of execution, from reports, on the paper's instance."""

import contextlib
import math
import random
from fractions import Fraction

import pytest

from fjsp_planner.execution.replan import replan, residual_problem, simulated_state
from fjsp_planner.execution.tracking import ROBOT_EVENTS, EventKind, Ignored, MissionTracker
from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.problem import Job, Problem, Robot
from fjsp_planner.model.scenario import load_scenario, parse_scenario
from fjsp_planner.model.schedule import JobAssignment, Schedule
from fjsp_planner.model.validate import validate

from jig_scenarios import held_then_followed
from repo_paths import PAPER


@pytest.fixture(scope='module')
def planned():
    from fjsp_planner.solving.solve import solve

    problem = load_scenario(PAPER)
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
    assert f"job '{name}'" in late and '2.500 after its plan' in late


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
    assert validate(problem, executed) == [] and tracker.violations() == []
    assert executed.jobs[jig].start >= now and holder not in executed.jobs[jig].robots
    assert tracker.projected_makespan(0) == executed.makespan


def test_a_successor_that_followed_a_voided_jig_job_stays_valid():
    """A fails at 3, during L: T is voided (its hold is lost) and redone by B before L. M
    started after T's first completion, which it relied on: the mission is valid, though M
    ran before T's last one."""
    problem, first = held_then_followed()
    assert validate(problem, first) == []
    tracker = MissionTracker(problem)
    tracker.set_plan(first, 1)
    run_plan(tracker, first, until=3)
    tracker.record_robot_state('A', 'failed', '', '', float('nan'))
    tracker.record_event('abort', EventKind.ABORTED, 'A', 'L', 1, 3.0)
    outcome = replan(problem, first, tracker.execution_state(3), time_limit=5)
    assert outcome.residual.voided == ['T']
    tracker.set_plan(outcome.schedule, 2)
    run_plan(tracker, outcome.schedule, revision=2)
    assert tracker.complete
    executed = tracker.executed_schedule()
    assert executed.jobs['M'].start < executed.jobs['T'].end
    assert tracker.violations() == []


# --- no report ever raises ------------------------------------------------------------

def test_operation_done_without_started_is_classified_not_a_crash(planned):
    """A forged event, or a planner restarted mid-mission whose old event history arrives
    after its new plan, used to crash the planner (`Fraction(None)`)."""
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    name, a = min(schedule.jobs.items(), key=lambda kv: (kv[1].start, kv[0]))
    robot = next(iter(a.robots))
    outcome = tracker.record_event('x', EventKind.OPERATION_DONE, robot, name, 1, 5.0)
    assert outcome.ignored == Ignored.UNKNOWN
    assert outcome.reason == (f"event 'x': '{robot}' reports operation_done for job "
                              f"'{name}' without having reported started")
    assert tracker.ignored[Ignored.UNKNOWN] == 1
    assert name not in tracker.running | tracker.done


def test_planner_restart_history_arriving_after_the_new_plan(planned):
    """The restarted planner ignores the old STARTED events that come before its plan, then
    takes the OPERATION_DONE ones that follow it: none of them may raise, and no job is
    completed from half a history."""
    problem, schedule = planned
    tracker = MissionTracker(problem)
    history = []
    for name, a in sorted(schedule.jobs.items(), key=lambda kv: kv[1].start):
        for robot, q in a.robots.items():
            history.append((f'{robot}/{name}/started/1', EventKind.STARTED, robot, name, 1,
                            float(a.start)))
            history.append((f'{robot}/{name}/operation_done/1', EventKind.OPERATION_DONE,
                            robot, name, 1, float(a.start + problem.duration(robot, q))))
    for event in history[:len(history) // 2]:
        assert tracker.record_event(*event).ignored == Ignored.STALE
    tracker.set_plan(schedule, 1)
    for event in history[len(history) // 2:]:
        tracker.record_event(*event)
    assert tracker.ignored[Ignored.UNKNOWN] > 0          # operations done, never started
    seen = {name for _, kind, _, name, _, _ in history[len(history) // 2:]
            if kind == EventKind.STARTED}
    assert tracker.done and tracker.done <= seen
    # What it saw is a partial history: it may break precedence, but it must be said.
    assert all('is done but' in v for v in tracker.violations())
    tracker.execution_state(100.0)
    tracker.projected_makespan(100.0)


NAN, INF = float('nan'), float('inf')


@pytest.mark.parametrize(('kind', 'time', 'reason'), [
    (EventKind.STARTED, NAN, 'invalid time nan'),
    (EventKind.STARTED, INF, 'invalid time inf'),
    (EventKind.STARTED, -INF, 'invalid time -inf'),
    (EventKind.OPERATION_DONE, NAN, 'invalid time nan'),
    (EventKind.ARRIVED, -1.0, 'invalid time -1.0'),
    (EventKind.STARTED, None, 'invalid time None'),
    (EventKind.STARTED, 'soon', "invalid time 'soon'"),
    (EventKind.STARTED, True, 'invalid time True'),
    ('job_done', 1.0, "unknown event kind 'job_done'"),
    ('', 1.0, "unknown event kind ''"),
    (None, 1.0, 'unknown event kind None'),
])
def test_malformed_events_are_classified(planned, kind, time, reason):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    name, a = min(schedule.jobs.items(), key=lambda kv: (kv[1].start, kv[0]))
    outcome = tracker.record_event('x', kind, next(iter(a.robots)), name, 1, time)
    assert outcome.ignored == Ignored.UNKNOWN and reason in outcome.reason, outcome


def test_operation_done_before_its_start_is_classified(planned):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    name, a = min(schedule.jobs.items(), key=lambda kv: (kv[1].start, kv[0]))
    robot = next(iter(a.robots))
    tracker.record_event('s', EventKind.STARTED, robot, name, 1, 5.0)
    outcome = tracker.record_event('d', EventKind.OPERATION_DONE, robot, name, 1, 4.0)
    assert outcome.ignored == Ignored.UNKNOWN
    assert 'operation_done at t=4 before it started at t=5' in outcome.reason


@pytest.mark.parametrize(('args', 'reason'), [
    (('', EventKind.STARTED, '', 'M1', 1, 0.0), "unknown robot ''"),
    (('', EventKind.STARTED, 'LSMS', '', 1, 0.0), "unknown job ''"),
    (('x', EventKind.STARTED, None, 'M1', 1, 0.0), 'unknown robot None'),
    (('x', EventKind.STARTED, 'LSMS', ['M1'], 1, 0.0), "unknown job ['M1']"),
    (('x', EventKind.STARTED, 'LSMS', 'M1', NAN, 0.0), 'invalid plan revision nan'),
    (('x', EventKind.STARTED, 'LSMS', 'M1', None, 0.0), 'invalid plan revision None'),
    ((None, EventKind.STARTED, 'LSMS', 'M1', 1, 0.0), 'invalid event id None'),
])
def test_events_with_odd_fields_are_classified(planned, args, reason):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    outcome = tracker.record_event(*args)
    assert outcome.ignored == Ignored.UNKNOWN and reason in outcome.reason, outcome


def test_event_of_a_robot_the_plan_leaves_out_of_the_job(planned):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    name, a = min(schedule.jobs.items(), key=lambda kv: (kv[1].start, kv[0]))
    outsider = next(r.name for r in problem.robots if r.name not in a.robots)
    for kind in sorted(ROBOT_EVENTS):
        outcome = tracker.record_event(f'x/{kind}', kind, outsider, name, 1, 1.0)
        assert outcome.ignored == Ignored.UNKNOWN and 'has no part in' in outcome.reason
    assert name not in tracker.running and name not in tracker.aborted


@pytest.mark.parametrize(('state', 'reason'), [
    (('MARC1', 'idle', 'Nowhere', '', 0.0), "'MARC1' reports unknown location 'Nowhere'"),
    (('MARC1', 'travelling', 'M1', 'Mars', 3.0),
     "'MARC1' reports unknown destination 'Mars'"),
])
def test_robot_states_naming_unknown_places_are_ignored_once(planned, state, reason):
    problem, _ = planned
    tracker = MissionTracker(problem)
    first = tracker.record_robot_state(*state)
    again = tracker.record_robot_state(*state)
    assert first.ignored == again.ignored == Ignored.UNKNOWN and reason in first.reason
    assert (first.repeated, again.repeated) == (False, True)
    assert tracker.ignored[Ignored.UNKNOWN] == 1
    assert not tracker.robots['MARC1'].reported


@pytest.mark.parametrize('busy_until', [NAN, INF, -INF, None, 'later', 1e308])
def test_odd_busy_until_never_breaks_the_projections(planned, busy_until):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    name, a = min(schedule.jobs.items(), key=lambda kv: (kv[1].start, kv[0]))
    robot = next(iter(a.robots))
    tracker.record_event('s', EventKind.STARTED, robot, name, 1, 0.0)
    for mode in ('working', 'travelling'):
        assert tracker.record_robot_state(robot, mode, name, name, busy_until, name)
        tracker.overruns(1.0)
        tracker.projected_makespan(1.0)
        tracker.execution_state(1.0)


def test_heartbeat_loss_of_an_unknown_robot_is_classified(planned):
    problem, _ = planned
    tracker = MissionTracker(problem)
    outcome = tracker.mark_offline('R2D2')
    assert outcome.ignored == Ignored.UNKNOWN and "unknown robot 'R2D2'" in outcome.reason


def test_random_report_storms_never_raise(planned):
    """Property: whatever reports arrive, in whatever order, with whatever values, nothing
    the planner calls on the tracker raises, and re-planning from its state raises at most
    a `ValueError` naming what contradicts the plan (the planner blocks with it). Seeded, so
    a failure is reproducible."""
    problem, schedule = planned
    rng = random.Random(14)
    robots = [r.name for r in problem.robots] + ['', 'R2D2']
    jobs = list(schedule.jobs) + ['', 'Zz']
    times = [0.0, 1.0, 5.5, 17.25, 32.0, 1e6, 1e300, -1.0, NAN, INF]
    modes = ['idle', 'travelling', 'waiting', 'working', 'holding', 'failed', 'offline', '?']
    places = problem.locations() + ['']
    for _ in range(15):
        tracker = MissionTracker(problem)
        revision = 0
        for step in range(200):
            roll = rng.random()
            if roll < 0.03 or revision == 0:
                revision += 1
                tracker.set_plan(schedule, revision,
                                 continued=set(rng.sample(sorted(schedule.jobs), 3)))
            elif roll < 0.75:
                tracker.record_event(f'e{rng.randrange(400)}', rng.choice(list(EventKind)),
                                     rng.choice(robots), rng.choice(jobs),
                                     rng.choice([revision, revision - 1, revision + 1, 0]),
                                     rng.choice(times))
            elif roll < 0.95:
                tracker.record_robot_state(rng.choice(robots), rng.choice(modes),
                                           rng.choice(places), rng.choice(places),
                                           rng.choice(times), rng.choice(jobs),
                                           at=rng.choice(times[:6]))
            else:
                tracker.mark_offline(rng.choice(robots), at=rng.choice(times[:6]))
            now = rng.choice(times[:6])
            state = tracker.execution_state(now)
            if step % 10 == 0:
                with contextlib.suppress(ValueError):
                    residual_problem(problem, state, schedule)
            tracker.projected_makespan(now)
            tracker.overruns(1.0)
            tracker.failed_since(rng.randrange(revision + 2))
            if step % 50 == 0:
                tracker.violations()
                tracker.executed_schedule()


# --- the executed timeline is checked ---------------------------------------------------

def tiny_problem() -> Problem:
    """Locations a, b, c with a non-metric table: a-c is 10, but a-b-c only 2.

    J at a [hold]; W at a [hold, weld], after J, held from J with type 0; X at c [weld];
    one robot type, hold 2, weld 3, travel = distance; robots A, B free to start anywhere.
    """
    return Problem(
        operation_types={0: 'hold', 1: 'weld', 2: 'locomote'},
        robot_types={'Arm': {0: Fraction(2), 1: Fraction(3), 2: Fraction(1)}},
        robots=(Robot('A', 'Arm'), Robot('B', 'Arm')),
        jobs=(Job('J', 'a', ((0,),)), Job('W', 'a', ((0, 1),)), Job('X', 'c', ((1,),)),
              Job('Y', 'b', ((1,),))),
        distances={('a', 'b'): Fraction(1), ('b', 'c'): Fraction(1), ('a', 'c'): Fraction(10),
                   ('b', 'a'): Fraction(1), ('c', 'b'): Fraction(1), ('c', 'a'): Fraction(10)},
        precedence=(('J', 'W'),),
        holding=(('J', 'W', 0),),
        locomote=2,
        name='tiny')


def execute(tracker, jobs, revision=1):
    """Report each (job, start, {robot: end}) as executed; robots from the plan."""
    for name, start, ends in jobs:
        for robot, end in ends.items():
            for kind, time in ((EventKind.ARRIVED, start), (EventKind.STARTED, start),
                               (EventKind.OPERATION_DONE, end)):
                outcome = tracker.record_event(f'{robot}/{name}/{kind}/{revision}', kind,
                                               robot, name, revision, time)
                assert outcome.ignored is None, outcome


def sched(sequences, **jobs):
    return Schedule({name: JobAssignment(name, 0, Fraction(s), Fraction(e), robots)
                     for name, (s, e, robots) in jobs.items()}, sequences)


def test_a_valid_execution_has_no_violations():
    problem = tiny_problem()
    plan = sched({'A': ('J', 'W'), 'B': ('Y', 'W', 'X')},
                 J=(0, 2, {'A': 0}), Y=(0, 3, {'B': 1}), W=(4, 7, {'A': 0, 'B': 1}),
                 X=(9, 12, {'B': 1}))
    tracker = MissionTracker(problem)
    tracker.set_plan(plan, 1)
    execute(tracker, [('J', 0, {'A': 2}), ('Y', 0, {'B': 3}), ('W', 4, {'A': 6, 'B': 7})])
    assert tracker.violations() == []
    execute(tracker, [('X', 9, {'B': 12})])          # W (a) -> X (c): 10 direct, 2 via b
    assert tracker.complete and tracker.violations() == []


@pytest.mark.parametrize(('plan', 'executed', 'violation'), [
    (sched({'A': ('J', 'W'), 'B': ('W',)}, J=(0, 2, {'A': 0}), W=(1, 4, {'A': 0, 'B': 1})),
     [('J', 0, {'A': 2}), ('W', 1, {'A': 3, 'B': 4})],
     "robot 'A': job 'W' starts at 1, overlapping 'J' which ends at 2"),
    (sched({'A': ('J', 'W'), 'B': ('W',)}, J=(0, 2, {'A': 0}), W=(1, 4, {'A': 0, 'B': 1})),
     [('J', 0, {'A': 2}), ('W', 1, {'A': 3, 'B': 4})],
     "job 'W' starts at 1 before its predecessor 'J' completes at 2"),
    (sched({'A': ('J', 'Y', 'W'), 'B': ('W',)}, J=(0, 2, {'A': 0}), Y=(3, 6, {'A': 1}),
           W=(7, 10, {'A': 0, 'B': 1})),
     [('J', 0, {'A': 2}), ('Y', 3, {'A': 6}), ('W', 7, {'A': 9, 'B': 10})],
     "holding arc ('J', 'W', 0): robot 'A' does not go directly from 'J' to 'W'"),
    (sched({'A': ('J',), 'B': ('W',)}, J=(0, 2, {'A': 0}), W=(2, 5, {'B': 0, 'A': 1})),
     [('J', 0, {'A': 2}), ('W', 2, {'A': 5, 'B': 5})],
     "holding arc ('J', 'W', 0): type-0 robots of 'J' are ['A'] but of 'W' are ['B']"),
    (sched({'A': ('X', 'J'), 'B': ()}, X=(0, 3, {'A': 1}), J=(3.5, 5.5, {'A': 0})),
     [('X', 0, {'A': 3}), ('J', 3.5, {'A': 5.5})],
     "robot 'A': job 'J' starts at 3.500 but the robot ends 'X' at 3 and travels 2 from 'c' "
     "to 'a', arriving at 5"),
    (sched({'A': ('W',), 'B': ('W',)}, W=(0, 3, {'A': 0, 'B': 0})),
     [('W', 0, {'A': 2, 'B': 2})],
     "job 'W': its robots do operation types [0, 0] but plan 0 is [0, 1]"),
    (sched({'A': ('W',), 'B': ('W',)}, W=(0, 3, {'A': 0, 'B': 1})),
     [('W', 0, {'A': 2, 'B': 3})],
     "job 'W' is done but 'J', which must complete before it, is not"),
], ids=['robot on two jobs at once', 'precedence', 'hold not direct', 'holder swapped',
        'travel too fast even by the shortest route', 'plan not followed',
        'done before its predecessor'])
def test_violations_of_the_executed_timeline_are_named(plan, executed, violation):
    problem = tiny_problem()
    tracker = MissionTracker(problem)
    tracker.set_plan(plan, 1)
    execute(tracker, executed)
    violations = tracker.violations()
    assert violation in violations, violations


def test_the_paper_executed_as_planned_has_no_violations(planned):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    run_plan(tracker, schedule)
    assert tracker.complete and tracker.violations() == []


def test_moves_that_ran_short_of_their_time_are_no_violation(planned):
    """Seen with noisy simulated robots: LSMS moved M1 (a 'locomote' operation, as the paper
    has it) in 0.84 units instead of 1, and the mission FAILED on its executed timeline: an
    operation's duration is what its robot took, whatever its type; travel still counts."""
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    moves = {name for name, a in schedule.jobs.items()
             if set(a.robots.values()) == {problem.locomote}}
    assert moves
    for name, a in sorted(schedule.jobs.items(), key=lambda kv: kv[1].start):
        for robot in a.robots:
            for kind in (EventKind.ARRIVED, EventKind.STARTED):
                tracker.record_event(f'{robot}/{name}/{kind}', kind, robot, name, 1, a.start)
        for robot, q in a.robots.items():
            took = problem.duration(robot, q) * (Fraction(84, 100) if name in moves else 1)
            tracker.record_event(f'{robot}/{name}/done', EventKind.OPERATION_DONE, robot,
                                 name, 1, a.start + took)
    assert tracker.complete and tracker.violations() == []


# --- holds are lost once a holder failed, even if it came back --------------------------

def during_held_job(planned):
    """A tracker of the paper's plan run to the middle of its first held job, every robot
    reporting where it is; returns (tracker, jig, held, holders, now)."""
    problem, schedule = planned
    jig, held, q = problem.holding[0]
    holders = [r for r, t in schedule.jobs[jig].robots.items() if t == q]
    now = (schedule.jobs[held].start + schedule.jobs[held].end) / 2
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    run_plan(tracker, schedule, until=now)
    report_positions(tracker, problem, schedule, now)
    assert jig in tracker.done and held in tracker.running
    return tracker, jig, held, holders, float(now)


def test_a_hold_is_voided_when_its_holders_failed_and_recovered(planned):
    """Every robot of the held job failed while on it and came back before the re-plan: the
    parts they held were let go, so the jig job must be redone (the re-plan used to log
    `kept held: Ja` and finish Aa on a hold that was lost)."""
    problem, schedule = planned
    tracker, jig, held, holders, now = during_held_job(planned)
    robots = schedule.jobs[held].robots
    for robot in robots:
        tracker.record_robot_state(robot, 'failed', problem.job(held).location, '',
                                   float('nan'), at=now)
    tracker.record_event('abort', EventKind.ABORTED, holders[0], held, 1, now)
    back = now + 0.5
    for robot in robots:
        tracker.record_robot_state(robot, 'idle', problem.job(held).location, '',
                                   float('nan'), at=back)
    assert tracker.healthy == {r.name for r in problem.robots} and held in tracker.aborted
    state = tracker.execution_state(back)
    residual = residual_problem(problem, state, schedule)
    assert residual.voided == [jig] and residual.kept == []
    outcome = replan(problem, schedule, state, time_limit=5)
    assert outcome.problems == [] and jig in outcome.schedule.jobs
    assert outcome.schedule.jobs[jig].start >= back


def test_a_hold_survives_a_failure_before_the_jig_job_began(planned):
    problem, schedule = planned
    tracker, jig, held, holders, now = during_held_job(planned)
    before = float(schedule.jobs[jig].start) - 0.5
    assert before >= 0
    record = tracker.robots[holders[0]]
    mode = record.mode, record.location, record.destination, record.busy_until
    tracker.record_robot_state(holders[0], 'failed', '', '', float('nan'), at=before)
    tracker.record_robot_state(holders[0], *mode, record.current_job, at=before + 0.1)
    assert tracker.robots[holders[0]].failures == 1
    residual = residual_problem(problem, tracker.execution_state(now), schedule)
    assert residual.voided == [] and held in residual.problem.fixed


def test_a_failure_without_a_time_is_dated_by_the_latest_report(planned):
    """Without `at`, a failure is taken to have happened at the latest time any event
    reported (here, after the held job began), so the hold is lost and the held job, running
    on it, is redone."""
    problem, schedule = planned
    tracker, jig, held, holders, now = during_held_job(planned)
    tracker.mark_offline(holders[0])
    assert tracker.robots[holders[0]].last_failure_at >= schedule.jobs[held].start
    tracker.record_robot_state(holders[0], 'working', problem.job(held).location, '',
                               float('nan'), held)
    residual = residual_problem(problem, tracker.execution_state(now), schedule)
    assert residual.voided == [jig] and residual.aborted == [held]


# --- failures between two looks are not missed ------------------------------------------

def test_failures_are_counted_on_every_transition_to_unhealthy(planned):
    problem, _ = planned
    tracker = MissionTracker(problem)
    assert tracker.robots['MARC1'].failures == 0
    for mode in ('idle', 'failed', 'failed', 'idle', 'working', 'failed'):  # heartbeats repeat
        tracker.record_robot_state('MARC1', mode, 'M1', '', float('nan'), at=3.0)
    assert tracker.robots['MARC1'].failures == 2
    tracker.mark_offline('MARC1', at=4.0)                 # already unhealthy: no new failure
    assert tracker.robots['MARC1'].failures == 2
    tracker.record_robot_state('MARC1', 'idle', 'M1', '', float('nan'), at=5.0)
    tracker.mark_offline('MARC1', at=6.0)
    assert tracker.robots['MARC1'].failures == 3
    assert tracker.robots['MARC1'].last_failure_at == 6.0


def test_a_failure_and_recovery_within_one_planner_tick_are_seen(planned):
    """The planner compared healthy sets every 0.1 s, so a failure and a recovery in between
    went unnoticed while the recovered agent waited, its tasks dropped, for a revision."""
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.record_robot_state('LSMS', 'failed', 'M1', '', float('nan'), at=0.0)
    tracker.set_plan(schedule, 1)
    assert tracker.failed_since(1) == frozenset()
    assert tracker.failed_since(0) == {'LSMS'}               # before any plan
    tracker.record_robot_state('MARC2', 'failed', 'M1', '', float('nan'), at=2.0)
    tracker.record_robot_state('MARC2', 'idle', 'M1', '', float('nan'), at=2.1)
    assert tracker.healthy == {r.name for r in problem.robots} - {'LSMS'}
    assert tracker.failed_since(1) == {'MARC2'}
    tracker.set_plan(schedule, 2)
    assert tracker.failed_since(2) == frozenset() and tracker.failed_since(1) == {'MARC2'}


def test_a_robot_on_a_leg_or_stopped_on_one_is_placed_at_the_point_it_reached(planned):
    """MARC2 (speed 25, MARC locomotion 1) reports 37.5 % of its way from M1 to Ja; the
    planner places it at 37 % of that leg: at least as far as it got, never further."""
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    leg = problem.travel('MARC2', 'M1', 'Ja')
    tracker.record_robot_state('MARC2', 'travelling', 'M1', 'Ja', 10.0, 'Ja', progress=0.375)
    way = tracker.execution_state(5.0).robots['MARC2'].on_way
    assert (way.origin, way.destination, way.share) == ('M1', 'Ja', Fraction(37, 100))
    # Stopped there (a new plan no longer needed the leg): free at once, the leg's end the
    # rest of the leg away.
    tracker.record_robot_state('MARC2', 'idle', 'M1', 'Ja', math.nan, '', progress=0.375)
    stopped = tracker.execution_state(6.0).robots['MARC2']
    assert stopped.on_way == way
    assert (stopped.location, stopped.free_at) == ('Ja', 6 + Fraction(63, 100) * leg)
    # A progress out of [0, 1] says nothing: the robot is taken to drive on to the end.
    tracker.record_robot_state('MARC2', 'travelling', 'M1', 'Ja', 10.0, 'Ja', progress=1.5)
    assert tracker.execution_state(6.0).robots['MARC2'].on_way is None


def test_a_restarted_agent_that_reports_no_place_is_where_it_was(planned):
    """Found by the soak: the Assembler's agent was killed in panel 1 and started again; its
    new process reported no location, the re-plan placed it anywhere, sent it to a job of
    panel 2 without its 200-unit crossing, and the executed timeline failed the mission."""
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    last = max((a for a in schedule.jobs.values() if 'Assembler' in a.robots),
               key=lambda a: a.end)
    now = float(last.end)
    run_plan(tracker, schedule, until=now)
    place = problem.job(last.job).location
    tracker.record_robot_state('Assembler', 'idle', place, '', math.nan)
    tracker.record_robot_state('Assembler', 'idle', '', '', math.nan)  # a new agent process
    assert tracker.execution_state(now).robots['Assembler'].location == place
    # A planner restarted too knows the robot only from the jobs it did.
    resumed = MissionTracker(problem)
    resumed.set_plan(schedule, 1)
    for name in tracker.done:
        resumed.restore_done(tracker.jobs[name].done_as)
    resumed.record_robot_state('Assembler', 'idle', '', '', math.nan)
    assert resumed.execution_state(now).robots['Assembler'].location == place


# --- the projected makespan -------------------------------------------------------------

def test_the_projection_at_mission_start_is_the_plan(planned):
    problem, schedule = planned
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    assert tracker.projected_makespan(0) == schedule.makespan == 32


@pytest.mark.parametrize('seed', [3, 11, 27])
def test_robots_start_where_and_when_the_scenario_says(seed):
    """Robots placed away from their first job and released late: the plan waits for them,
    and so does the projection (it used to start every robot anywhere at 0)."""
    from fjsp_planner.solving.solve import solve

    problem = parse_scenario(random_scenario(seed, Shape(jobs=10, robots=5)))
    assert any(r.start_location for r in problem.robots)
    assert any(r.release_time > 0 for r in problem.robots)
    schedule = solve(problem, solver='greedy', time_limit=5).schedule
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    assert tracker.projected_makespan(0) == schedule.makespan


def delay_problem() -> Problem:
    """Places p and q, 4 apart; travel = distance. A starts at p, released at 1; B at q.

    J1 at p [hold] by A, 3;  J3 at q [inspect] by B, 9;  J2 at q [hold, weld] by A (hold, 3)
    and B (weld, 2), after J3's robot is free: the plan has J1 1-4, A driving 4-8 and waiting,
    J3 0-9, J2 9-12.
    """
    return Problem(
        operation_types={0: 'hold', 1: 'weld', 2: 'drive', 3: 'inspect'},
        robot_types={'Arm': {0: Fraction(3), 1: Fraction(2), 2: Fraction(1), 3: Fraction(9)}},
        robots=(Robot('A', 'Arm', start_location='p', release_time=Fraction(1)),
                Robot('B', 'Arm', start_location='q')),
        jobs=(Job('J1', 'p', ((0,),)), Job('J2', 'q', ((0, 1),)), Job('J3', 'q', ((3,),))),
        distances={('p', 'q'): Fraction(4), ('q', 'p'): Fraction(4)},
        locomote=2, name='delay')


def delay_plan() -> Schedule:
    return sched({'A': ('J1', 'J2'), 'B': ('J3', 'J2')}, J1=(1, 4, {'A': 0}),
                 J3=(0, 9, {'B': 3}), J2=(9, 12, {'A': 0, 'B': 1}))


def test_a_delay_costs_only_what_the_slack_does_not_absorb():
    """A's J1 runs 2 late (it expects to end at 6): A reaches q at 10, one after the 9 the
    plan waited for anyway, so J2 runs 10-13: the projection grows by 1, not 2."""
    problem, plan = delay_problem(), delay_plan()
    assert validate(problem, plan) == []
    tracker = MissionTracker(problem)
    tracker.set_plan(plan, 1)
    assert tracker.projected_makespan(0) == 12
    for robot, job, time in (('A', 'J1', 1.0), ('B', 'J3', 0.0)):
        for kind in (EventKind.ARRIVED, EventKind.STARTED):
            tracker.record_event(f'{robot}/{kind}', kind, robot, job, 1, time)
    tracker.record_robot_state('A', 'working', 'p', '', 4.0, 'J1')
    assert tracker.projected_makespan(2) == 12
    tracker.record_robot_state('A', 'working', 'p', '', 6.0, 'J1')
    assert tracker.expected_ends(2)['J1'] == 6
    assert tracker.projected_makespan(2) == 13


def test_a_robot_late_on_its_leg_is_waited_for():
    """A left p late and reports arriving at q at 11 instead of 8: J2 starts at 11."""
    problem, plan = delay_problem(), delay_plan()
    tracker = MissionTracker(problem)
    tracker.set_plan(plan, 1)
    execute(tracker, [('J1', 1, {'A': 4})])
    for kind in (EventKind.ARRIVED, EventKind.STARTED):
        tracker.record_event(f'B/{kind}', kind, 'B', 'J3', 1, 0.0)
    assert tracker.projected_makespan(5) == 12
    tracker.record_robot_state('A', 'travelling', 'p', 'q', 11.0)
    assert tracker.projected_makespan(5) == 14


@pytest.mark.parametrize(('panels', 'failure', 'least'), [
    (1, 12, 32),
    pytest.param(2, 40, Fraction(274, 3), marks=pytest.mark.slow),
], ids=['1 panel', '2 panels'])
def test_the_projection_never_reads_below_the_optimum_of_an_executed_mission(
        planned, panels, failure, least):
    """The paper's mission executed as planned, then with MARC1 failing and the rest executed
    as re-planned from where the robots were: at every moment the projection is the makespan
    of the plan being followed, so never below the least makespan possible (1 panel: the
    optimum, 32; 2 panels: the proven bound, 91 1/3). It read 80.9 on 2 panels after the
    re-plan, whose robots it started anywhere at 0. Reports carry times as floats, so a job
    done at 1729/6 counts as the float nearest it."""
    from fjsp_planner.solving.solve import solve

    problem, schedule = planned
    if panels > 1:
        problem = load_scenario(PAPER, panels=panels)
        schedule = solve(problem, time_limit=5).schedule
    tracker = MissionTracker(problem)
    tracker.set_plan(schedule, 1)
    for now in (Fraction(k, 4) for k in range(4 * failure + 1)):
        run_plan(tracker, schedule, until=now)
        report_positions(tracker, problem, schedule, now)
        assert tracker.projected_makespan(float(now)) == pytest.approx(schedule.makespan,
                                                                       abs=1e-9), now
        assert schedule.makespan >= least
    tracker.record_robot_state('MARC1', 'failed', '', '', math.nan, at=float(failure))
    for name in tracker.running:
        if 'MARC1' in schedule.jobs[name].robots:
            tracker.record_event('abort', EventKind.ABORTED, 'MARC1', name, 1, float(failure))
    outcome = replan(problem, schedule, tracker.execution_state(failure), time_limit=5)
    replanned = outcome.schedule
    tracker.set_plan(replanned, 2, continued=set(outcome.residual.problem.fixed))
    for now in (Fraction(k, 4) for k in range(4 * failure, 4 * int(replanned.makespan) + 8)):
        run_plan(tracker, replanned, until=now, revision=2)
        report_positions(tracker, outcome.residual.problem, replanned, now)
        assert tracker.projected_makespan(float(now)) == pytest.approx(replanned.makespan,
                                                                       abs=1e-9), now
        assert replanned.makespan >= least
    assert tracker.complete
