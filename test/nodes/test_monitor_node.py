"""The monitor node built in-process (no fleet): it publishes the robots' poses and the map's
markers when a robot moved, nothing when nothing did, and clears the picture once when the
mission that follows a mission on a map has none."""

import math
import time

import pytest
import rclpy

from fjsp_common.vocabulary import MissionState, RobotMode
from fjsp_planner.nodes.monitor import MonitorNode
from fjsp_planner.observe.facts import MapPlace, PlanFact, RobotStateFact, StatusFact
from fjsp_planner.testing import DomainClaim


@pytest.fixture
def monitor():
    claim = DomainClaim()
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=claim.domain)
    node = None
    try:
        node = MonitorNode(context=context, parameter_overrides=[
            rclpy.parameter.Parameter('web_port', value=0)])
        node.published = []
        node.poses_pub.publish = lambda msg: node.published.append(('poses', msg))
        node.map_pub.publish = lambda msg: node.published.append(('map', msg))
        yield node
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown(context=context)
        claim.release()


def mission(mission_id: str, start: float, places=()) -> list:
    """A plan of robot R1 and a status saying the mission executes."""
    return [PlanFact(stamp=start, mission_id=mission_id, revision=1, scenario_id='s',
                     mission_start=start, time_scale=1.0, cancelled=False, makespan=10.0,
                     solver_status='optimal', lower_bound=10.0, reasons=(),
                     robots=(('R1', 'Rover'),), tasks=(), places=tuple(places)),
            StatusFact(stamp=start, mission_id=mission_id, state=MissionState.EXECUTING,
                       revision=1, scenario_id='s', jobs_done=0, jobs_running=0, jobs_total=1,
                       planned_makespan=10.0, projected_makespan=10.0, elapsed=0.0,
                       blocked_reasons=(), replan_reasons=(), warnings=(), ignored=(0, 0, 0))]


def travelling(mission_id: str, stamp: float, progress: float) -> RobotStateFact:
    return RobotStateFact(stamp=stamp, robot='R1', robot_type='Rover', incarnation=1,
                          mission_id=mission_id, mode=RobotMode.TRAVELLING, revision=1,
                          refusal='', failures=0, current_job='J', location='dock',
                          destination='site', progress=progress, busy_until=math.nan)


def test_poses_follow_the_robot_and_a_mission_without_a_map_clears_them(monitor):
    now = time.time()
    for fact in mission('m1', now - 5, [MapPlace('dock', 0, 0, 0), MapPlace('site', 4, 0, 0)]):
        monitor.fleet.add(fact)
    monitor.fleet.add(travelling('m1', now, 0.25))
    monitor.publish_map()
    [(_, poses), (_, markers)] = monitor.published
    assert poses.header.frame_id == 'map'
    assert [(p.position.x, p.position.y) for p in poses.poses] == [(1.0, 0.0)]
    assert {m.text for m in markers.markers} >= {'dock', 'site', 'R1'}
    monitor.publish_map()
    assert len(monitor.published) == 2, 'nothing moved, nothing is published'
    monitor.fleet.add(travelling('m1', now + 0.1, 0.5))
    monitor.publish_map()
    assert monitor.published[2][1].poses[0].position.x == 2.0

    for fact in mission('m2', now + 1):
        monitor.fleet.add(fact)
    monitor.publish_map()
    [(_, poses), (_, markers)] = monitor.published[4:]
    assert list(poses.poses) == []
    assert [m.action for m in markers.markers] == [markers.markers[0].DELETEALL]
    monitor.publish_map()
    assert len(monitor.published) == 6, 'cleared once'
