"""`run_node`, the loop every node process runs: it releases what it used before rclpy shuts
down, so no finaliser runs on a destroyed handle when the process exits."""

import signal

import pytest
import rclpy
from rclpy.node import Node

from fjsp_common import running
from fjsp_planner.testing import DomainClaim


@pytest.fixture
def own_domain(monkeypatch):
    claim = DomainClaim()
    monkeypatch.setenv('ROS_DOMAIN_ID', str(claim.domain))
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    handlers = {sig: signal.getsignal(sig) for sig in running.STOP_SIGNALS}
    try:
        yield
    finally:
        for sig, handler in handlers.items():  # run_node ignores them once it is done
            signal.signal(sig, handler)
        claim.release()


def test_the_executor_is_shut_down_before_rclpy(own_domain, monkeypatch):
    # An executor left to its finaliser destroys its signal guard condition at interpreter
    # exit, when rclpy may have destroyed it already: "Exception ignored in: Executor.__del__
    # ... InvalidHandle" in a node's log, now and then, after a clean stop.
    shut_down = []
    """Whether rclpy was still up, at each executor shutdown."""

    class Recorded(running.SingleThreadedExecutor):
        def shutdown(self, *args, **kwargs):
            shut_down.append(rclpy.ok())
            return super().shutdown(*args, **kwargs)

    monkeypatch.setattr(running, 'SingleThreadedExecutor', Recorded)
    code = running.run_node(lambda: Node('run_node_test'), 'run_node_test',
                            done=lambda node: True)
    assert code == 0
    assert shut_down == [True]
