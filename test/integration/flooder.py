"""A keyless flooder, run as its own process: `flooder.py SECONDS TOPIC ROBOT...` publishes
unsigned messages on TOPIC (robot_states: each robot failed; plan; mission_status: COMPLETE)
as fast as it can for SECONDS, then prints how many it sent. `start(seconds, topic, robots,
env)` runs it."""

import math
import subprocess
import sys
import time


def start(seconds: float, topic: str, robots, env) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, __file__, str(seconds), topic, *robots], env=env,
                            stdout=subprocess.PIPE, text=True)


def forged(topic: str, robots) -> list:
    from fjsp_msgs.msg import MissionStatus, Plan, RobotState
    if topic == 'robot_states':
        return [RobotState(robot=robot, mode=RobotState.MODE_FAILED, failures=1,
                           busy_until=math.nan) for robot in robots]
    if topic == 'plan':
        return [Plan(mission_id='forged', revision=1000 + n) for n in range(len(robots))]
    return [MissionStatus(mission_id='forged', state=MissionStatus.STATE_COMPLETE,
                          jobs_done=n, jobs_total=n) for n in range(1, len(robots) + 1)]


def main() -> None:
    import rclpy

    from fjsp_common.contract import MISSION_STATUS, PLAN, ROBOT_STATES, publisher
    seconds, topic, robots = float(sys.argv[1]), sys.argv[2], sys.argv[3:]
    rclpy.init()
    node = rclpy.create_node('flooder')
    out = publisher(node, {'robot_states': ROBOT_STATES, 'plan': PLAN,
                           'mission_status': MISSION_STATUS}[topic])
    messages = forged(topic, robots)
    sent, end = 0, time.monotonic() + seconds
    while time.monotonic() < end:
        for msg in messages:
            out.publish(msg)
        sent += len(messages)
    print(sent)


if __name__ == '__main__':
    main()
