"""A scenario whose travel is free without its author meaning it: the launcher prints the
warning before it starts anything, the planner logs it, and the mission runs."""

import os
import subprocess

from repo_paths import DATA

WARNING = ("distances and the start locations of robots 'C1', 'W1' are given, but no "
           'operation type is the travel type')


def test_the_launcher_and_the_planner_warn_and_the_mission_runs(tmp_path, ros_domain):
    scenario = DATA / 'beam_drive.yaml'
    out = tmp_path / 'out'
    env = dict(os.environ, ROS_DOMAIN_ID=str(ros_domain), PYTHONUNBUFFERED='1',
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    run = subprocess.run(['ros2', 'run', 'fjsp_planner', 'fleet', str(scenario), '--out',
                          str(out), '--exit-on-complete', '--time-scale', '0.05',
                          '--timeout', '90', '--no-recording'],
                         env=env, capture_output=True, text=True, timeout=150)
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stderr.startswith(f'fleet: warning: {WARNING}'), run.stderr
    assert "did you mean 'locomote: drive'?" in run.stderr.splitlines()[0]
    planner = (out / 'logs' / 'planner.log').read_text()
    assert f"scenario 'beam': {WARNING}" in planner
    assert 'Traceback' not in ''.join(log.read_text() for log in (out / 'logs').iterdir())
