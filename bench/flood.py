"""A keyless flood of robot states against one receiver of an authenticated fleet: what taking
and dropping one forged message costs, how many a second the receiver takes, and how many of
a signed robot's states it still hears.

First, a backlog of forged states is taken from two histories filled at once, timed per
message: decoded into Python messages then checked, or refused from their bytes.

Three processes on a private ROS domain: a flooder publishing unsigned `RobotState`s as fast as
it can, a robot publishing signed states every --period seconds, and the receiver (this
process) subscribing as the planner does — `contract.subscription` with the node's `NodeAuth`,
which refuses unsigned messages from their bytes — or, with --decode-all, decoding every
message into a Python message before checking it (what a subscription without `auth` does).

Prints figures, never asserts. They depend on the machine's load: the flooder, the robot and
the receiver share its cores.

Run from the repository with the workspace sourced:
    source ros2_ws/env.sh && python bench/flood.py [--seconds 10] [--decode-all]
"""

import argparse
import math
import os
import random
import resource
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import rclpy
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy

from fjsp_common.auth import NodeAuth, new_key
from fjsp_common.contract import ROBOT_STATES, ROBOT_STATES_TOPIC, subscription, take_waiting

FLOODER = """
import math, sys, time
import rclpy
from fjsp_common.contract import ROBOT_STATES, publisher
from fjsp_msgs.msg import RobotState
rclpy.init()
node = rclpy.create_node('flooder')
out = publisher(node, ROBOT_STATES)
forged = RobotState(robot='robot', mode=RobotState.MODE_FAILED, failures=1, busy_until=math.nan)
deadline = time.monotonic() + 10.0
while out.get_subscription_count() == 0 and time.monotonic() < deadline:
    time.sleep(0.1)
time.sleep(0.5)
sent, end = 0, time.monotonic() + float(sys.argv[1])
while time.monotonic() < end:
    out.publish(forged)
    sent += 1
print(sent)
"""

ROBOT = """
import sys, time
import rclpy
from fjsp_common.auth import Signer, read_key
from fjsp_common.contract import ROBOT_STATES, ROBOT_STATES_TOPIC, publisher
from fjsp_msgs.msg import RobotState
rclpy.init()
node = rclpy.create_node('robot')
out = publisher(node, ROBOT_STATES)
signer = Signer(read_key(sys.argv[3]), 'robot')
name = node.resolve_topic_name(ROBOT_STATES_TOPIC)
time.sleep(1.0)
sent, end = 0, time.monotonic() + float(sys.argv[1])
while time.monotonic() < end:
    out.publish(signer.sign(RobotState(robot='robot', busy_until=float('nan')), name))
    sent += 1
    time.sleep(float(sys.argv[2]))
print(sent)
"""


def backlog_cost(node, auth, receive, env) -> None:
    subs = {'decoded then checked': subscription(node, ROBOT_STATES, receive),
            'refused from its bytes': subscription(node, ROBOT_STATES, receive, auth)}
    subprocess.run([sys.executable, '-c', FLOODER, '2'], env=env, stdout=subprocess.PIPE,
                   check=True)
    time.sleep(0.5)
    for how, sub in subs.items():
        before, start = auth.rejected, time.perf_counter()
        while True:
            taken = auth.rejected
            take_waiting(sub, sub.callback)
            if auth.rejected == taken:
                break
        seconds, count = time.perf_counter() - start, auth.rejected - before
        print(f'backlog of {count:,} forged states, {how}: '
              f'{seconds / max(count, 1) * 1e6:.1f} us each ({count / seconds:,.0f} a second)')
        node.destroy_subscription(sub)
    auth.verifier.rejected = 0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seconds', type=float, default=10.0)
    parser.add_argument('--period', type=float, default=0.05,
                        help="seconds between the robot's signed states")
    parser.add_argument('--depth', type=int, default=ROBOT_STATES.qos.depth,
                        help="the receiver's history depth")
    parser.add_argument('--best-effort', action='store_true',
                        help='the receiver subscribes best effort')
    parser.add_argument('--decode-all', action='store_true',
                        help='decode every message before checking it')
    args = parser.parse_args()
    key_file = new_key(Path(tempfile.mkdtemp()) / 'fleet.key')
    env = dict(os.environ, ROS_DOMAIN_ID=str(random.randint(150, 230)),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    os.environ.update(env)
    rclpy.init()
    node = rclpy.create_node('receiver', parameter_overrides=[
        Parameter('fleet_key_file', value=str(key_file))])
    auth = NodeAuth(node, 'receiver')
    heard = []

    def receive(msg) -> None:
        if auth.accept(msg, ROBOT_STATES_TOPIC, {msg.robot}):
            heard.append(time.monotonic())

    backlog_cost(node, auth, receive, env)
    qos = QoSProfile(**{name: getattr(ROBOT_STATES.qos, name)
                        for name in ('reliability', 'durability', 'history')}, depth=args.depth)
    if args.best_effort:
        qos.reliability = ReliabilityPolicy.BEST_EFFORT
    topic = replace(ROBOT_STATES, qos=qos)
    subscription(node, topic, receive, None if args.decode_all else auth)
    flooder = subprocess.Popen([sys.executable, '-c', FLOODER, str(args.seconds)], env=env,
                               stdout=subprocess.PIPE, text=True)
    robot = subprocess.Popen([sys.executable, '-c', ROBOT, str(args.seconds), str(args.period),
                              str(key_file)], env=env, stdout=subprocess.PIPE, text=True)
    end = time.monotonic() + args.seconds + 3.0
    cpu = resource.getrusage(resource.RUSAGE_SELF)
    try:
        while time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.1)
        flooded = int(flooder.communicate(timeout=30)[0])
        signed = int(robot.communicate(timeout=30)[0])
    finally:
        flooder.kill()
        robot.kill()
    now = resource.getrusage(resource.RUSAGE_SELF)
    used = now.ru_utime + now.ru_stime - cpu.ru_utime - cpu.ru_stime
    gaps = [b - a for a, b in zip(heard, heard[1:], strict=False)]
    print(f"{'decoding every message' if args.decode_all else 'refusing unsigned bytes'}: "
          f'depth {args.depth}, {args.seconds:g} s, '
          f'flood {flooded / args.seconds:,.0f} unsigned states/s')
    print(f'  taken and refused: {auth.rejected:,} ({auth.rejected / args.seconds:,.0f}/s, '
          f'{auth.rejected / max(flooded, 1):.0%} of the flood); receiver CPU '
          f'{used:.1f} s, {used / max(auth.rejected, 1) * 1e6:.0f} us a message')
    print(f"  robot's signed states heard: {len(heard)}/{signed}; longest silence "
          f'{max(gaps, default=math.inf):.2f} s')
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
