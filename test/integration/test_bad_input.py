"""Bad parameters and command lines: a clear message naming the item, a non-zero exit code,
no traceback and no hang."""

import subprocess

import pytest
from harness import SCENARIO


@pytest.mark.parametrize(('command', 'code', 'message'), [
    (['run', 'fjsp_planner', 'planner_node', '--ros-args', '-p', 'scenario:=/no/such.yaml'],
     2, "parameter 'scenario'"),  # unreadable scenario file
    (['run', 'fjsp_planner', 'planner_node', '--ros-args', '-p', f'scenario:={SCENARIO}',
      '-p', 'time_scale:=-1.0'], 2, "parameter 'time_scale' must be"),  # negative scale
    (['run', 'fjsp_planner', 'planner_node', '--ros-args', '-p', 'workers:=two'],
     2, "parameter 'workers' must be of type integer"),  # wrong parameter type
    (['run', 'robot_agents', 'marc_agent'], 2, "parameter 'robot_name' is required"),
    (['run', 'robot_agents', 'lsms_agent', '--ros-args', '-p', 'robot_name:=LSMS',
      '-p', 'tick_period:=0.0'], 2, "parameter 'tick_period' must be within [0.001, 1]"),
    (['run', 'fjsp_planner', 'monitor_node', '--ros-args', '-p', 'refresh_period:=0.0'],
     2, "parameter 'refresh_period' must be within [0.05, 60]"),
    (['run', 'no_such_package', 'x'], 1, "Package 'no_such_package' not found"),
    (['run', 'robot_agents', 'no_such_agent'], 1, 'No executable found'),
    (['bag', 'info', 'x.mcap'], 2, 'not provided by this front end'),
    (['topic', 'echo', '/plan', '--spin-time', '-1'], 2, '--spin-time must be >= 0'),
])
def test_bad_input_is_refused_clearly(launcher, command, code, message):
    done = subprocess.run(['ros2', *command], env=launcher.env, capture_output=True,
                          text=True, timeout=30)
    output = done.stdout + done.stderr
    assert done.returncode == code, output
    assert message in output
    assert 'Traceback' not in output
