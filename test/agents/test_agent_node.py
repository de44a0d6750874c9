"""The robot agent built in-process (no fleet): what it hears of a mission before the mission's
plan reaches it counts once the plan comes, in an authenticated fleet too."""

from fractions import Fraction

import pytest
import rclpy

from fjsp_common.auth import Signer, new_key, read_key
from fjsp_common.contract import PLAN_TOPIC, TASK_EVENTS_TOPIC
from fjsp_common.fleet import PLANNER_NODE
from fjsp_common.vocabulary import RobotMode
from fjsp_msgs.msg import TaskEvent
from fjsp_planner.model.problem import Job, Problem, Robot
from fjsp_planner.model.schedule import JobAssignment, Result, Schedule, Status
from fjsp_planner.nodes.conversions import plan_msg
from fjsp_planner.testing import DomainClaim
from robot_agents.agent_node import RobotAgent

MISSION = 'early-reports'


@pytest.fixture
def agent_and_key(tmp_path):
    """The agent of robot A in a fleet keyed with a new key, and that key."""
    key_file = new_key(tmp_path / 'fleet.key')
    claim = DomainClaim()
    rclpy.init(args=['--ros-args', '-p', f'fleet_key_file:={key_file}'],
               domain_id=claim.domain)
    agent = None
    try:
        agent = RobotAgent('A')
        yield agent, read_key(key_file)
    finally:
        if agent is not None:
            agent.destroy_node()
        rclpy.try_shutdown()
        claim.release()


def _plan(agent):
    """Revision 1: A and B weld x together, at the place both start at, for 100 units."""
    problem = Problem(operation_types={1: 'weld'}, robot_types={'Arm': {1: Fraction(100)}},
                      robots=(Robot('A', 'Arm', start_location='here'),
                              Robot('B', 'Arm', start_location='here')),
                      jobs=(Job('x', 'here', ((1, 1),)),))
    schedule = Schedule({'x': JobAssignment('x', 0, Fraction(0), Fraction(100),
                                            {'A': 1, 'B': 1})}, {'A': ('x',), 'B': ('x',)})
    result = Result(Status.OPTIMAL, Fraction(100), Fraction(100), 0.0, schedule, 'test')
    now = agent.get_clock().now().to_msg()
    return plan_msg(problem, problem, schedule, result, MISSION, 1, now, 1.0, now)


def test_a_co_worker_heard_before_the_plan_is_waited_for_no_longer(agent_and_key):
    """B reports its arrival at x before A's plan comes (the plan was delayed): once the
    plan comes, A, there already, starts x with B instead of waiting for B for ever."""
    agent, key = agent_and_key
    arrival = TaskEvent(kind=TaskEvent.KIND_ARRIVED, robot='B', job='x', mission_id=MISSION,
                        plan_revision=1, time=0.0, event_id='B-1')
    agent.on_event(Signer(key, 'B').sign(arrival, agent.auth.resolve(TASK_EVENTS_TOPIC)))
    assert agent.execution.mode != RobotMode.WORKING
    agent.on_plan(Signer(key, PLANNER_NODE).sign(_plan(agent), agent.auth.resolve(PLAN_TOPIC)))
    agent.tick()
    assert agent.execution.current_job == 'x'
    assert agent.execution.mode == RobotMode.WORKING
