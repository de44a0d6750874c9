"""Deeply nested YAML through every input path — a scenario file for `fjsp-solve` and `fleet`,
a parameters file, a RunMission goal inline and by path, a fragment added mid-mission — is
refused naming the limit: no process crashes, and a running mission goes on."""

import os
import subprocess
import time

import pytest
from rclpy.action import ActionClient

from fjsp_common.contract import RUN_MISSION_ACTION
from fjsp_msgs.action import RunMission
from fjsp_planner.launcher.supervision import find_executable
from fjsp_planner.missions import MissionClient, MissionError

from repo_paths import PAPER

DEEP = '[' * 30000 + ']' * 30000
"""60 KB: the C YAML loader overflowed the C stack on it (SIGSEGV)."""
DEEP_FRAGMENT = 'jobs: ' + '[' * 2000 + ']' * 2000
"""4 KB: the Python YAML loader raised RecursionError on it."""
LIMIT = 'YAML nesting deeper than 64 levels at line'


def run(tmp_path, env, package, executable, *args):
    done = subprocess.run([str(find_executable(package, executable)), *args], env=env,
                          capture_output=True, text=True, timeout=60, cwd=tmp_path)
    return done.returncode, done.stdout + done.stderr


def test_fjsp_solve_and_fleet_refuse_deep_files_with_exit_2(tmp_path, ros_domain):
    env = dict(os.environ, ROS_DOMAIN_ID=str(ros_domain),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    deep = tmp_path / 'deep.yaml'
    deep.write_text(DEEP)
    params = tmp_path / 'params.yaml'
    params.write_text('/**:\n  ros__parameters:\n    x: ' + DEEP + '\n')
    for command in (('fjsp_planner', 'fjsp-solve', str(deep)),
                    ('fjsp_planner', 'fleet', str(deep), '--out', str(tmp_path / 'out')),
                    ('fjsp_planner', 'fleet', str(PAPER), '--params-file', str(params),
                     '--out', str(tmp_path / 'out'))):
        code, output = run(tmp_path, env, *command)
        assert code == 2, output
        assert LIMIT in output and 'Traceback' not in output


def goal_by_path(observer, path: str, timeout: float = 30.0) -> RunMission.Result:
    """The result of a RunMission goal naming a scenario file on the planner's machine."""
    client = ActionClient(observer.node, RunMission, RUN_MISSION_ACTION)
    try:
        assert client.wait_for_server(timeout_sec=timeout), 'no RunMission server'
        sent = client.send_goal_async(RunMission.Goal(scenario_path=path))
        deadline = time.monotonic() + timeout
        while not sent.done() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert sent.done() and sent.result().accepted, 'the goal was not answered'
        result = sent.result().get_result_async()
        while not result.done() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert result.done(), 'the goal got no result'
        return result.result().result
    finally:
        client.destroy()


def test_the_planner_refuses_deep_goals_and_fragments_and_the_mission_goes_on(fjsp_fleet,
                                                                              tmp_path):
    fleet = fjsp_fleet(PAPER, time_scale=0.3).start()
    fleet.wait_for(lambda o: o.status.jobs_done >= 1, 60, 'the mission under way')
    fragment = tmp_path / 'fragment.yaml'
    fragment.write_text(DEEP_FRAGMENT)
    added = fleet.run('fjsp_planner', 'mission', 'add', str(fragment))
    assert added.returncode == 1, added.stdout + added.stderr
    assert f'fragment: {LIMIT}' in added.stderr and 'Traceback' not in added.stderr
    deep = tmp_path / 'deep.yaml'
    deep.write_text(DEEP)
    with MissionClient(domain_id=fleet.domain) as client, \
            pytest.raises(MissionError) as refused:
        client.submit(scenario_yaml=DEEP)
    assert any(LIMIT in p for p in refused.value.problems), refused.value.problems
    result = goal_by_path(fleet.observer, str(deep))
    assert result.state == RunMission.Result.STATE_REJECTED
    assert any(LIMIT in r for r in result.reasons), result.reasons
    fleet.check_mission_complete(timeout=90)
    assert 'planner' not in fleet.exited()
    assert 'Traceback' not in fleet.log('planner')
