"""Latched plan and kept events: nodes started after the plan was published still catch up."""

from harness import ROBOTS

from fjsp_msgs.msg import MissionStatus, RobotState


def test_agent_and_monitor_started_after_the_plan(launcher, observer, tmp_path):
    # MARC2 is missing: the planner waits 1 s for it, then plans with all four robots anyway.
    launcher.start_planner(robot_wait_timeout=1.0)
    for robot, _ in ROBOTS[:3]:
        launcher.start_agent(robot)
    observer.wait_for(lambda o: o.plans, 30, 'the plan')
    revision = observer.plans[-1].revision
    launcher.start_agent('MARC2')
    observer.wait_for(lambda o: 'MARC2' in o.robots
                      and o.robots['MARC2'].plan_revision == revision, 20,
                      'the late MARC2 agent to follow the published plan')
    observer.wait_for(lambda o: o.complete(), 60, 'the mission to complete')
    # Discovery may be slow for the others too; MARC2 at least cannot have reported.
    warning = next(line for line in launcher.log('planner').splitlines()
                   if 'planning without a report from' in line)
    assert 'MARC2' in warning

    # A monitor started after the mission ended still gets plan, status and events.
    launcher.start('monitor', 'fjsp_planner', 'monitor_node',
                   [('out_dir', tmp_path / 'out'), ('exit_on_complete', True),
                    ('web_port', 0)])
    code = launcher.processes['monitor'].wait(timeout=30)
    log = launcher.log('monitor')
    assert code == 0, log
    assert 'complete: 12/12 jobs done (planner: 12/12)' in log
    assert len(list((tmp_path / 'out').glob('*.png'))) == 1
    assert observer.status.state == MissionStatus.STATE_COMPLETE
    assert observer.robots['MARC2'].mode == RobotState.MODE_IDLE
