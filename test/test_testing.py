"""The test harness's waits: a condition on something the observer has not heard yet (no
mission status, no plan) is not yet true, and a timeout names what it raised."""

from types import SimpleNamespace

import pytest

from fjsp_planner import testing
from fjsp_planner.launcher.listener import Listener


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


class Stopped(testing.FleetHarness):
    """A harness whose nodes have the given exit codes (None: still running), without a ROS
    context, and whose observer has heard nothing."""

    def __init__(self, codes):
        self.observer = Unheard()
        self.processes = {name: SimpleNamespace(returncode=code, poll=lambda code=code: code)
                          for name, code in codes.items()}


def test_a_timeout_names_the_nodes_that_are_no_longer_running(monkeypatch):
    monkeypatch.setattr(Listener, 'wait_for', lambda self, predicate, timeout: False)
    harness = Stopped({'agent_A1': -11, 'agent_S1': 1, 'planner': None})
    with pytest.raises(pytest.fail.Exception) as failure:
        harness.wait_for(lambda o: False, 1, 'a healthy fleet')
    assert str(failure.value).endswith(
        'a healthy fleet; last mission status: None; not running: agent_A1 (killed by '
        'SIGSEGV), agent_S1 (exited with 1)')


def test_a_timeout_with_every_node_running_says_only_what_it_waited_for(monkeypatch):
    monkeypatch.setattr(Listener, 'wait_for', lambda self, predicate, timeout: False)
    with pytest.raises(pytest.fail.Exception) as failure:
        Stopped({'planner': None}).wait_for(lambda o: False, 1, 'a healthy fleet')
    assert str(failure.value).endswith('a healthy fleet; last mission status: None')
