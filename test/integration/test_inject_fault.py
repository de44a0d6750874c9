"""The inject_fault tool against one real agent: accepted and refused faults, exit codes, the
agent's state, and the Python helper through a node however its caller spins it."""

import threading
import time

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor

from fjsp_common.contract import LATCHED_READER_QOS, ROBOT_STATES_TOPIC
from fjsp_msgs.msg import RobotState
from fjsp_planner.faults import FaultError, inject_fault


def run(fleet, *args):
    done = fleet.run('fjsp_planner', 'inject_fault', *args, timeout=30)
    assert 'Traceback' not in done.stdout + done.stderr
    return done


def mode_is(mode):
    return lambda o: 'MARC1' in o.robots and o.robots['MARC1'].mode == mode


def marc1_agent(fjsp_fleet):
    fleet = fjsp_fleet()
    fleet.start_agent('MARC1')
    fleet.wait_for(mode_is(RobotState.MODE_IDLE), 20, 'the MARC1 agent')
    return fleet


def test_fail_recover_and_refusals(fjsp_fleet):
    fleet = marc1_agent(fjsp_fleet)

    done = run(fleet, 'MARC1', 'fail')
    assert done.returncode == 0, done.stdout + done.stderr
    assert "robot 'MARC1' failed" in done.stdout
    fleet.wait_for(mode_is(RobotState.MODE_FAILED), 5, 'MARC1 to report FAILED')

    done = run(fleet, 'MARC1', 'fail')
    assert done.returncode == 1
    assert done.stderr.strip() == "inject_fault: fail refused: robot 'MARC1' has already failed"

    done = run(fleet, 'MARC1', 'recover')
    assert done.returncode == 0, done.stdout + done.stderr
    assert "robot 'MARC1' recovered" in done.stdout
    fleet.wait_for(mode_is(RobotState.MODE_IDLE), 5, 'MARC1 to report IDLE')

    # Without a plan it has nothing to slow down.
    done = run(fleet, 'MARC1', 'delay', '--factor', '2')
    assert done.returncode == 1
    assert "delay refused: robot 'MARC1' has no operation left to do" in done.stderr

    done = run(fleet, 'MARC1', 'delay', '--factor', '0')
    assert done.returncode == 2
    assert 'factor must be a finite number > 0, got 0' in done.stderr

    began = time.monotonic()
    done = run(fleet, 'NOBODY', 'fail', '--timeout', '1')
    assert done.returncode == 1
    assert "no agent serves '/NOBODY/inject_fault' (waited 1 s)" in done.stderr
    assert time.monotonic() - began < 15

    assert 'fault injected' in fleet.log('agent_MARC1')


def test_helper_through_the_observers_node(fjsp_fleet):
    fleet = marc1_agent(fjsp_fleet)
    node = fleet.observer.node
    answer = inject_fault('MARC1', 'fail', node=node, timeout=10)
    assert "robot 'MARC1' failed" in answer
    fleet.wait_for(mode_is(RobotState.MODE_FAILED), 5, 'MARC1 to report FAILED')
    with pytest.raises(FaultError, match='has already failed'):
        inject_fault('MARC1', 'fail', node=node, timeout=10)
    assert 'recovered' in inject_fault('MARC1', 'recover', node=node, timeout=10)


@pytest.mark.parametrize('spun', ['by an executor on another thread',
                                  'by hand in this thread, not during the call',
                                  'and the call made from one of its callbacks'])
def test_helper_works_however_the_callers_node_is_spun(fjsp_fleet, spun):
    """The trap: a helper that borrows the caller's node must get that node spun, and either
    steals it from the caller's executor or waits for an executor that is not spinning."""
    fleet = marc1_agent(fjsp_fleet)
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=fleet.domain)
    node = rclpy.create_node('user_test', context=context)
    heard = []
    node.create_subscription(RobotState, ROBOT_STATES_TOPIC,
                             lambda msg: heard.append(time.monotonic()), LATCHED_READER_QOS)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    thread = None
    try:
        if spun == 'by hand in this thread, not during the call':
            executor.spin_once(timeout_sec=0.5)
            answer = inject_fault('MARC1', 'fail', node=node, timeout=10)
        else:
            thread = threading.Thread(target=executor.spin, daemon=True)
            thread.start()
            if spun == 'by an executor on another thread':
                answer = inject_fault('MARC1', 'fail', node=node, timeout=10)
            else:
                answers = []
                timer = node.create_timer(0.1, lambda: answers.append(
                    inject_fault('MARC1', 'fail', node=node, timeout=10)) or timer.cancel())
                deadline = time.monotonic() + 30
                while not answers and time.monotonic() < deadline:
                    time.sleep(0.05)
                assert answers, 'the call from the callback did not return within 30 s'
                answer = answers[0]
        assert "robot 'MARC1' failed" in answer
        fleet.wait_for(mode_is(RobotState.MODE_FAILED), 5, 'MARC1 to report FAILED')
        # The caller's node is still its executor's, and still hears the fleet.
        assert node.executor is executor
        if thread is not None:
            called = time.monotonic()
            deadline = called + 10
            while not any(t > called for t in heard) and time.monotonic() < deadline:
                time.sleep(0.05)
            assert any(t > called for t in heard), 'the node stopped receiving'
    finally:
        executor.shutdown(timeout_sec=1.0)
        if thread is not None:
            thread.join(timeout=2.0)
        node.destroy_node()
        rclpy.try_shutdown(context=context)


def test_monitor_shows_failed_then_offline(fjsp_fleet):
    fleet = marc1_agent(fjsp_fleet)
    fleet.start_monitor(refresh_period=0.2, heartbeat_timeout=0.6, web_port=0)
    run(fleet, 'MARC1', 'fail')
    wait_for_line(fleet, 'monitor', 'MARC1      failed')
    fleet.kill('agent_MARC1')
    wait_for_line(fleet, 'monitor', 'MARC1      offline')


def wait_for_line(fleet, name, text, timeout=10.0):
    deadline = time.monotonic() + timeout
    while text not in fleet.log(name):
        if time.monotonic() > deadline:
            pytest.fail(f'no {text!r} in the {name} log after {timeout:g} s:\n'
                        + fleet.log(name))
        time.sleep(0.1)
