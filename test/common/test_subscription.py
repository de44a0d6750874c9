"""Fleet subscriptions (`contract.subscription`) served outside the executor: `catch_up`
hands a node what has arrived before it judges by it."""

import time

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from fjsp_common.contract import DRAIN, ROBOT_STATES, catch_up, publisher, subscription
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


def test_catch_up_serves_every_message_waiting_however_many():
    """A node that fell behind a flood judges by the newest states, which come last, not by
    the first thousand of those waiting: a robot's own state after 3000 forged ones is heard
    by one catch-up."""
    claim = DomainClaim()
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=claim.domain)
    try:
        node = rclpy.create_node('catching_up', context=context)
        watcher = rclpy.create_node('watching', context=context)
        heard, seen = [], []
        sub = subscription(node, ROBOT_STATES, heard.append)
        watcher.create_subscription(RobotState, ROBOT_STATES.name, seen.append, ROBOT_STATES.qos)
        # A flooder's writer that keeps all it sends until each reader has it.
        out = node.create_publisher(RobotState, ROBOT_STATES.name, QoSProfile(
            depth=5000, reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL))
        deadline = time.monotonic() + 20
        while out.get_subscription_count() < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
        forged = 3 * DRAIN
        for _ in range(forged):
            out.publish(RobotState(robot='forged'))
        out.publish(RobotState(robot='R1'))
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(watcher)
        while (not seen or seen[-1].robot != 'R1') and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.1)
        assert seen and seen[-1].robot == 'R1', 'the states never arrived'
        catch_up(sub)
        assert len(heard) == forged + 1 and heard[-1].robot == 'R1'
    finally:
        rclpy.try_shutdown(context=context)
        claim.release()
