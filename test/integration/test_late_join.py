"""Latched plan and kept events: nodes started after the plan was published still catch up."""

from harness import ROBOTS

from fjsp_msgs.msg import MissionStatus, RobotState


def test_agent_and_monitor_started_after_the_plan(launcher, observer, tmp_path):
    # MARC2 is missing: the planner waits 3 s for it, then plans without it, saying so.
    launcher.start_planner(robot_wait_timeout=3.0, time_scale=0.3)
    for robot, _ in ROBOTS[:3]:
        launcher.start_agent(robot)
    observer.wait_for(lambda o: o.plans, 30, 'the plan')
    first = observer.plans[0]
    assert not next(r for r in first.robots if r.robot == 'MARC2').tasks
    observer.wait_for(lambda o: any("robot 'MARC2' has not reported" in w
                                    for w in o.status.warnings), 10,
                      'a warning naming the missing MARC2')
    launcher.start_agent('MARC2')
    observer.wait_for(lambda o: 'MARC2' in o.robots and o.plans[-1].revision > 1
                      and o.robots['MARC2'].plan_revision == o.plans[-1].revision, 20,
                      'the late MARC2 agent to be planned in and follow the new revision')
    assert any("robot 'MARC2' available" in r for r in observer.plans[-1].reasons)
    observer.wait_for(lambda o: o.complete(), 60, 'the mission to complete')
    assert not observer.status.warnings

    # A monitor started after the mission ended still gets plan, status and events.
    launcher.start('monitor', 'fjsp_planner', 'monitor_node',
                   [('gantt_dir', tmp_path / 'gantt'), ('exit_on_complete', True)])
    code = launcher.processes['monitor'].wait(timeout=30)
    log = launcher.log('monitor')
    assert code == 0, log
    assert 'complete' in log
    assert len(list((tmp_path / 'gantt').glob('*.png'))) == 1
    assert observer.status.state == MissionStatus.STATE_COMPLETE
    assert observer.robots['MARC2'].mode == RobotState.MODE_IDLE
