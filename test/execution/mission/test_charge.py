"""Which planner of a domain is in charge (`charge.Charge`), on a fake clock: a newcomer that
hears another planner stands by, a planner standing by takes charge once the other is
silent, and two that both spoke settle it the same way on both sides."""

from fjsp_planner.execution.mission.charge import Charge, Role

TIMEOUT = 3.0
OLD, NEW = 1_000, 2_000
"""Incarnations: process starts, in ns."""


def test_a_planner_alone_takes_charge_once_it_has_listened():
    charge = Charge(OLD, 100.0, TIMEOUT)
    assert charge.update(False, 102.9) is None and charge.role == Role.LISTENING
    change = charge.update(False, 103.0)
    assert change.role == Role.IN_CHARGE and change.why == 'no other planner heard in 3 s'


def test_a_newcomer_that_hears_a_planner_stands_by_until_it_falls_silent():
    charge = Charge(NEW, 100.0, TIMEOUT)
    charge.hear(OLD, False, '', stamp=100.5, wall=100.5)
    change = charge.update(False, 100.6)
    assert change.role == Role.STANDING_BY
    assert 'incarnation 1000), idle is on this ROS domain' in change.why
    charge.hear(OLD, True, 'm1', stamp=102.0, wall=102.0)
    assert charge.update(False, 104.9) is None  # heard 2.9 s ago
    change = charge.update(False, 105.1)
    assert change.role == Role.IN_CHARGE and change.why == 'no other planner heard for 3 s'


def test_two_planners_that_both_spoke_agree_on_which_keeps_charge():
    def in_charge(incarnation, busy):
        charge = Charge(incarnation, 0.0, TIMEOUT)
        charge.update(busy, 3.0)
        assert charge.role == Role.IN_CHARGE
        return charge

    def after_hearing(me, other):
        (mine, my_busy), (theirs, their_busy) = me, other
        charge = in_charge(mine, my_busy)
        charge.hear(theirs, their_busy, 'm' if their_busy else '', stamp=3.5, wall=3.5)
        charge.update(my_busy, 3.6)
        return charge.role

    for old_busy, new_busy, keeps in ((False, False, NEW), (True, True, NEW),
                                      (True, False, OLD), (False, True, NEW)):
        old, new = (OLD, old_busy), (NEW, new_busy)
        assert after_hearing(old, new) == (Role.IN_CHARGE if keeps == OLD else
                                           Role.STANDING_BY)
        assert after_hearing(new, old) == (Role.IN_CHARGE if keeps == NEW else
                                           Role.STANDING_BY)


def test_its_own_status_and_a_stale_one_are_no_rival():
    charge = Charge(OLD, 100.0, TIMEOUT)
    charge.hear(OLD, True, 'm1', stamp=100.5, wall=100.5)
    charge.hear(NEW, True, 'm2', stamp=90.0, wall=100.5)  # replayed: 10.5 s old
    assert charge.leader() is None
    assert charge.update(False, 103.0).role == Role.IN_CHARGE
