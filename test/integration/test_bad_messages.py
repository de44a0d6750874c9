"""Stale revisions, duplicated events and unknown names are ignored, logged and counted."""

import copy
import time

from fjsp_common.contract import (
    EVENTS_QOS,
    LATCHED_QOS,
    PLAN_TOPIC,
    ROBOT_STATES_TOPIC,
    TASK_EVENTS_TOPIC,
)
from fjsp_msgs.msg import Plan, RobotState, TaskEvent

from repo_paths import PAPER


def test_bad_messages_are_ignored_and_counted(fjsp_fleet):
    # Slow enough (32 units * 0.15 s) that the bad messages land mid-mission.
    fleet = fjsp_fleet(PAPER, time_scale=0.15).start()
    observer = fleet.observer
    # Each writer is discovered on its own: the planner's job-done may come before any
    # agent's event, so wait for both kinds.
    fleet.wait_for(lambda o: {TaskEvent.KIND_JOB_DONE, TaskEvent.KIND_STARTED}
                      <= {e.kind for e in o.events}, 30, 'the first job to start and complete')
    plans = observer.node.create_publisher(Plan, PLAN_TOPIC, LATCHED_QOS)
    events = observer.node.create_publisher(TaskEvent, TASK_EVENTS_TOPIC, EVENTS_QOS)
    states = observer.node.create_publisher(RobotState, ROBOT_STATES_TOPIC, LATCHED_QOS)
    # Subscribers: planner, four agents and this observer (plan, events); planner and
    # observer (states). Latched writers would deliver late anyway, but within the wait.
    fleet.wait_for(lambda o: plans.get_subscription_count() >= 6
                      and events.get_subscription_count() >= 6
                      and states.get_subscription_count() >= 2, 15,
                      'the nodes to discover the test publishers')

    stale = copy.deepcopy(observer.plans[-1])
    stale.revision = 0
    plans.publish(stale)
    with observer.lock:
        original = next(e for e in observer.events if e.kind == TaskEvent.KIND_STARTED)
    events.publish(original)
    mission = original.mission_id
    events.publish(TaskEvent(event_id='R2D2/M1/started/1', mission_id=mission,
                             kind=TaskEvent.KIND_STARTED, robot='R2D2', job='M1',
                             plan_revision=1, time=1.0))
    events.publish(TaskEvent(event_id='MARC1/Zz/started/1', mission_id=mission,
                             kind=TaskEvent.KIND_STARTED, robot='MARC1', job='Zz',
                             plan_revision=1, time=1.0))
    # Robot states are heartbeats: publish a few, as a robot would; counted once per robot.
    for _ in range(10):
        states.publish(RobotState(robot='R2D2', mode=RobotState.MODE_IDLE))
        time.sleep(0.2)

    fleet.wait_for(lambda o: o.status.ignored_stale >= 1 and o.status.ignored_duplicate >= 1
                      and o.status.ignored_unknown >= 3, 15,
                      'the planner to count 1 stale, 1 duplicate and 3 unknown messages')
    fleet.wait_for(lambda o: o.complete(), 60, 'the mission to complete anyway')
    status = observer.status
    assert (status.ignored_stale, status.ignored_duplicate, status.ignored_unknown) == (1, 1, 3)
    assert status.jobs_done == 12
    planner = fleet.log('planner')
    assert 'ignoring stale plan revision 0' in planner
    assert f"event '{original.event_id}' was already received" in planner
    assert "unknown robot 'R2D2'" in planner
    assert "unknown job 'Zz'" in planner
    assert "agent of robot 'R2D2' is running, but scenario 'solar_panel' has no such robot" \
        in planner
    for robot in ('Assembler', 'LSMS', 'MARC1', 'MARC2'):
        assert 'ignoring stale plan revision 0' in fleet.log(f'agent_{robot}')
        assert observer.robots[robot].plan_revision == 1
