"""No silent stall: an agent that refuses its plan, or plays a robot the scenario does not
have, shows on mission_status with a reason naming the robot, and the mission goes on
without it where it can."""


from fjsp_msgs.msg import MissionStatus

from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')


def test_type_mismatch_and_unknown_agent_reach_mission_status(fjsp_fleet):
    fleet = fjsp_fleet(PAPER, time_scale=0.1)
    observer = fleet.observer
    fleet.start_planner()
    for robot in ROBOTS:
        # MARC1 is started as an LSMS: it must refuse a plan that makes it a MARC.
        fleet.start_agent(robot, 'lsms_agent' if robot == 'MARC1' else 'robot_agent')
    fleet.start_agent('R2D2')
    fleet.wait_for(lambda o: o.status is not None and any(
        "robot 'MARC1' refuses its plan" in w for w in o.status.warnings)
        and any("'R2D2'" in w for w in o.status.warnings), 30,
        'warnings naming the refusing MARC1 and the unknown R2D2')
    warnings = '\n'.join(observer.status.warnings)
    assert "makes 'MARC1' a 'MARC' but this agent plays a 'LSMS'" in warnings
    assert "scenario 'solar_panel' has no such robot" in warnings
    # The plan in force leaves the refusing robot out, and the others complete the mission.
    fleet.wait_for(lambda o: o.complete(), 60, 'the mission to complete without MARC1')
    last = observer.plans[-1]
    assert not next(r for r in last.robots if r.robot == 'MARC1').tasks
    assert observer.status.state == MissionStatus.STATE_COMPLETE
    assert observer.robots['MARC1'].refusal
    assert 'no robot' in observer.robots['R2D2'].refusal
