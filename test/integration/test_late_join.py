"""Latched plan, states and kept events: nodes started after the plan was published, or after
the mission ended, still catch up."""

import time

from rclpy.time import Time

from fjsp_common.contract import LATCHED_READER_QOS, ROBOT_STATES_TOPIC
from fjsp_msgs.msg import MissionStatus, RobotState
from fjsp_planner.launcher.listener import Listener

from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')


def test_agent_and_monitor_started_after_the_plan(fjsp_fleet, tmp_path):
    # MARC2 is missing: the planner waits 3 s for it, then plans without it, saying so.
    fleet = fjsp_fleet(PAPER, time_scale=0.3, planner={'robot_wait_timeout': 3.0})
    fleet.start_planner()
    for robot in ROBOTS[:3]:
        fleet.start_agent(robot)
    fleet.wait_for(lambda o: o.plans, 30, 'the plan')
    first = fleet.observer.plans[0]
    assert not next(r for r in first.robots if r.robot == 'MARC2').tasks
    fleet.wait_for(lambda o: any("robot 'MARC2' has not reported" in w
                                 for w in o.status.warnings), 10,
                   'a warning naming the missing MARC2')
    fleet.start_agent('MARC2')
    fleet.wait_for(lambda o: 'MARC2' in o.robots and o.plans[-1].revision > 1
                   and o.robots['MARC2'].plan_revision == o.plans[-1].revision, 20,
                   'the late MARC2 agent to be planned in and follow the new revision')
    assert any("robot 'MARC2' available" in r for r in fleet.observer.plans[-1].reasons)
    fleet.wait_for(lambda o: o.complete(), 60, 'the mission to complete')
    assert not fleet.observer.status.warnings

    # A monitor started after the mission ended still gets plan, status and events.
    monitor = fleet.start_monitor(out_dir=tmp_path / 'out', exit_on_complete=True, web_port=0)
    code = monitor.wait(timeout=30)
    log = fleet.log('monitor')
    assert code == 0, log
    assert 'complete: 12/12 jobs done (planner: 12/12)' in log
    assert len(list((tmp_path / 'out').glob('*.png'))) == 1
    assert fleet.observer.status.state == MissionStatus.STATE_COMPLETE
    assert fleet.observer.robots['MARC2'].mode == RobotState.MODE_IDLE


def test_a_late_subscriber_gets_every_robots_state(fjsp_fleet):
    # Heartbeats every 10 s: after the mission the agents stay silent for seconds, so what a
    # late subscriber gets at once is what DDS kept for it, one latched state per agent.
    fleet = fjsp_fleet(PAPER, agents={'heartbeat_period': 10.0},
                       planner={'heartbeat_timeout': 60.0}).start()
    fleet.wait_for(lambda o: o.complete(), 60, 'the mission to complete')
    late = Listener(fleet.domain, name='late_subscriber', discovery_range='LOCALHOST')
    states: dict[str, RobotState] = {}
    try:
        # Matched first, then given time to receive before its executor takes anything: a
        # reader that keeps fewer samples than there are robots loses all but the last.
        late.executor.remove_node(late.node)
        late.subscribe(RobotState, ROBOT_STATES_TOPIC, LATCHED_READER_QOS,
                       lambda msg: states.setdefault(msg.robot, msg))
        deadline = time.monotonic() + 30
        while late.node.count_publishers(ROBOT_STATES_TOPIC) < len(ROBOTS):
            assert time.monotonic() < deadline, 'the agents were not discovered within 30 s'
            time.sleep(0.1)
        time.sleep(1.0)
        # A heartbeat may replace an agent's kept state between matching and now (agents keep
        # one): what counts is that each state was there before the subscriber took any.
        taken = time.time_ns()
        late.executor.add_node(late.node)
        late.wait_for(lambda: len(states) == len(ROBOTS), 30)
    finally:
        late.close()
    assert sorted(states) == sorted(ROBOTS)
    # Each state is one the agent published before the subscriber took any: kept, not new.
    for robot, state in states.items():
        assert Time.from_msg(state.stamp).nanoseconds < taken, robot
        assert state.mode == RobotState.MODE_IDLE, robot
