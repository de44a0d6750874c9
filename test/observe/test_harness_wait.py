"""The test harness's waits: a condition on something the observer has not heard yet (no
mission status, no plan) is not yet true, and a timeout names what it raised."""

from types import SimpleNamespace

import pytest

from fjsp_planner import testing
from fjsp_planner.fleet import Listener


class Unheard(testing.Observer):
    """An observer that has heard nothing, without a ROS context."""

    def __init__(self):
        self.status = None
        self.plans = []


def test_a_condition_on_a_status_not_heard_yet_is_false_until_it_arrives(monkeypatch):
    seen = []

    def wait(self, predicate, timeout):
        seen.append(predicate())
        self.status = SimpleNamespace(state=3)
        seen.append(predicate())
        return seen[-1]

    monkeypatch.setattr(Listener, 'wait_for', wait)
    Unheard().wait_for(lambda o: o.status.state == 3, 1, 'executing')
    assert seen == [False, True]


def test_a_timeout_names_what_the_condition_raised(monkeypatch):
    monkeypatch.setattr(Listener, 'wait_for', lambda self, predicate, timeout: predicate())
    with pytest.raises(pytest.fail.Exception, match=r'a re-plan; the condition last raised '
                                                    r'IndexError'):
        Unheard().wait_for(lambda o: o.plans[-1].revision >= 2, 1, 'a re-plan')


def test_other_errors_in_a_condition_are_not_hidden(monkeypatch):
    monkeypatch.setattr(Listener, 'wait_for', lambda self, predicate, timeout: predicate())
    with pytest.raises(ZeroDivisionError):
        Unheard().wait_for(lambda o: 1 / 0, 1)
