"""What a fleet does with messages it cannot believe: a malformed plan from anyone in a fleet
without a key, and an agent without the key in a fleet with one."""

import copy
import math

from fjsp_common.contract import LATCHED_QOS, PLAN_TOPIC
from fjsp_msgs.msg import MissionEvent, Plan

from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')


def test_a_plan_with_a_nan_time_scale_fools_no_one(fjsp_fleet):
    """Unauthenticated, anyone may publish a plan; one that cannot be followed (time scale
    NaN) is ignored as malformed: no agent refuses it, so the planner, which judges robots by
    what they refuse, does not plan them away, and the mission completes as planned."""
    fleet = fjsp_fleet(PAPER, time_scale=0.15).start()
    observer = fleet.observer
    fleet.wait_for(lambda o: o.status.jobs_done >= 1, 60, 'the mission under way')
    plans = observer.node.create_publisher(Plan, PLAN_TOPIC, LATCHED_QOS)
    fleet.wait_for(lambda o: plans.get_subscription_count() >= 6, 15,
                   'the fleet to discover the forger')
    forged = copy.deepcopy(observer.plans[-1])
    forged.revision, forged.time_scale = 50, math.nan
    plans.publish(forged)
    # The observer took the forged plan too: the status says how the mission went.
    fleet.wait_for(lambda o: o.complete(), 90, 'the mission to complete')
    with observer.lock:
        refusals = [s.refusal for s in observer.robot_history if s.refusal]
        blocked = [e for e in observer.mission_events if e.kind == MissionEvent.KIND_BLOCKED]
    assert not refusals and not blocked
    assert observer.status.plan_revision == 1 and observer.status.jobs_done == 12
    for robot in ROBOTS:
        assert 'ignoring a malformed plan revision 50' in fleet.log(f'agent_{robot}')


def test_an_agent_without_the_key_is_named_as_unverified(fjsp_fleet):
    """In a fleet with a key, an agent started without it reports unsigned states: the
    planner drops them, and says that they do not verify rather than that the robot is
    silent."""
    fleet = fjsp_fleet(PAPER, time_scale=0.15, key=True,
                       planner={'robot_wait_timeout': 5.0})
    for robot in ROBOTS[:3]:
        fleet.start_agent(robot)
    fleet.start_agent('MARC2', fleet_key_file='')
    fleet.wait_for(lambda o: all(r in o.robots for r in ROBOTS), 60, 'every agent to report')
    fleet.start_planner()
    waiting = "waiting for robot 'MARC2' to report: its states do not verify: not signed"
    fleet.wait_for(lambda o: waiting in o.status.blocked_reasons, 60,
                   'the planner to say why it does not hear MARC2')
    unverified = "robot 'MARC2' sends states that do not verify: not signed"
    fleet.wait_for(lambda o: unverified in o.status.warnings, 60,
                   'the mission to go on without MARC2, saying why')
    fleet.wait_for(lambda o: o.complete(), 90, 'the mission to complete without MARC2')
