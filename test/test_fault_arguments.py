"""fjsp_planner.faults: the arguments it refuses before touching ROS."""

import math
import os
import re
import subprocess
import sys

import pytest

from fjsp_planner.faults import FaultError, check_fault, inject_fault

from repo_paths import REPO


@pytest.mark.parametrize(('fault', 'factor', 'message'), [
    ('explode', None, "unknown fault 'explode': expected one of fail, recover, delay"),
    ('Fail', None, "unknown fault 'Fail'"),                       # names are lower case
    ('delay', None, "fault 'delay' needs a factor within [0.001, 1000]"),
    ('delay', 0, 'factor must be a finite number > 0, got 0'),
    ('delay', -1.5, 'got -1.5'),
    ('delay', math.nan, 'got nan'),
    ('delay', math.inf, 'got inf'),
    ('delay', 1e306, 'factor must be within [0.001, 1000], got 1e+306'),
    ('delay', 1e-200, 'factor must be within [0.001, 1000], got 1e-200'),
    ('delay', 'twice', "factor must be a number, got 'twice'"),
    ('fail', 2.0, "fault 'fail' takes no factor (got 2.0)"),
    ('recover', 1.0, "fault 'recover' takes no factor"),         # even a neutral one
])
def test_bad_arguments_are_refused_with_the_reason(fault, factor, message):
    with pytest.raises(FaultError, match=re.escape(message)):
        inject_fault('MARC1', fault, factor)


@pytest.mark.parametrize('timeout', [0, -1, math.nan, math.inf, '5'])
def test_bad_timeout_is_refused(timeout):
    with pytest.raises(FaultError, match='timeout must be a number of seconds > 0'):
        inject_fault('MARC1', 'fail', timeout=timeout)


def test_good_arguments_give_the_factor_to_send():
    assert check_fault('delay', 2) == 2.0
    assert check_fault('delay', 1e-3) == 1e-3 and check_fault('delay', 1e3) == 1e3
    assert check_fault('fail', None) == 0.0 and check_fault('recover', None) == 0.0


@pytest.mark.integration
@pytest.mark.integration
@pytest.mark.parametrize(('args', 'message'), [
    ([], 'the following arguments are required: robot, fault'),
    (['MARC1', 'explode'], "invalid choice: 'explode'"),
    (['MARC1', 'delay'], "fault 'delay' needs a factor within [0.001, 1000]"),
    (['MARC1', 'delay', '--factor', '0'], 'factor must be a finite number > 0, got 0'),
    (['MARC1', 'delay', '--factor', '1e306'], 'factor must be within [0.001, 1000], got 1e+306'),
    (['MARC1', 'delay', '--factor', 'fast'], "invalid float value: 'fast'"),
    (['MARC1', 'fail', '--factor', '2'], "fault 'fail' takes no factor"),
    (['MARC1', 'fail', '--timeout', '0'], '--timeout must be a number of seconds > 0'),
    (['MARC1', 'fail', '--ros-args', '-p'], 'bad ROS arguments: Failed to parse ROS arguments'),
], ids=['nothing', 'unknown fault', 'delay without factor', 'zero factor', 'huge factor',
        'factor not a number',
        'factor for fail', 'zero timeout', 'bad ROS arguments'])
def test_command_line_exits_2_with_the_reason(args, message):
    done = subprocess.run([sys.executable, '-m', 'fjsp_planner.faults', *args],
                          capture_output=True, text=True, timeout=60,
                          env=dict(os.environ, PYTHONPATH=os.pathsep.join(
                              str(REPO / 'src' / package)
                              for package in ('fjsp_common', 'fjsp_planner'))))
    assert done.returncode == 2, done.stderr
    assert message in done.stderr
    assert 'Traceback' not in done.stderr
