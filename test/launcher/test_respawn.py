"""The launcher's respawn decisions on a fake clock: a node that ended starts again after the
delay, one that keeps ending is given up on, and only the planner's loss ends the fleet."""

import signal

import pytest

from fjsp_planner.launcher.respawn import RespawnPolicy, Supervisor

KILLED = -signal.SIGKILL
POLICY = RespawnPolicy(delay=1.0, limit=3, window=10.0)


def supervisor(policy=POLICY, **options) -> Supervisor:
    return Supervisor(policy, essential={'planner'}, **options)


def test_a_killed_agent_starts_again_after_the_delay():
    s = supervisor()
    verdict = s.ended('agent_R1', KILLED, now=100.0)
    assert verdict.respawn_at == 101.0 and not verdict.ends_fleet
    assert verdict.describe(100.0) == ("node 'agent_R1' killed by SIGKILL; starting it again "
                                       'in 1 s')
    assert not s.watches('agent_R1')
    assert s.due(100.9) == []
    assert s.due(101.0) == ['agent_R1']
    assert s.watches('agent_R1') and s.due(105.0) == []


def test_nodes_ending_together_start_again_together():
    s = supervisor()
    s.ended('monitor', 1, now=0.0)
    s.ended('agent_R2', KILLED, now=0.5)
    s.ended('agent_R1', KILLED, now=0.2)
    assert s.due(1.2) == ['agent_R1', 'monitor']
    assert s.due(1.5) == ['agent_R2']


@pytest.mark.parametrize('node, ends_fleet', [('agent_R1', False), ('recorder', False),
                                               ('planner', True)])
def test_a_node_that_keeps_ending_is_given_up_on(node, ends_fleet):
    s = supervisor()
    for now in (0.0, 2.0):
        assert s.ended(node, KILLED, now).respawn_at == now + 1.0
        assert s.due(now + 1.0) == [node]
    verdict = s.ended(node, 1, now=4.0)  # the third end within 10 s
    assert verdict.respawn_at is None and verdict.ends_fleet == ends_fleet
    then = 'the fleet stops' if ends_fleet else 'the fleet goes on without it'
    assert verdict.describe(4.0) == (f"node '{node}' exited with 1; not starting it again: it "
                                     f'ended 3 times within 10 s; {then}')
    assert s.settled(node) and not s.watches(node) and s.due(100.0) == []


def test_ends_further_apart_than_the_window_allows_are_respawned_forever():
    s = supervisor()
    for end in range(20):
        now = end * 5.5  # two ends within any 10 s, never three
        assert s.ended('agent_R1', KILLED, now).respawn_at == now + 1.0
        assert s.due(now + 1.0) == ['agent_R1']


def test_a_node_refusing_its_parameters_is_given_up_on_at_once():
    s = supervisor()
    verdict = s.ended('agent_R1', 2, now=0.0)
    assert verdict.respawn_at is None and not verdict.ends_fleet
    assert 'refused its parameters' in verdict.why_not
    assert s.ended('planner', 2, now=0.0).ends_fleet


def test_without_respawning_any_end_ends_the_fleet_but_a_node_that_may_finish():
    s = Supervisor(None, essential={'planner'}, may_finish={'monitor'})
    verdict = s.ended('agent_R1', KILLED, now=0.0)
    assert verdict.ends_fleet and verdict.why_not == 'respawning is off'
    assert s.ended('recorder', 0, now=0.0).ends_fleet
    finished = s.ended('monitor', 0, now=0.0)
    assert finished.finished and not finished.ends_fleet and s.settled('monitor')
    assert finished.describe(0.0) == "node 'monitor' exited with 0"


def test_a_node_that_may_finish_is_respawned_if_it_fails():
    s = supervisor(may_finish={'monitor'})
    assert s.ended('monitor', KILLED, now=0.0).respawn_at == 1.0
    assert s.ended('recorder', 0, now=0.0).respawn_at == 1.0  # not allowed to finish
