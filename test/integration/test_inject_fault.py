"""The inject_fault tool against one real agent: accepted and refused faults, exit codes, the
agent's state, and the Python helper through a node that is already being spun."""

import time

import pytest
from harness import Launcher

from fjsp_msgs.msg import RobotState
from fjsp_planner.faults import FaultError, inject_fault


def run(launcher: Launcher, *args):
    done = launcher.inject_fault(*args, timeout=30)
    assert 'Traceback' not in done.stdout + done.stderr
    return done


def mode_is(observer, mode):
    return lambda o: 'MARC1' in o.robots and o.robots['MARC1'].mode == mode


def test_fail_recover_and_refusals(launcher, observer):
    launcher.start_agent('MARC1')
    observer.wait_for(mode_is(observer, RobotState.MODE_IDLE), 20, 'the MARC1 agent')

    done = run(launcher, 'MARC1', 'fail')
    assert done.returncode == 0, done.stdout + done.stderr
    assert "robot 'MARC1' failed" in done.stdout
    observer.wait_for(mode_is(observer, RobotState.MODE_FAILED), 5, 'MARC1 to report FAILED')

    done = run(launcher, 'MARC1', 'fail')
    assert done.returncode == 1
    assert done.stderr.strip() == "inject_fault: fail refused: robot 'MARC1' has already failed"

    done = run(launcher, 'MARC1', 'recover')
    assert done.returncode == 0, done.stdout + done.stderr
    assert "robot 'MARC1' recovered" in done.stdout
    observer.wait_for(mode_is(observer, RobotState.MODE_IDLE), 5, 'MARC1 to report IDLE')

    # Without a plan it has nothing to slow down.
    done = run(launcher, 'MARC1', 'delay', '--factor', '2')
    assert done.returncode == 1
    assert "delay refused: robot 'MARC1' has no operation left to do" in done.stderr

    done = run(launcher, 'MARC1', 'delay', '--factor', '0')
    assert done.returncode == 2
    assert 'factor must be a finite number > 0, got 0' in done.stderr

    began = time.monotonic()
    done = run(launcher, 'NOBODY', 'fail', '--timeout', '1')
    assert done.returncode == 1
    assert "no agent serves '/NOBODY/inject_fault' (waited 1 s)" in done.stderr
    assert time.monotonic() - began < 15

    assert 'fault injected' in launcher.log('marc1_agent')


def test_helper_through_a_spun_node(launcher, observer):
    launcher.start_agent('MARC1')
    observer.wait_for(mode_is(observer, RobotState.MODE_IDLE), 20, 'the MARC1 agent')
    answer = inject_fault('MARC1', 'fail', node=observer.node, timeout=10)
    assert "robot 'MARC1' failed" in answer
    observer.wait_for(mode_is(observer, RobotState.MODE_FAILED), 5, 'MARC1 to report FAILED')
    with pytest.raises(FaultError, match='has already failed'):
        inject_fault('MARC1', 'fail', node=observer.node, timeout=10)
    assert 'recovered' in inject_fault('MARC1', 'recover', node=observer.node, timeout=10)


def test_monitor_shows_failed_then_offline(launcher, observer):
    launcher.start_agent('MARC1')
    launcher.start('monitor', 'fjsp_planner', 'monitor_node',
                   [('refresh_period', 0.2), ('heartbeat_timeout', 0.6), ('web_port', 0)])
    observer.wait_for(mode_is(observer, RobotState.MODE_IDLE), 20, 'the MARC1 agent')
    run(launcher, 'MARC1', 'fail')
    wait_for_line(launcher, 'monitor', 'MARC1      failed')
    launcher.kill('marc1_agent')
    wait_for_line(launcher, 'monitor', 'MARC1      offline')


def wait_for_line(launcher, name, text, timeout=10.0):
    deadline = time.monotonic() + timeout
    while text not in launcher.log(name):
        if time.monotonic() > deadline:
            pytest.fail(f'no {text!r} in the {name} log after {timeout:g} s:\n'
                        + launcher.log(name))
        time.sleep(0.1)
