"""Fleet subscriptions (`contract.subscription`) served outside the executor: `catch_up`
hands a node what has arrived before it judges by it."""

import time

import rclpy

from fjsp_common.contract import ROBOT_STATES, catch_up, publisher, subscription
from fjsp_msgs.msg import RobotState
from fjsp_planner.testing import DomainClaim


def test_catch_up_serves_the_waiting_messages_without_the_executor():
    """What a node judges by (a robot's last state) is what has arrived, even when its
    executor has not served the subscription yet: nothing spins here."""
    claim = DomainClaim()
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=claim.domain)
    try:
        node = rclpy.create_node('catching_up', context=context)
        heard = []
        sub = subscription(node, ROBOT_STATES, heard.append)
        out = publisher(node, ROBOT_STATES)
        deadline = time.monotonic() + 10
        while out.get_subscription_count() < 1 and time.monotonic() < deadline:
            time.sleep(0.05)
        for robot in ('R1', 'R2', 'R3'):
            out.publish(RobotState(robot=robot))
        while len(heard) < 3 and time.monotonic() < deadline:
            catch_up(sub)
            time.sleep(0.05)
        assert [msg.robot for msg in heard] == ['R1', 'R2', 'R3']
        catch_up(sub)  # nothing waiting: nothing served
        assert len(heard) == 3
    finally:
        rclpy.try_shutdown(context=context)
        claim.release()
