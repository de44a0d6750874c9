"""Stale revisions, duplicated events and unknown names are ignored, logged and counted."""

import copy

from harness import ROBOTS

from fjsp_msgs.msg import Plan, RobotState, TaskEvent
from fjsp_planner.nodes.interfaces import (
    EVENTS_QOS,
    LATCHED_QOS,
    PLAN_TOPIC,
    ROBOT_STATES_TOPIC,
    TASK_EVENTS_TOPIC,
)


def test_bad_messages_are_ignored_and_counted(launcher, observer):
    # Slow enough (32 units * 0.15 s) that the bad messages land mid-mission.
    launcher.start_planner(time_scale=0.15)
    for robot, _ in ROBOTS:
        launcher.start_agent(robot)
    observer.wait_for(lambda o: any(e.kind == TaskEvent.KIND_JOB_DONE for e in o.events), 30,
                      'the first job to complete')
    plans = observer.publisher(Plan, PLAN_TOPIC, LATCHED_QOS)
    events = observer.publisher(TaskEvent, TASK_EVENTS_TOPIC, EVENTS_QOS)
    states = observer.publisher(RobotState, ROBOT_STATES_TOPIC, LATCHED_QOS)
    observer.wait_for(lambda o: plans.get_subscription_count() >= 5
                      and events.get_subscription_count() >= 5, 10,
                      'the nodes to discover the test publishers')

    stale = copy.deepcopy(observer.plans[-1])
    stale.revision = 0
    plans.publish(stale)
    with observer.lock:
        original = next(e for e in observer.events if e.kind == TaskEvent.KIND_STARTED)
    events.publish(original)
    events.publish(TaskEvent(event_id='R2D2/M1/started/1', kind=TaskEvent.KIND_STARTED,
                             robot='R2D2', job='M1', plan_revision=1, time=1.0))
    events.publish(TaskEvent(event_id='MARC1/Zz/started/1', kind=TaskEvent.KIND_STARTED,
                             robot='MARC1', job='Zz', plan_revision=1, time=1.0))
    states.publish(RobotState(robot='R2D2', mode=RobotState.MODE_IDLE))

    observer.wait_for(lambda o: o.status.ignored_stale >= 1 and o.status.ignored_duplicate >= 1
                      and o.status.ignored_unknown >= 3, 10,
                      'the planner to count the ignored messages')
    observer.wait_for(lambda o: o.complete(), 60, 'the mission to complete anyway')
    status = observer.status
    assert (status.ignored_stale, status.ignored_duplicate, status.ignored_unknown) == (1, 1, 3)
    assert status.jobs_done == 12
    planner = launcher.log('planner')
    assert 'ignoring stale plan revision 0' in planner
    assert f"event '{original.event_id}' was already received" in planner
    assert "unknown robot 'R2D2'" in planner
    assert "unknown job 'Zz'" in planner
    assert "state of unknown robot 'R2D2'" in planner
    for robot, _ in ROBOTS:
        assert 'ignoring stale plan revision 0' in launcher.log(f'{robot.lower()}_agent')
        assert observer.robots[robot].plan_revision == 1
