"""The test harness's waits: a condition on something the observer has not heard yet (no
mission status, no plan) is not yet true, and a timeout names what it raised. Its check of
an executed timeline judges a voided jig job as the planner does."""

import re
from fractions import Fraction
from types import SimpleNamespace

import pytest

from fjsp_msgs.msg import MissionStatus, TaskEvent
from fjsp_planner import testing
from fjsp_planner.launcher.listener import Listener
from fjsp_planner.model.schedule import JobAssignment, Schedule

from jig_scenarios import held_then_followed


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


class Ended(testing.FleetHarness):
    """A harness whose observer heard the mission end in `state`, without a ROS context."""

    def __init__(self, state, reasons):
        self.observer = Unheard()
        self.observer.status = SimpleNamespace(state=state, mission_id='m1', jobs_done=5,
                                               jobs_total=12, blocked_reasons=reasons)
        self.processes = {}
        self.problem = SimpleNamespace(jobs=[])


@pytest.mark.parametrize(('state', 'reasons', 'said'), [
    (MissionStatus.STATE_FAILED, ["job 'Aa' cannot be staffed", 'blocked for 20 s'],
     "mission 'm1' ended FAILED instead of completing (5/12 jobs done): job 'Aa' cannot be "
     'staffed; blocked for 20 s'),
    (MissionStatus.STATE_CANCELLED, [],
     "mission 'm1' ended CANCELLED instead of completing (5/12 jobs done): no reason given"),
])
def test_a_mission_that_ended_undone_fails_the_check_at_once(monkeypatch, state, reasons,
                                                               said):
    """The wait ends as soon as the status says the mission ended; it used to wait out the
    whole timeout for a COMPLETE that could not come any more."""
    waited = []

    def wait(self, predicate, timeout):
        waited.append(timeout)
        return predicate()

    monkeypatch.setattr(Listener, 'wait_for', wait)
    with pytest.raises(pytest.fail.Exception) as failure:
        Ended(state, reasons).check_mission_complete(timeout=600)
    assert str(failure.value) == said
    assert waited == [600]


@pytest.fixture
def environment(monkeypatch):
    """No domain setting of the caller's: each test sets its own."""
    for name in ('ROS_DOMAIN_ID', testing.DOMAINS_VARIABLE):
        monkeypatch.delenv(name, raising=False)
    return monkeypatch


def test_the_domain_is_the_one_ros_domain_id_names(environment):
    environment.setenv('ROS_DOMAIN_ID', '231')
    claim = testing.DomainClaim()
    try:
        assert claim.domain == 231
        with pytest.raises(RuntimeError, match='ROS_DOMAIN_ID=231 is in use by another fleet '
                                               'of tests on this machine; for several fleets '
                                               'at once set FJSP_TEST_DOMAINS'):
            testing.DomainClaim()
    finally:
        claim.release()
    testing.DomainClaim().release()            # free again once released


def test_a_range_of_domains_gives_each_fleet_its_own(environment):
    environment.setenv('ROS_DOMAIN_ID', '231')
    environment.setenv(testing.DOMAINS_VARIABLE, '229-230')
    claims = [testing.DomainClaim(), testing.DomainClaim()]
    try:
        assert sorted(c.domain for c in claims) == [229, 230]
        with pytest.raises(RuntimeError, match=r'every ROS domain id 229..230 '
                                               r'\(FJSP_TEST_DOMAINS\) is in use'):
            testing.DomainClaim()
    finally:
        for claim in claims:
            claim.release()


def test_without_a_setting_the_domain_is_from_the_default_range(environment):
    claim = testing.DomainClaim()
    claim.release()
    assert claim.domain in testing.DOMAINS


@pytest.mark.parametrize(('variable', 'value', 'message'), [
    ('ROS_DOMAIN_ID', 'ten', "ROS_DOMAIN_ID='ten': expected an id within 0..232"),
    ('ROS_DOMAIN_ID', '300', "ROS_DOMAIN_ID='300': expected an id within 0..232"),
    (testing.DOMAINS_VARIABLE, '200-100', "FJSP_TEST_DOMAINS='200-100': expected first-last"),
    (testing.DOMAINS_VARIABLE, '1-999', "FJSP_TEST_DOMAINS='1-999': expected first-last"),
])
def test_an_unusable_domain_setting_is_named(environment, variable, value, message):
    environment.setenv(variable, value)
    with pytest.raises(RuntimeError, match=re.escape(message)):
        testing.DomainClaim()


def test_what_followed_a_voided_completion_met_its_precedence():
    """T done at 2 and followed by M (2-3), voided when its holder failed, redone 3-5: the
    planner declared T done twice. M met T's precedence by the first completion."""
    problem, _ = held_then_followed()
    executed = Schedule({'T': JobAssignment('T', 0, Fraction(3), Fraction(5), {'B': 1}),
                         'L': JobAssignment('L', 0, Fraction(5), Fraction(7), {'B': 1}),
                         'M': JobAssignment('M', 0, Fraction(2), Fraction(3), {'C': 3})},
                        {'A': (), 'B': ('T', 'L'), 'C': ('M',)})
    done = [TaskEvent(kind=TaskEvent.KIND_JOB_DONE, mission_id=mission, job=job, time=time)
            for mission, job, time in (('m', 'T', 2.0), ('m', 'M', 3.0), ('m', 'T', 2.0),
                                       ('m', 'T', 5.0), ('other', 'M', 1.0),
                                       ('other', 'M', 9.0))]
    plans = [SimpleNamespace(mission_id='m')]
    assert testing.voided_ends(plans, done) == {'T': 2.0}
    assert testing.validate_executed(problem, executed, testing.voided_ends(plans, done)) == []
    assert testing.validate_executed(problem, executed) == [
        "job 'M' starts at 2 before its predecessor 'T' completes at 5"]
