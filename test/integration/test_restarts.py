"""Restarts in the middle of a mission: a planner killed just after declaring a job done, an
agent killed while the planner is down, an agent restarted mid-job, a planner resuming after
an earlier mission. Nothing is done twice, nothing is lost."""

import time

from fjsp_common.fleet import agent_node_name
from fjsp_msgs.msg import MissionStatus, RobotState, TaskEvent
from fjsp_planner.testing import valid_events

from repo_paths import SCENARIOS


def test_a_planner_killed_just_after_declaring_a_job_done_does_not_declare_it_again(
        fjsp_fleet, tmp_path):
    fleet = fjsp_fleet(SCENARIOS / 'solar_panel.yaml', time_scale=0.15,
                       planner={'journal_dir': tmp_path / 'journal'}).start()
    observer = fleet.observer
    deadline = time.monotonic() + 60
    while not any(e.kind == TaskEvent.KIND_JOB_DONE for e in observer.events):
        assert time.monotonic() < deadline, 'no job done within 60 s'
        time.sleep(0.001)
    fleet.kill('planner')  # within milliseconds of its first JOB_DONE
    fleet.start_planner()
    fleet.check_mission_complete(timeout=90)  # every job declared done exactly once


def test_an_agent_killed_while_the_planner_is_down_hands_its_reports_on(fjsp_fleet, tmp_path):
    """An operation finished while no planner runs is known only to the agent that reported
    it (and the co-workers and successors that went on from it). Its agent killed too, a
    planner resuming the mission never learnt it was done, and the mission did not complete.
    The agent's reports_dir hands the reports to the next agent of the robot."""
    fleet = fjsp_fleet(SCENARIOS / 'solar_panel.yaml', time_scale=0.15,
                       planner={'journal_dir': tmp_path / 'journal'},
                       agents={'reports_dir': tmp_path / 'reports'}).start()
    observer = fleet.observer
    fleet.wait_for(lambda o: o.schedule_time() >= 1, 60, 'the mission under way')
    fleet.kill('planner')
    with observer.lock:
        seen = len(observer.events)

    def done_since(o):
        return [e for e in list(o.events)[seen:] if e.kind == TaskEvent.KIND_OPERATION_DONE]

    fleet.wait_for(done_since, 60, 'an operation done while the planner is down')
    robot = done_since(observer)[0].robot
    fleet.kill(agent_node_name(robot))
    fleet.start_agent(robot)
    fleet.start_planner()
    fleet.check_mission_complete(timeout=120)
    with observer.lock:
        apart = started_together(list(observer.plans), list(observer.events))
    assert not apart, apart


def started_together(plans, events) -> list[str]:
    """Jobs of the last attempts whose robots did not start them at the same instant, as
    every robot of a job must (docs/ros-interfaces.md, How execution is timed)."""
    starts = {}
    for e in valid_events(plans, events):
        if e.kind == TaskEvent.KIND_STARTED:
            starts.setdefault(e.job, {})[e.robot] = e.time
    return [f'{job}: {times}' for job, times in sorted(starts.items())
            if max(times.values()) - min(times.values()) > 1e-3]


def test_a_restarted_agent_does_not_finish_alone_a_job_it_began_with_others(fjsp_fleet):
    """On the antenna, S2 is killed while it works on a job with another robot; the planner,
    with S2 offline, cannot staff the dish test (it needs both spiders) and blocks. A new S2
    agent starts, takes the latched revision and does that job alone, after its co-worker
    finished its part long before."""
    fleet = fjsp_fleet(SCENARIOS / 'antenna.yaml', time_scale=0.3).start()
    observer = fleet.observer
    fleet.wait_for(lambda o: o.plans, 60, 'the first plan')
    shared = next(t.job for r in observer.plans[0].robots if r.robot == 'S2'
                  for t in r.tasks if t.co_workers)
    fleet.wait_for(lambda o: 'S2' in o.robots and o.robots['S2'].current_job == shared
                   and o.robots['S2'].mode == RobotState.MODE_WORKING, 60,
                   f'S2 at work on {shared}')
    fleet.kill('agent_S2')
    fleet.wait_for(lambda o: any("'S2'" in r and 'offline' in r
                                 for r in o.status.blocked_reasons + o.status.warnings), 20,
                   'the planner to see S2 offline')
    fleet.start_agent('S2')
    fleet.check_mission_complete(timeout=90)
    with observer.lock:
        apart = started_together(list(observer.plans), list(observer.events))
    assert not apart, apart


def test_a_mission_resumed_after_another_is_judged_from_where_its_robots_started(
        fjsp_fleet, tmp_path):
    """On the truss, the second mission starts each robot where the first left it. Its
    planner is killed mid-mission and restarted: the resumed mission used to be judged from
    the scenario's start locations (the gantry 'at the depot', 16 units from its first job)
    and FAILED on a violation that never happened."""
    from fjsp_planner.missions import MissionClient

    fleet = fjsp_fleet(SCENARIOS / 'truss.yaml', time_scale=0.1,
                       planner={'journal_dir': tmp_path / 'journal'})
    fleet.start_planner(scenario='')
    for robot in fleet.problem.robots:
        fleet.start_agent(robot.name)
    observer = fleet.observer
    fleet.wait_for(lambda o: len(o.robots) == len(fleet.problem.robots), 60, 'every agent')
    with MissionClient(domain_id=fleet.domain) as client:
        assert client.run(SCENARIOS / 'truss.yaml', timeout=90).complete
        second = client.submit(SCENARIOS / 'truss.yaml')
        fleet.wait_for(lambda o: o.status.mission_id == second.mission_id
                       and o.status.jobs_done >= 1, 60, 'the second mission under way')
        fleet.kill('planner')
        fleet.start_planner(scenario='')
        fleet.wait_for(lambda o: o.status.mission_id == second.mission_id
                       and o.status.state in (MissionStatus.STATE_COMPLETE,
                                              MissionStatus.STATE_FAILED), 90,
                       'the second mission to end')
    assert observer.status.state == MissionStatus.STATE_COMPLETE, (
        observer.status.blocked_reasons, fleet.log('planner')[-4000:])
