"""Health statuses for /diagnostics, as the agents, the planner and the monitor build them
(message classes only: no node, no DDS)."""

import pytest
from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticStatus

from fjsp_common.diagnostics import diagnostic_array, planner_diagnostic, robot_diagnostic
from fjsp_common.vocabulary import MissionState, RobotMode

OK, WARN, ERROR, STALE = (DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.ERROR,
                          DiagnosticStatus.STALE)


@pytest.mark.parametrize('mode, options, level, message', [
    (RobotMode.WORKING, {'job': 'Ja'}, OK, 'working Ja'),
    (RobotMode.IDLE, {}, OK, 'idle'),
    (RobotMode.WORKING, {'job': 'Ja', 'late_by': 3.0, 'late_threshold': 2.0}, WARN,
     'late: Ja ends 3 units after the plan'),
    (RobotMode.WORKING, {'job': 'Ja', 'late_by': 1.0, 'late_threshold': 2.0}, OK, 'working Ja'),
    (RobotMode.IDLE, {'refusal': "plan makes 'R1' a 'Drone'"}, WARN,
     "refuses its plan: plan makes 'R1' a 'Drone'"),
    (RobotMode.FAILED, {}, ERROR, 'failed'),
    (RobotMode.WORKING, {'silent_for': 2.5}, ERROR, 'offline: no state for 2.5 s'),
    (RobotMode.OFFLINE, {}, ERROR, 'offline'),
    (None, {}, STALE, 'no state received yet'),
])
def test_robot_levels(mode, options, level, message):
    status = robot_diagnostic('monitor: robot MARC1', 'MARC1', mode, **options)
    assert (status.level, status.message) == (level, message)
    assert (status.name, status.hardware_id) == ('monitor: robot MARC1', 'MARC1')


def test_robot_values_are_strings_with_unknowns_spelled_out():
    status = robot_diagnostic('agent_MARC1: robot', 'MARC1', RobotMode.WORKING, job='Ja',
                              values={'busy until': float('nan'), 'revision': 2})
    values = {v.key: v.value for v in status.values}
    assert values['mode'] == 'working' and values['job'] == 'Ja'
    assert values['busy until'] == 'n/a' and values['revision'] == '2'


@pytest.mark.parametrize('state, options, level, start', [
    (MissionState.EXECUTING, {}, OK, 'executing, revision 2, 5/12 jobs done'),
    (MissionState.EXECUTING, {'warnings': ["robot 'X' is not in the scenario"]}, WARN,
     'executing, revision 2, 5/12 jobs done: robot'),
    (MissionState.BLOCKED, {'blocked_reasons': ["job 'Aa' cannot be staffed"]}, WARN,
     "blocked: job 'Aa'"),
    (MissionState.FAILED, {'blocked_reasons': ['no plan']}, ERROR, 'mission failed: no plan'),
])
def test_planner_levels(state, options, level, start):
    status = planner_diagnostic('planner: mission', state, revision=2, jobs_done=5,
                                jobs_total=12, solver_status='feasible', gap=0.125,
                                replan_latency=0.42, **options)
    assert status.level == level and status.message.startswith(start)
    values = {v.key: v.value for v in status.values}
    assert values['gap'] == '12.5%' and values['last re-plan latency (s)'] == '0.42'
    assert values['solver status'] == 'feasible'


def test_the_array_carries_its_stamp():
    array = diagnostic_array(Time(sec=5, nanosec=7),
                             [robot_diagnostic('n', 'R1', RobotMode.IDLE)])
    assert (array.header.stamp.sec, array.header.stamp.nanosec) == (5, 7)
    assert [s.hardware_id for s in array.status] == ['R1']
