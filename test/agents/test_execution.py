"""The agents' ROS-free execution logic, on hand-checkable two-robot sequences."""

import pytest

from robot_agents.execution import EventKind, Mode, RobotExecution, Task


def task(job, start, duration, end=None, leg=0.0, co=(), preds=(), held=False, location=None):
    return Task(job=job, operation_type=0, location=location or job, travel_start=start - leg,
                arrival=start, start=start, operation_end=start + duration,
                end=end if end is not None else start + duration, co_workers=tuple(co),
                predecessors=tuple(preds), held_into_next=held)


def kinds(events):
    return [(e.kind, e.job, round(e.time, 4)) for e in events]


def test_solo_sequence_travels_and_works_in_logical_time():
    r = RobotExecution('A')
    r.set_plan(1, [task('J1', 0, 2), task('J2', 5, 1, leg=3)], {'J1': {'A'}, 'J2': {'A'}}, 0)
    assert kinds(r.step(0)) == [(EventKind.ARRIVED, 'J1', 0), (EventKind.STARTED, 'J1', 0)]
    assert r.mode == Mode.WORKING and r.progress(1) == pytest.approx(0.5)
    # Stepping late (at 10) still reports the instants the work was due at.
    assert kinds(r.step(10)) == [(EventKind.OPERATION_DONE, 'J1', 2),
                                 (EventKind.ARRIVED, 'J2', 5), (EventKind.STARTED, 'J2', 5),
                                 (EventKind.OPERATION_DONE, 'J2', 6)]
    assert r.finished and r.mode == Mode.IDLE and r.location == 'J2'


def test_job_waits_for_co_workers_and_predecessors():
    r = RobotExecution('A')
    r.set_plan(1, [task('J2', 4, 1, co=['B'], preds=['J1'])], {'J1': {'B'}, 'J2': {'A', 'B'}}, 0)
    assert kinds(r.step(3)) == [(EventKind.ARRIVED, 'J2', 0)]
    assert r.mode == Mode.WAITING
    r.operation_done('B', 'J1', 3.0)      # J1's only robot is done: J1 is complete at 3
    assert r.step(3.5) == []              # B has not arrived yet
    r.arrived('B', 'J2', 3.25)
    assert kinds(r.step(3.5)) == [(EventKind.STARTED, 'J2', 3.25)]
    assert r.step(4.2) == []
    assert kinds(r.step(4.3)) == [(EventKind.OPERATION_DONE, 'J2', 4.25)]
    assert r.mode == Mode.WAITING         # occupied until B's operation ends too
    r.job_done('J2', 6.0)
    r.step(6.0)
    assert r.finished


def test_holder_stays_holding_into_the_next_job():
    r = RobotExecution('A')
    r.set_plan(1, [task('Ja', 0, 1, end=5, co=['B'], held=True),
                   task('Aa', 5, 5, co=['B'], preds=['Ja'], leg=2)],
               {'Ja': {'A', 'B'}, 'Aa': {'A', 'B'}}, 0)
    r.arrived('B', 'Ja', 0.0)
    r.step(2)
    assert r.mode == Mode.HOLDING and r.current_job == 'Ja'
    r.operation_done('B', 'Ja', 5.0)
    assert kinds(r.step(5)) == [(EventKind.ARRIVED, 'Aa', 5)]   # no travel while holding
    assert r.mode == Mode.HOLDING and r.current_job == 'Aa'


def test_stale_revision_is_refused():
    r = RobotExecution('A')
    r.set_plan(2, [task('J1', 0, 1)], {'J1': {'A'}}, 0)
    with pytest.raises(ValueError, match='revision 1 is not newer than revision 2'):
        r.set_plan(1, [], {}, 0)


def test_new_revision_keeps_the_current_job_or_aborts_it():
    r = RobotExecution('A')
    r.set_plan(1, [task('J1', 0, 4), task('J2', 4, 1)], {'J1': {'A'}, 'J2': {'A'}}, 0)
    r.step(1)
    assert r.set_plan(2, [task('J1', 0, 4), task('J3', 4, 1)],
                      {'J1': {'A'}, 'J3': {'A'}}, 1) == []
    assert r.mode == Mode.WORKING and r.current_job == 'J1'
    aborted = r.set_plan(3, [task('J3', 4, 1)], {'J3': {'A'}}, 2)
    assert kinds(aborted) == [(EventKind.ABORTED, 'J1', 2)]
    assert kinds(r.step(2)) == [(EventKind.ARRIVED, 'J3', 2), (EventKind.STARTED, 'J3', 2)]


def test_late_joiner_cannot_act_before_it_got_the_plan():
    r = RobotExecution('A')
    r.set_plan(1, [task('J1', 0, 1)], {'J1': {'A'}}, 7.0)
    assert kinds(r.step(7.0)) == [(EventKind.ARRIVED, 'J1', 7), (EventKind.STARTED, 'J1', 7)]
