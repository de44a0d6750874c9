"""Bad parameters and command lines: a clear message naming the item, a non-zero exit code,
no traceback and no hang."""

import os
import subprocess

import pytest

from repo_paths import PAPER


@pytest.mark.parametrize(('command', 'code', 'message'), [
    (['run', 'fjsp_planner', 'planner_node', '--ros-args', '-p', 'scenario:=/no/such.yaml'],
     2, "parameter 'scenario'"),  # unreadable scenario file
    (['run', 'fjsp_planner', 'planner_node', '--ros-args', '-p', f'scenario:={PAPER}',
      '-p', 'time_scale:=-1.0'], 2, "parameter 'time_scale' must be"),  # negative scale
    (['run', 'fjsp_planner', 'planner_node', '--ros-args', '-p', 'workers:=two'],
     2, "parameter 'workers' must be of type integer"),  # wrong parameter type
    *[(['run', 'fjsp_planner', 'planner_node', '--ros-args', '-p', f'scenario:={PAPER}',
        '-p', f'{name}:={value}'], 2, f"parameter '{name}' must be within")
      for name, value in (('time_scale', '.inf'), ('robot_wait_timeout', '.nan'),
                          ('start_delay', '1e300'), ('workers', '999999'),
                          ('status_period', '1e-9'), ('panels', '100000'))],
    (['run', 'robot_agents', 'marc_agent'], 2, "parameter 'robot_name' is required"),
    (['run', 'robot_agents', 'lsms_agent', '--ros-args', '-p', 'robot_name:=LSMS',
      '-p', 'tick_period:=0.0'], 2, "parameter 'tick_period' must be within [0.001, 1]"),
    (['run', 'fjsp_planner', 'monitor_node', '--ros-args', '-p', 'refresh_period:=0.0'],
     2, "parameter 'refresh_period' must be within [0.05, 60]"),
    (['run', 'no_such_package', 'x'], 1, "Package 'no_such_package' not found"),
    (['run', 'robot_agents', 'no_such_agent'], 1, 'No executable found'),
    (['run', 'fjsp_planner', 'fleet'], 2, 'the following arguments are required: scenario'),
    (['run', 'fjsp_planner', 'fleet', 'no_such_scenario'], 2,
     'no_such_scenario: no such scenario file (installed: antenna.yaml, habitat.yaml, '
     'solar_panel.yaml, truss.yaml, yard.yaml)'),
    (['run', 'fjsp_planner', 'fleet', 'truss', '--panels', '0'], 2,
     'argument --panels: must be > 0, got 0'),
    (['run', 'fjsp_planner', 'fleet', 'truss', '--time-scale', 'fast'], 2,
     "argument --time-scale: expected a number > 0, got 'fast'"),
    (['run', 'fjsp_planner', 'fleet', 'truss', '--params-file', '/no/such.yaml'], 2,
     '/no/such.yaml: no such file'),
    (['run', 'fjsp_planner', 'fleet', 'truss', '--web-port', '65536'], 2,
     'argument --web-port: must be within [0, 65535], got 65536'),
    (['run', 'fjsp_planner', 'fleet', 'truss', '--web-port', 'http'], 2,
     "argument --web-port: expected a port number, got 'http'"),
    (['bag', 'info', 'x.mcap'], 2, 'not provided by this front end'),
    (['topic', 'echo', '/plan', '--spin-time', '-1'], 2,
     "argument --spin-time: must be a number of seconds >= 0, got '-1'"),
])
def test_bad_input_is_refused_clearly(command, code, message, ros_domain):
    env = dict(os.environ, ROS_DOMAIN_ID=str(ros_domain),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    done = subprocess.run(['ros2', *command], env=env, capture_output=True, text=True,
                          timeout=30)
    output = done.stdout + done.stderr
    assert done.returncode == code, output
    assert message in output
    assert 'Traceback' not in output
