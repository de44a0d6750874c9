"""The agent's execution behind a driver whose robot takes its own time and may fail, like a
real robot behind its action servers, on hand-checkable sequences (no ROS)."""

import math

import pytest

from fjsp_common.vocabulary import EventKind, RobotMode
from robot_agents.drivers import Ending, Leg, MockDriver, Operation, later
from robot_agents.execution import RobotExecution, Task

ARRIVED, STARTED, DONE, ABORTED = (EventKind.ARRIVED, EventKind.STARTED,
                                   EventKind.OPERATION_DONE, EventKind.ABORTED)


class ScriptedDriver:
    """A robot whose legs and operations last what the test says (`finish`), or fail."""

    def __init__(self):
        self.begun: list[tuple[Leg | Operation, float]] = []
        self.stops: list[float] = []
        self.share = 0.0
        self._start = math.nan
        self._ending: Ending | None = None

    ends_when_expected = False

    def begin(self, work, start):
        self.begun.append((work, start))
        self._start, self._ending, self.share = start, None, 0.0

    def finish(self, took: float, failure: str = '', share: float = 1.0):
        self._ending = Ending(later(self._start + took), failure, share)

    def ending(self, now):
        if self._ending is None or now < self._ending.end:
            return None
        ending, self._ending = self._ending, None
        return ending

    def stop(self, now):
        self.stops.append(now)
        self._ending = None
        return self.share

    def progress(self, now):
        return self.share

    def expected_end(self):
        return self._start + 100

    def retime(self, duration, now):
        return False


def task(job, start, duration, leg=0.0, location=None, co=(), end=None):
    return Task(job=job, operation_type=0, location=location or job, travel_start=start - leg,
                arrival=start, start=start, operation_end=start + duration,
                end=end if end is not None else start + duration, co_workers=tuple(co),
                operation_name='grip')


def kinds(events):
    return [(e.kind, e.job, round(e.time, 4)) for e in events]


def robot(tasks, job_robots=None):
    driver = ScriptedDriver()
    r = RobotExecution('A', driver)
    r.set_plan(1, tasks, job_robots or {t.job: {'A'} for t in tasks}, 0.0,
               restarted_in={t.job: 1 for t in tasks})
    return r, driver


def test_legs_and_operations_last_what_the_robot_took_from_their_logical_start():
    r, driver = robot([task('J1', 2, 3, leg=2, location='s'), task('J2', 9, 2, leg=4)])
    assert r.step(0.0) == [] and driver.begun == [(Leg('J1', '', 's', 2.0), 0.0)]
    driver.finish(2.5)                                   # half a unit longer than planned
    assert kinds(r.step(3)) == [(ARRIVED, 'J1', 2.5), (STARTED, 'J1', 2.5)]
    operation, start = driver.begun[1]
    assert (operation.job, operation.operation_name, operation.duration) == ('J1', 'grip', 3.0)
    assert start == pytest.approx(2.5)
    driver.finish(1.0)                                   # two units shorter than planned
    assert kinds(r.step(4)) == [(DONE, 'J1', 3.5)]
    assert driver.begun[2][0] == Leg('J2', 's', 'J2', 4.0)
    assert r.mode == RobotMode.TRAVELLING and r.busy_until == pytest.approx(103.5)


def test_a_robot_whose_driver_alone_knows_when_its_work_ends_is_polled():
    r, driver = robot([task('J1', 2, 3, leg=2, location='s')])
    assert r.step(0.0) == [] and r.due() is None          # on its leg
    driver.finish(2.5)
    r.step(3)
    assert r.due() is None                                # at work
    driver.finish(1.0)
    r.step(4)
    assert r.finished and r.due() == math.inf


def test_a_robot_failure_during_an_operation_aborts_it_and_fails_the_robot():
    r, driver = robot([task('J1', 0, 3), task('J2', 5, 1)])
    r.step(0)
    driver.finish(1.25, failure="'A/execute_operation': gripper jammed")
    assert kinds(r.step(2)) == [(ABORTED, 'J1', 1.25)]
    assert r.mode == RobotMode.FAILED and r.current_job == ''
    assert r.failures() == ["robot 'A' failed at t=1.25 ('A/execute_operation': gripper "
                            "jammed), aborting its operation of job 'J1' at 'J1'"]
    assert r.failures() == [] and r.step(10) == []
    assert r.fail(10).message == "fail refused: robot 'A' has already failed"
    assert r.recover(11).accepted and r.mode == RobotMode.IDLE


def test_a_robot_failure_on_a_leg_leaves_it_where_it_stopped():
    r, driver = robot([task('J0', 0, 1), task('J1', 5, 1, leg=4)])
    r.step(1)
    driver.finish(0.5)
    r.step(2)                                            # on its way to J1 since 0.5
    driver.finish(1.0, failure='wheel lost', share=0.25)
    assert r.step(2) == []
    assert (r.mode, r.location, r.destination) == (RobotMode.FAILED, 'J0', 'J1')
    assert r.progress(9) == 0.25
    assert 'failed at t=1.50 (wheel lost)' in r.failures()[0]


def test_a_new_plan_stops_what_the_robot_no_longer_needs():
    r, driver = robot([task('J0', 0, 1), task('J1', 5, 1, leg=4)])
    r.step(0)
    driver.finish(1.0)
    r.step(2)
    driver.share = 0.4
    r.set_plan(2, [task('J2', 6, 1, leg=3)], {'J2': {'A'}}, 2.5, restarted_in={'J2': 2})
    assert driver.stops == [2.5]
    assert (r.mode, r.location, r.destination, r.progress(3)) == (
        RobotMode.IDLE, 'J0', 'J1', 0.4)
    r.step(2.5)
    assert driver.begun[-1] == (Leg('J2', 'J0', 'J2', 3.0), 2.5)
    # An operation the next plan does not continue is stopped too.
    driver.finish(3.0)
    assert kinds(r.step(6)) == [(ARRIVED, 'J2', 5.5), (STARTED, 'J2', 5.5)]
    r.set_plan(3, [task('J3', 7, 1, leg=1)], {'J3': {'A'}}, 6.0, restarted_in={'J3': 3})
    assert driver.stops == [2.5, 6.0]


def test_the_operation_under_way_is_not_retimed_behind_a_robot_with_its_own_timing():
    r, driver = robot([task('J1', 0, 4), task('J2', 6, 1, leg=1)])
    r.step(1)
    result = r.delay(2.0, 1)
    assert not result.accepted and 'cannot be retimed' in result.message
    driver.finish(4.0)
    r.step(4.5)                                          # on its way to J2 since 4
    # The next operation's goal carries the delay: its robot may take it into account.
    assert r.delay(3.0, 4.5).accepted
    driver.finish(1.0)
    assert kinds(r.step(5.1)) == [(ARRIVED, 'J2', 5), (STARTED, 'J2', 5)]
    assert driver.begun[-1][0].duration == 3.0


def test_the_mock_driver_takes_the_planned_times():
    driver = MockDriver()
    driver.begin(Leg('J', 'a', 'b', 4.0), 1.0)
    assert driver.ending(4.9) is None and driver.progress(3.0) == pytest.approx(0.5)
    assert driver.expected_end() == later(5.0) and driver.ending(5.1) == Ending(later(5.0))
    driver.begin(Operation('J', 0, 'grip', 'b', (), 2.0), 5.0)
    assert driver.stop(6.0) == pytest.approx(0.5) and driver.ending(100) is None
