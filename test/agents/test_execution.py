"""The agents' ROS-free execution logic, on hand-checkable two-robot sequences."""

import math

import pytest

from fjsp_common.vocabulary import EventKind, RobotMode
from robot_agents.drivers import later
from robot_agents.execution import RobotExecution, Task

ARRIVED, STARTED, DONE, ABORTED = (EventKind.ARRIVED, EventKind.STARTED,
                                   EventKind.OPERATION_DONE, EventKind.ABORTED)


def task(job, start, duration, end=None, leg=0.0, co=(), preds=(), held=False, location=None,
         arrival=None):
    arrival = start if arrival is None else arrival
    return Task(job=job, operation_type=0, location=location or job, travel_start=arrival - leg,
                arrival=arrival, start=start, operation_end=start + duration,
                end=end if end is not None else start + duration, co_workers=tuple(co),
                predecessors=tuple(preds), held_into_next=held)


def plan(r, revision, tasks, job_robots=None, now=0.0, continued=(), restarted_in=None):
    """Give robot `r` a revision; by default it does every job alone, and a continued job
    was last started afresh in revision 1."""
    job_robots = job_robots if job_robots is not None else {t.job: {r.robot} for t in tasks}
    if restarted_in is None:
        restarted_in = {job: revision if job not in continued else 1 for job in job_robots}
    r.set_plan(revision, tasks, job_robots, now, restarted_in=restarted_in)


def kinds(events):
    return [(e.kind, e.job, round(e.time, 4)) for e in events]


def attempts(events):
    return [(e.kind, e.job, e.attempt) for e in events]


def test_solo_sequence_travels_and_works_in_logical_time():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 2), task('J2', 5, 1, leg=3)])
    assert kinds(r.step(0)) == [(ARRIVED, 'J1', 0), (STARTED, 'J1', 0)]
    assert r.mode == RobotMode.WORKING and r.progress(1) == pytest.approx(0.5)
    # Stepping late (at 10) still reports the instants the work was due at.
    assert kinds(r.step(10)) == [(DONE, 'J1', 2), (ARRIVED, 'J2', 5), (STARTED, 'J2', 5),
                                 (DONE, 'J2', 6)]
    assert r.finished and r.mode == RobotMode.IDLE and r.location == 'J2'


def test_job_waits_for_co_workers_and_predecessors():
    r = RobotExecution('A')
    plan(r, 1, [task('J2', 4, 1, co=['B'], preds=['J1'], arrival=0)],
         {'J1': {'B'}, 'J2': {'A', 'B'}})
    assert kinds(r.step(3)) == [(ARRIVED, 'J2', 0)]
    assert r.mode == RobotMode.WAITING
    r.operation_done('B', 'J1', 3.0, 1)   # J1's only robot is done
    r.job_done('J1', 3.0, 1)              # and the planner declares J1 complete at 3
    assert r.step(3.5) == []              # B has not arrived yet
    r.arrived('B', 'J2', 3.25, 1)
    assert kinds(r.step(3.5)) == [(STARTED, 'J2', 3.25)]
    assert r.step(4.2) == []
    assert kinds(r.step(4.3)) == [(DONE, 'J2', 4.25)]
    assert r.mode == RobotMode.WAITING         # occupied until B's operation ends too
    r.job_done('J2', 6.0, 1)
    r.step(6.0)
    assert r.finished


def test_a_completion_only_a_peer_reported_does_not_start_a_job():
    """Seen in the soak test: D hauled J1 (the only robot on it) and reported it done, then
    was killed before those reports reached the planner, which declared D offline and had J1
    hauled again much later. A, whose J2 follows J1, had heard D's report and started J2 at
    once: the planner's record then had J2 starting before J1 ended, and failed the
    mission. A waits for the planner to declare J1 done, and starts J2 at J1's end."""
    r = RobotExecution('A')
    plan(r, 1, [task('J2', 4, 1, preds=['J1'], arrival=0)], {'J1': {'D'}, 'J2': {'A'}})
    assert kinds(r.step(3)) == [(ARRIVED, 'J2', 0)]
    r.operation_done('D', 'J1', 3.0, 1)
    assert r.step(20) == [] and r.mode == RobotMode.WAITING
    r.job_done('J1', 3.0, 1)
    assert kinds(r.step(20)) == [(STARTED, 'J2', 3.0), (DONE, 'J2', 4.0)]


def test_a_robot_goes_on_from_its_own_job_without_the_planner():
    """Where A took part in the predecessor, its robots' reports are enough (A goes on with
    the plan while the planner is cut off): J2 starts when A and B are both done with J1."""
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 1, end=2, co=['B']), task('J2', 2, 1, preds=['J1'])],
         {'J1': {'A', 'B'}, 'J2': {'A'}})
    r.arrived('B', 'J1', 0.0, 1)
    assert kinds(r.step(1.5)) == [(ARRIVED, 'J1', 0), (STARTED, 'J1', 0), (DONE, 'J1', 1)]
    r.operation_done('B', 'J1', 2.0, 1)
    assert kinds(r.step(3.5)) == [(ARRIVED, 'J2', 2), (STARTED, 'J2', 2), (DONE, 'J2', 3)]


def holder(leg=2.0):
    """A holds jig job Ja (with B) into Aa, `leg` units away: Ja's operations end at 1 (A)
    and 5 (B), and Aa is planned to start once the part is carried there."""
    r = RobotExecution('A')
    plan(r, 1, [task('Ja', 0, 1, end=5, co=['B'], held=True),
                task('Aa', 5 + leg, 5, co=['B'], preds=['Ja'], leg=leg,
                     location='Aa' if leg else 'Ja')],
         {'Ja': {'A', 'B'}, 'Aa': {'A', 'B'}})
    r.arrived('B', 'Ja', 0.0, 1)
    return r


def test_holder_carries_the_part_along_its_leg_into_the_next_job():
    r = holder(leg=2.0)
    r.step(2)
    assert r.mode == RobotMode.HOLDING and r.current_job == 'Ja'
    r.operation_done('B', 'Ja', 5.0, 1)
    assert r.step(6) == []                               # on its way, part in hand
    assert r.mode == RobotMode.TRAVELLING and r.destination == 'Aa'
    assert r.busy_until == pytest.approx(7)
    assert kinds(r.step(7.1)) == [(ARRIVED, 'Aa', 7)]    # the leg took its travel time
    assert r.mode == RobotMode.HOLDING and r.current_job == 'Aa' and r.location == 'Aa'


def test_holder_whose_next_job_is_at_the_same_place_goes_straight_on():
    r = holder(leg=0.0)
    r.step(2)
    r.operation_done('B', 'Ja', 5.0, 1)
    assert kinds(r.step(5)) == [(ARRIVED, 'Aa', 5)]
    assert r.mode == RobotMode.HOLDING and r.current_job == 'Aa'


def test_a_robot_already_at_its_next_jobs_place_does_not_travel_there_again():
    # Revision 1 sends A from J1 to J2 (3 units); revision 2, at 2, drops J2 and plans J3
    # at J2's place with the leg from J1 it would take had A not set off. A ends its leg at
    # 4, where J3 is: it has no way left to go.
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 1), task('J2', 4, 1, leg=3)])
    r.step(2)
    assert r.mode == RobotMode.TRAVELLING
    plan(r, 2, [task('J3', 5, 1, leg=3, location='J2')], now=2)
    assert kinds(r.step(4.5)) == [(ARRIVED, 'J3', 4), (STARTED, 'J3', 4)]


def test_stale_revision_is_refused():
    r = RobotExecution('A')
    plan(r, 2, [task('J1', 0, 1)])
    with pytest.raises(ValueError, match='revision 1 is not newer than revision 2'):
        plan(r, 1, [])


def test_late_joiner_cannot_act_before_it_got_the_plan():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 1)], now=7.0)
    assert kinds(r.step(7.0)) == [(ARRIVED, 'J1', 7), (STARTED, 'J1', 7)]


def test_later_revision_cannot_make_an_idle_robot_depart_in_the_past():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 5)])
    r.step(6)
    assert r.finished                     # idle at J1 since 5
    plan(r, 2, [task('J2', 8, 1, leg=3)], now=10.0)
    assert kinds(r.step(20)) == [(ARRIVED, 'J2', 13), (STARTED, 'J2', 13), (DONE, 'J2', 14)]


# --- faults ---------------------------------------------------------------------------

def test_fail_while_working_aborts_and_stops_until_recovered_and_replanned():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 4), task('J2', 4, 1)])
    r.step(1)
    result = r.fail(2.5)
    assert result.accepted and "robot 'A' failed at t=2.50" in result.message
    assert kinds(result.events) == [(ABORTED, 'J1', 2.5)]
    assert result.events[0].attempt == 1 and result.events[0].reason == "robot 'A' failed"
    assert r.mode == RobotMode.FAILED and r.current_job == '' and math.isnan(r.busy_until)
    assert r.step(10) == []
    again = r.fail(3)
    assert not again.accepted and again.message == "fail refused: robot 'A' has already failed"
    assert not r.delay(2.0, 3).accepted
    plan(r, 2, [task('J2', 11, 1)], now=5)     # taken, but not acted on while failed
    assert r.revision == 2 and r.step(12) == [] and r.mode == RobotMode.FAILED

    result = r.recover(6)
    assert result.accepted and "recovered at t=6.00 at 'J1'" in result.message
    assert r.step(6) == [] and r.mode == RobotMode.IDLE and r.location == 'J1'   # tasks dropped
    assert r.recover(7).message == "recover refused: robot 'A' has not failed"
    plan(r, 3, [task('J1', 7, 4), task('J2', 11, 1)], now=7)  # J1 is redone
    assert attempts(r.step(7)) == [(ARRIVED, 'J1', 2), (STARTED, 'J1', 2)]
    assert kinds(r.step(20)) == [(DONE, 'J1', 11), (ARRIVED, 'J2', 11), (STARTED, 'J2', 11),
                                 (DONE, 'J2', 12)]


def test_fail_mid_leg_stops_it_there_and_it_recovers_there():
    r = RobotExecution('A')
    plan(r, 1, [task('J0', 0, 1), task('J1', 5, 1, leg=4)])
    r.step(3)                              # left J0 at 1, due at J1 at 5
    assert r.mode == RobotMode.TRAVELLING and r.progress(3) == pytest.approx(0.5)
    result = r.fail(3)
    assert result.accepted and result.events == []
    assert "from 'J0' to 'J1' (50% done)" in result.message
    assert (r.mode, r.location, r.destination) == (RobotMode.FAILED, 'J0', 'J1')
    assert r.progress(9) == pytest.approx(0.5)
    assert r.step(100) == []

    result = r.recover(10)
    assert "on its way from 'J0' to 'J1' (50% done)" in result.message
    assert r.step(100) == []               # it waits where it stopped for a new plan
    assert (r.mode, r.current_job, r.location, r.destination) == (
        RobotMode.IDLE, '', 'J0', 'J1')
    assert r.progress(100) == pytest.approx(0.5) and math.isnan(r.busy_until)
    # The planner sends it on to J1 from there: the 2 units of the leg that are left.
    plan(r, 2, [task('J1', 102, 1, leg=2)], now=100)
    assert r.step(101.9) == [] and r.busy_until == pytest.approx(102)
    # Its first attempt at J1 began with the leg, so this arrival is its second.
    assert attempts(r.step(102.1)) == [(ARRIVED, 'J1', 2), (STARTED, 'J1', 2)]


def test_a_plan_placing_a_stopped_robot_nearer_than_it_is_does_not_make_it_arrive_sooner():
    """A plan made before the planner heard where the robot stopped may give it a shorter
    leg than what is left of the one it stopped on: it takes what is left."""
    r = RobotExecution('A')
    plan(r, 1, [task('J0', 0, 1), task('J1', 5, 1, leg=4)])
    r.fail(2)                              # a quarter of the way: 3 units left to J1
    r.recover(2)
    plan(r, 2, [task('J1', 3, 1, leg=1)], now=2)
    assert r.step(4.9) == [] and r.busy_until == pytest.approx(5)
    assert kinds(r.step(5.1)) == [(ARRIVED, 'J1', 5), (STARTED, 'J1', 5)]


def test_fail_while_holding_releases_the_hold():
    r = holder()
    r.operation_done('B', 'Ja', 5.0, 1)
    r.step(7.5)
    assert r.mode == RobotMode.HOLDING and r.current_job == 'Aa'
    result = r.fail(7.5)
    # It withdraws from Aa, where it held Ja's part waiting for B: B must not start Aa
    # with it.
    assert result.accepted and kinds(result.events) == [(ABORTED, 'Aa', 7.5)]
    assert r.mode == RobotMode.FAILED
    # The planner voids Ja (its holder failed) and gives A nothing while it is down.
    plan(r, 2, [], {'Ja': {'B'}, 'Aa': {'B'}}, now=7.75)
    r.recover(8)
    assert r.mode == RobotMode.IDLE and r.location == 'Aa'
    # Ja is redone under revision 3: no longer held, so A travels there.
    plan(r, 3, [task('Ja', 11, 1, leg=3)], now=8)
    assert kinds(r.step(11.1)) == [(ARRIVED, 'Ja', 11), (STARTED, 'Ja', 11)]


def test_delay_of_the_operation_under_way():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 4)])
    r.step(1)
    result = r.delay(2.0, 1)
    assert result.accepted and "job 'J1' now ends at t=8.00" in result.message
    assert r.busy_until == pytest.approx(8) and r.progress(4) == pytest.approx(0.5)
    assert r.step(7.9) == []
    assert kinds(r.step(8.1)) == [(DONE, 'J1', 8)]


def test_speed_up_cannot_end_the_operation_before_it_was_ordered():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 4)])
    r.step(3)
    assert r.delay(0.5, 3).accepted        # 0 + 4 * 0.5 = 2 is already past
    assert r.busy_until == pytest.approx(3)


def test_delay_of_the_next_operation():
    r = RobotExecution('A')
    plan(r, 1, [task('J0', 0, 1), task('J1', 3, 4, leg=2), task('J2', 7, 2)])
    r.step(2)
    assert r.mode == RobotMode.TRAVELLING       # left J0 at 1, due at J1 at 3
    result = r.delay(3.0, 2)
    assert result.accepted and 'next operation it begins takes 3 times' in result.message
    assert r.busy_until == pytest.approx(3)   # the leg is not slowed
    assert kinds(r.step(3.1)) == [(ARRIVED, 'J1', 3), (STARTED, 'J1', 3)]
    assert r.busy_until == pytest.approx(15)  # 3 + 4 * 3
    assert kinds(r.step(20)) == [(DONE, 'J1', 15), (ARRIVED, 'J2', 15), (STARTED, 'J2', 15),
                                 (DONE, 'J2', 17)]   # only one operation slowed


BOUNDS = 'a delay factor must be within [0.001, 1000]'


@pytest.mark.parametrize(('factor', 'why'), [
    (0.0, f'{BOUNDS}, got 0'),
    (-2.0, f'{BOUNDS}, got -2'),
    (math.nan, f'{BOUNDS}, got nan'),
    (math.inf, f'{BOUNDS}, got inf'),
    (1e306, f'{BOUNDS}, got 1e+306'),          # killed the agent with an OverflowError
    (1e-200, f'{BOUNDS}, got 1e-200'),
    (1000.5, f'{BOUNDS}, got 1000.5'),
])
def test_delay_refuses_bad_factors(factor, why):
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 4)])
    r.step(1)
    result = r.delay(factor, 1)
    assert not result.accepted and result.message == f"delay refused: robot 'A' {why}"
    assert r.busy_until == pytest.approx(4)


@pytest.mark.parametrize(('first', 'second', 'product'), [
    (1e2, 1e2, '10000'), (0.02, 0.02, '0.0004'), (1e3, 1e3, '1e+06')])
def test_compounded_delays_are_bounded_too(first, second, product):
    """Two delays of 1e200 used to be accepted ("inf times its duration") and crash later;
    two of 1e-200 compounded to 0: the product of the factors on one operation is bounded
    like each factor."""
    for now in (1, 0):       # while working on the operation, and before beginning it
        r = RobotExecution('A')
        plan(r, 1, [task('J1', 2, 4, leg=1), task('J2', 6, 4)])
        r.step(now)
        assert r.delay(first, now).accepted
        ends = r.busy_until
        result = r.delay(second, now)
        assert not result.accepted
        assert result.message == (f"delay refused: robot 'A' would make its operation take "
                                  f'{product} times its duration; the factors on one '
                                  'operation must multiply to within [0.001, 1000]')
        assert r.busy_until == ends or (math.isnan(ends) and math.isnan(r.busy_until))


def test_extreme_but_allowed_delays_run_to_the_end():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 1e6)])
    r.step(1)
    assert r.delay(1000, 1).accepted
    assert r.busy_until == pytest.approx(1e9)
    assert kinds(r.step(2e9)) == [(DONE, 'J1', 1e9)]


@pytest.mark.parametrize('t', [0.0, 1.5, 1e6, 1e9, 1e300, 1e306, math.inf, -math.inf,
                               math.nan])
def test_later_never_raises_nor_goes_back(t):
    value = later(t)
    if t <= 1e9:
        assert t + 0.5e-6 <= value <= t + 1.6e-6     # half a grid step to one and a half
    elif math.isfinite(t):
        assert value >= t
    else:
        assert value == t or (math.isnan(value) and math.isnan(t))


def test_delay_refused_when_nothing_is_left_to_do():
    r = RobotExecution('A')
    assert r.delay(2.0, 0).message == "delay refused: robot 'A' has no operation left to do"
    plan(r, 1, [task('J1', 0, 4, end=6, co=['B'])], {'J1': {'A', 'B'}})
    r.arrived('B', 'J1', 0.0, 1)
    result = r.delay(2.0, 5)               # catches up first: its operation ended at 4
    assert not result.accepted and 'no operation left' in result.message
    assert kinds(result.events) == [(ARRIVED, 'J1', 0), (STARTED, 'J1', 0), (DONE, 'J1', 4)]


# --- revisions: continued and restarted jobs --------------------------------------------

def test_restarted_job_drops_stale_facts_and_ignores_late_ones():
    r = RobotExecution('A')
    jobs = {'J1': {'B'}, 'J2': {'A', 'B'}}
    plan(r, 1, [task('J2', 0, 2, co=['B'], preds=['J1'])], jobs)
    r.step(0)
    r.arrived('B', 'J2', 1.0, 1)
    r.job_done('J1', 2.0, 1)
    # Revision 2 restarts J2 (not continued); J1 is done and no longer in the plan.
    plan(r, 2, [task('J2', 4, 2, co=['B'], preds=['J1'])], {'J2': {'A', 'B'}}, now=3)
    assert attempts(r.step(3)) == [(ARRIVED, 'J2', 2)]
    assert r.mode == RobotMode.WAITING          # B's arrival of revision 1 no longer counts
    assert not r.arrived('B', 'J2', 1.0, 1)   # a late report of revision 1 is ignored
    assert r.step(5) == []
    assert r.arrived('B', 'J2', 4.0, 2)
    assert kinds(r.step(5)) == [(STARTED, 'J2', 4)]   # J1's completion still counts


def test_a_missed_revision_that_restarted_a_job_still_voids_its_old_facts():
    r = RobotExecution('A')
    jobs = {'J2': {'A', 'B'}}
    plan(r, 1, [task('J2', 0, 2, co=['B'])], jobs)
    r.step(0)
    r.arrived('B', 'J2', 1.0, 1)
    # A never got revision 2, which restarted J2; revision 3 keeps J2 as revision 2 had it.
    plan(r, 3, [task('J2', 4, 2, co=['B'])], jobs, now=3, continued={'J2'},
         restarted_in={'J2': 2})
    assert attempts(r.step(3)) == [(ARRIVED, 'J2', 2)]   # A redoes its part of J2
    assert r.mode == RobotMode.WAITING          # B's arrival of revision 1 no longer counts
    assert not r.arrived('B', 'J2', 1.5, 1)   # nor does a late one
    assert r.step(5) == []
    assert r.arrived('B', 'J2', 4.0, 2)
    assert kinds(r.step(5)) == [(STARTED, 'J2', 4)]


def test_report_of_the_new_revision_before_this_robot_follows_it():
    r = RobotExecution('A')
    plan(r, 1, [task('J2', 0, 2, co=['B'])], {'J2': {'A', 'B'}})
    r.step(0)
    r.arrived('B', 'J2', 1.0, 1)
    r.arrived('B', 'J2', 3.5, 2)           # B follows revision 2 already
    plan(r, 2, [task('J2', 4, 2, co=['B'])], {'J2': {'A', 'B'}}, now=4)
    assert kinds(r.step(4)) == [(ARRIVED, 'J2', 4), (STARTED, 'J2', 4)]


def test_continued_job_goes_on_and_restarted_one_is_abandoned():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 4), task('J2', 4, 1)])
    r.step(1)
    plan(r, 2, [task('J1', 0, 4), task('J3', 4, 1)], now=1, continued={'J1'})
    assert r.mode == RobotMode.WORKING and r.current_job == 'J1'
    assert r.busy_until == pytest.approx(4)
    # Revision 3 restarts J1: A leaves it without an event, free now, and comes back to it.
    plan(r, 3, [task('J1', 2, 4), task('J3', 6, 1)], now=2)
    assert attempts(r.step(2)) == [(ARRIVED, 'J1', 2), (STARTED, 'J1', 2)]
    assert kinds(r.step(10)) == [(DONE, 'J1', 6), (ARRIVED, 'J3', 6), (STARTED, 'J3', 6),
                                 (DONE, 'J3', 7)]


def test_job_left_out_of_the_new_plan_is_abandoned_without_an_event():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 4)])
    r.step(1)
    plan(r, 2, [task('J3', 2, 1)], now=2)
    assert kinds(r.step(2)) == [(ARRIVED, 'J3', 2), (STARTED, 'J3', 2)]


def test_continued_job_that_is_not_first_is_not_continued():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 4)])
    r.step(1)
    plan(r, 2, [task('J0', 2, 1), task('J1', 3, 4)], now=2, continued={'J1'})
    assert kinds(r.step(2)) == [(ARRIVED, 'J0', 2), (STARTED, 'J0', 2)]
    assert attempts(r.step(3.1)) == [(DONE, 'J0', 1), (ARRIVED, 'J1', 2), (STARTED, 'J1', 2)]


def test_continued_job_starts_no_earlier_than_a_predecessor_done_before_the_revision():
    """A waits at J2 from 2 for J1 (B's, due to end at 2 and reported done at 2.000002, its
    end rounded up onto the report grid). Revision 2, planned once J1 was done, leaves J1
    out but still names it a predecessor of J2, which goes on: J2 starts when J1 ended, not
    when A arrived (a planner restarted mid-mission found the start 2 before 2.000002)."""
    r = RobotExecution('A')
    plan(r, 1, [task('J2', 2, 5, preds=['J1'])], {'J1': {'B'}, 'J2': {'A'}})
    assert kinds(r.step(2)) == [(ARRIVED, 'J2', 2)]
    r.operation_done('B', 'J1', 2.000002, 1)
    plan(r, 2, [task('J2', 3, 5, preds=['J1'])], {'J2': {'A'}}, now=3, continued={'J2'})
    assert [(e.kind, e.job, e.time) for e in r.step(3)] == [(STARTED, 'J2', 2.000002)]


def test_a_predecessor_done_before_the_revision_and_never_heard_of_does_not_hold_a_job():
    """An agent started after J1 was declared done knows no report of it: the revision
    leaves J1 out, so it is complete, and J2 starts when its robots are there."""
    r = RobotExecution('A')
    plan(r, 2, [task('J2', 3, 5, preds=['J1'])], {'J2': {'A'}}, now=3)
    assert kinds(r.step(3)) == [(ARRIVED, 'J2', 3), (STARTED, 'J2', 3)]


def test_a_leg_no_task_needs_is_stopped_where_the_robot_is():
    """Found in a mission: a recovered crane, sent elsewhere by the new plan, first drove
    to the end of a 183-unit leg no task needed any more. It stops, and leaves from there
    with the leg the plan gives it, which the planner reckoned from that point."""
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 1), task('J2', 5, 1, leg=4)])
    r.step(2)                              # on its way to J2 since 1, a quarter done
    plan(r, 2, [task('J3', 5, 1, leg=3)], now=2)
    assert (r.mode, r.current_job, r.location, r.destination) == (
        RobotMode.IDLE, '', 'J1', 'J2')
    assert r.progress(2) == pytest.approx(0.25, abs=1e-6)
    assert r.step(2) == []
    assert (r.mode, r.location, r.destination) == (RobotMode.TRAVELLING, 'J1', 'J3')
    assert r.busy_until == pytest.approx(5)
    assert kinds(r.step(10)) == [(ARRIVED, 'J3', 5), (STARTED, 'J3', 5), (DONE, 'J3', 6)]


def test_a_leg_not_begun_when_the_plan_changes_is_not_travelled():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 5, 1, leg=2)])  # released at 3, 2 units from J1
    r.set_plan(2, [task('J2', 4, 1, leg=1, location='J2')], {'J2': {'A'}}, 1.0,
               restarted_in={'J2': 2})
    assert (r.mode, r.destination) == (RobotMode.IDLE, '')
    assert kinds(r.step(5)) == [(ARRIVED, 'J2', 4), (STARTED, 'J2', 4)]


def test_own_operation_done_and_continued_keeps_waiting_for_the_job_end():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 1, end=3, co=['B'])], {'J1': {'A', 'B'}})
    r.arrived('B', 'J1', 0.0, 1)
    r.step(2)
    plan(r, 2, [task('J1', 0, 1, end=3, co=['B'])], {'J1': {'A', 'B'}}, now=2,
         continued={'J1'})
    assert r.mode == RobotMode.WAITING and r.current_job == 'J1'
    r.operation_done('B', 'J1', 3.0, 1)
    r.step(3)
    assert r.finished


def test_holder_keeps_holding_through_a_restart_of_the_held_job():
    r = holder()
    r.operation_done('B', 'Ja', 5.0, 1)
    r.step(6)                              # carrying Ja's part to Aa, arriving at 7
    # Revision 2 keeps the done jig job Ja for its holder and restarts Aa with C.
    plan(r, 2, [task('Ja', 0, 1, end=5, held=True),
                task('Aa', 8, 5, co=['C'], preds=['Ja'], leg=2, location='Aa')],
         {'Ja': {'A'}, 'Aa': {'A', 'C'}}, now=6, continued={'Ja'})
    # It ends the leg it is on, which took it to Aa's place: nothing left to travel.
    assert attempts(r.step(7.5)) == [(ARRIVED, 'Aa', 2)]
    assert r.mode == RobotMode.HOLDING and r.location == 'Aa'
    r.arrived('C', 'Aa', 8.0, 2)
    assert kinds(r.step(8)) == [(STARTED, 'Aa', 8)]


def test_running_held_job_after_a_done_jig_job_is_continued():
    r = holder()
    r.operation_done('B', 'Ja', 5.0, 1)
    r.arrived('B', 'Aa', 7.0, 1)
    r.step(8)
    assert r.mode == RobotMode.WORKING and r.current_job == 'Aa'
    plan(r, 2, [task('Ja', 0, 1, end=5, held=True),
                task('Aa', 7, 5, co=['B'], preds=['Ja'], leg=2, location='Aa')],
         {'Ja': {'A'}, 'Aa': {'A', 'B'}}, now=8, continued={'Ja', 'Aa'})
    assert r.mode == RobotMode.WORKING and r.current_job == 'Aa'
    assert kinds(r.step(12.1)) == [(DONE, 'Aa', 12)]


def test_first_leg_leaves_from_the_start_location_once_released():
    # The plan starts A at its start location, released at 3, with a 2-unit leg to J1.
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 5, 1, leg=2)])
    assert r.step(1) == []
    assert r.mode == RobotMode.TRAVELLING and r.busy_until == pytest.approx(5)
    assert kinds(r.step(7)) == [(ARRIVED, 'J1', 5), (STARTED, 'J1', 5), (DONE, 'J1', 6)]
    # A robot that may start anywhere has a plan without a first leg: there at once.
    r = RobotExecution('B')
    plan(r, 1, [task('J1', 0, 1)])
    assert kinds(r.step(0)) == [(ARRIVED, 'J1', 0), (STARTED, 'J1', 0)]


def test_a_robot_failed_and_recovered_before_its_release_still_leaves_at_it():
    """Found by a generated fleet (seed 105797401): released at 10 with a 10-unit first leg,
    a robot failed at 4 and recovered at 5; following the re-plan, which again has it leave
    at 10, it left at once and arrived before it could have."""
    r = RobotExecution('C')
    plan(r, 1, [task('J1', 20, 1, leg=10)])
    assert r.step(4) == []
    r.fail(4)
    plan(r, 2, [], now=4.1)
    r.recover(5)
    plan(r, 3, [task('J1', 20, 1, leg=10)], now=5.1)
    assert r.step(6) == [] and r.busy_until == pytest.approx(20)
    assert kinds(r.step(22)) == [(ARRIVED, 'J1', 20), (STARTED, 'J1', 20), (DONE, 'J1', 21)]


def test_a_later_mission_leaves_no_earlier_than_planned_although_placed():
    """Found by the soak: the truss's D2 (released at 3) ended a mission at bay3; in the next
    one, placed there, it left for the depot at once, arrived before its release time, and
    the planner rightly judged the executed timeline invalid (mission FAILED)."""
    r = RobotExecution('D2')
    plan(r, 1, [task('J1', 0, 1, location='bay3')])
    r.step(2)
    assert r.finished and r.location == 'bay3'
    r.start_mission()
    # The next mission's plan has it leave bay3 at its release time, 3, for a 0.3 leg.
    plan(r, 1, [task('Haul2', 3.3, 1, leg=0.3, location='depot')])
    assert r.step(1) == []
    assert r.mode == RobotMode.TRAVELLING and r.busy_until == pytest.approx(3.3)
    assert kinds(r.step(5)) == [(ARRIVED, 'Haul2', 3.3), (STARTED, 'Haul2', 3.3),
                                (DONE, 'Haul2', 4.3)]
    # After its first leg of the mission it leaves as soon as it is free, as always.
    plan(r, 2, [task('J3', 20, 1, leg=1, location='bay1')], now=5)
    assert kinds(r.step(6.1)) == [(ARRIVED, 'J3', 6), (STARTED, 'J3', 6)]


def test_a_robot_stands_where_the_plan_starts_it_until_its_own_legs_move_it():
    """Found from outside: a robot with no task in a plan reported no location for the whole
    mission, though the scenario starts it at the depot, so monitors showed it nowhere."""
    idle, busy = RobotExecution('H1'), RobotExecution('N1')
    idle.set_plan(1, (), {'J1': {'N1'}}, 0.0, restarted_in={}, start_location='depot')
    assert idle.location == 'depot' and idle.mode == RobotMode.IDLE
    busy.set_plan(1, [task('J1', 3, 1, leg=3, location='site')], {'J1': {'N1'}}, 0.0,
                  restarted_in={'J1': 1}, start_location='depot')
    busy.step(1)
    assert (busy.location, busy.destination) == ('depot', 'site')
    busy.step(5)
    assert busy.location == 'site'
    # A later revision placing it elsewhere does not move a robot its own legs placed.
    busy.set_plan(2, (), {}, 5.0, restarted_in={}, start_location='depot')
    assert busy.location == 'site'
    # A robot that may start anywhere stays unplaced until its first job.
    anywhere = RobotExecution('N2')
    anywhere.set_plan(1, (), {}, 0.0, restarted_in={}, start_location='')
    assert anywhere.location == ''


def test_failing_while_waiting_at_a_job_withdraws_from_it():
    """Found by the soak: T2 arrived at PetalA, failed there before the job began and
    recovered at once, its tasks dropped. T1 knew only of its arrival, started PetalA alone,
    and T2, given the job again, did its part long after: the job ran apart. A robot failing
    at a job it waits for must say so, as one failing at work does."""
    a = RobotExecution('A')
    plan(a, 1, [task('J1', 4, 2, co=['B'], preds=['J0'], arrival=1)],
         {'J0': {'C'}, 'J1': {'A', 'B'}})
    a.arrived('B', 'J1', 0.5, 1)
    assert kinds(a.step(2)) == [(ARRIVED, 'J1', 1)]
    assert a.mode == RobotMode.WAITING
    failed = a.fail(3)
    assert failed.accepted and kinds(failed.events) == [(ABORTED, 'J1', 3)]
    # B, at J1 too, learns it and does not start J1 with A's arrival when J0 completes.
    b = RobotExecution('B')
    plan(b, 1, [task('J1', 4, 2, co=['A'], preds=['J0'], arrival=0.5)],
         {'J0': {'C'}, 'J1': {'A', 'B'}})
    b.arrived('A', 'J1', 1, 1)
    b.step(2)
    b.aborted('J1', 1)
    b.job_done('J0', 4, 1)
    assert b.step(5) == [] and b.mode == RobotMode.WAITING


def test_a_robot_recovered_at_a_job_it_finished_its_part_of_stays_until_the_job_completes():
    """Found by the soak: T1 finished its operation of PetalA, failed while T2 still worked on
    it, and recovered; the re-plan sent it on to PetalB and it left at once. A robot is on a
    job until the job completes (the planner plans it free at the job's end, and the record
    of the mission has it there until then): it leaves when the job's last robot is done."""
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 1, end=5, co=['B']), task('J2', 7, 1, leg=2)],
         {'J1': {'A', 'B'}, 'J2': {'A'}})
    r.arrived('B', 'J1', 0.0, 1)
    assert kinds(r.step(1.5)) == [(ARRIVED, 'J1', 0), (STARTED, 'J1', 0), (DONE, 'J1', 1)]
    assert r.mode == RobotMode.WAITING
    assert r.fail(2).accepted
    r.recover(3)
    plan(r, 2, [task('J2', 7, 1, leg=2)], {'J1': {'A', 'B'}, 'J2': {'A'}}, now=3,
         continued=['J1'])
    assert r.step(4.5) == []
    assert (r.mode, r.current_job, r.location) == (RobotMode.WAITING, 'J1', 'J1')
    r.operation_done('B', 'J1', 5.0, 1)
    assert kinds(r.step(10)) == [(ARRIVED, 'J2', 7), (STARTED, 'J2', 7), (DONE, 'J2', 8)]


def test_a_robot_recovered_with_nothing_left_to_do_is_done_only_when_its_job_is():
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 1, end=5, co=['B'])], {'J1': {'A', 'B'}})
    r.arrived('B', 'J1', 0.0, 1)
    r.step(1.5)
    r.fail(2)
    r.recover(3)
    plan(r, 2, [], {'J1': {'A', 'B'}}, now=3, continued=['J1'])
    assert r.step(4) == [] and not r.finished
    assert (r.mode, r.current_job) == (RobotMode.WAITING, 'J1')
    r.operation_done('B', 'J1', 5.0, 1)
    assert r.step(5) == [] and r.finished and r.mode == RobotMode.IDLE


def test_a_robot_recovered_at_a_job_restarted_without_it_leaves_at_once():
    """Where the re-plan restarts that job without it, nothing holds it there."""
    r = RobotExecution('A')
    plan(r, 1, [task('J1', 0, 1, end=5, co=['B']), task('J2', 7, 1, leg=2)],
         {'J1': {'A', 'B'}, 'J2': {'A'}})
    r.arrived('B', 'J1', 0.0, 1)
    r.step(1.5)
    r.fail(2)
    r.recover(3)
    plan(r, 2, [task('J2', 5, 1, leg=2)], {'J1': {'B'}, 'J2': {'A'}}, now=3)
    assert kinds(r.step(10)) == [(ARRIVED, 'J2', 5), (STARTED, 'J2', 5), (DONE, 'J2', 6)]


def test_the_robot_is_due_when_its_next_move_is_and_not_before():
    """What the agent sleeps until: a departure, the end of a leg or operation, a start or a
    job's end the reports fix; nothing while it waits on a report."""
    r = RobotExecution('A')
    plan(r, 1, [task('J0', 3, 1, leg=1, location='s'), task('J1', 6, 1, end=8, co=['B'], leg=2)],
         {'J0': {'A'}, 'J1': {'A', 'B'}})
    r.step(0)
    assert r.due() == 2                                   # it leaves at 2
    r.step(2)
    assert r.due() == pytest.approx(3)                    # and arrives at 3
    r.step(3.5)
    assert r.mode == RobotMode.WORKING and r.due() == pytest.approx(4)
    r.step(7)
    assert r.mode == RobotMode.WAITING and r.due() == math.inf   # B has not arrived
    r.arrived('B', 'J1', 6.5, 1)
    assert r.due() == 6.5
    r.step(7.6)
    assert r.mode == RobotMode.WAITING and r.due() == math.inf   # B's operation goes on
    r.operation_done('B', 'J1', 8.0, 1)
    assert r.due() == 8
    r.step(8)
    assert r.finished and r.due() == math.inf
