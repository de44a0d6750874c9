"""Health as ROS tools expect it: `diagnostic_msgs/DiagnosticStatus` on `/diagnostics`.

Pure functions, so every node reports health the same way: the agents about their robot, the
planner about its mission and solver, the monitor about every robot as the fleet sees it (a
robot whose agent died cannot report its own silence). Levels: OK; WARN for a robot running
late or refusing its plan, a blocked mission or a warning; ERROR for a robot failed or offline
and a failed mission; STALE for a robot not heard from yet. `rqt_robot_monitor`, the
diagnostic aggregator and Foxglove show them as they are.
"""

import math
from collections.abc import Iterable, Mapping

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from fjsp_common.decimals import decimal
from fjsp_common.vocabulary import MissionState, RobotMode

DIAGNOSTICS_TOPIC = '/diagnostics'
"""Absolute, as every ROS diagnostics tool listens there whatever the fleet's namespace."""

DIAGNOSTICS_QOS = QoSProfile(reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.VOLATILE,
                             history=HistoryPolicy.KEEP_LAST, depth=10)
"""What diagnostic_updater publishes with: a status is repeated every period anyway."""

LEVEL_NAMES = {DiagnosticStatus.OK: 'OK', DiagnosticStatus.WARN: 'WARN',
               DiagnosticStatus.ERROR: 'ERROR', DiagnosticStatus.STALE: 'STALE'}


def _values(pairs: Mapping[str, object]) -> list[KeyValue]:
    def text(value) -> str:
        if value is None or (isinstance(value, float) and not math.isfinite(value)):
            return 'n/a'
        if isinstance(value, float):
            return f'{value:g}'
        if isinstance(value, list | tuple):
            return '; '.join(str(v) for v in value)
        return str(value)
    return [KeyValue(key=key, value=text(value)) for key, value in pairs.items()]


def robot_diagnostic(name: str, robot: str, mode: RobotMode | None, *, job: str = '',
                     late_by: float = 0.0, late_threshold: float = 0.0, refusal: str = '',
                     silent_for: float | None = None,
                     values: Mapping[str, object] | None = None) -> DiagnosticStatus:
    """One robot's health.

    `mode` None: never heard from (STALE). `silent_for`: seconds since its last state, when
    that is over the heartbeat timeout (ERROR, offline). `late_by`: schedule units its current
    operation is expected to end after the plan said; over `late_threshold` it is WARN.
    `values` are added to the status's key/values.
    """
    if mode is None:
        level, message = DiagnosticStatus.STALE, 'no state received yet'
    elif silent_for is not None or mode == RobotMode.OFFLINE:
        level = DiagnosticStatus.ERROR
        message = ('offline: no state for ' + f'{silent_for:.1f} s' if silent_for is not None
                   else 'offline')
    elif mode == RobotMode.FAILED:
        level, message = DiagnosticStatus.ERROR, 'failed'
    elif refusal:
        level, message = DiagnosticStatus.WARN, f'refuses its plan: {refusal}'
    elif late_by > late_threshold:
        level = DiagnosticStatus.WARN
        message = f'late: {job or "its operation"} ends {decimal(late_by)} units after the plan'
    else:
        level = DiagnosticStatus.OK
        message = f'{mode} {job}'.strip()
    pairs = {'robot': robot, 'mode': mode if mode is not None else 'unknown', 'job': job,
             'late by (units)': late_by}
    pairs.update(values or {})
    return DiagnosticStatus(level=level, name=name, message=message, hardware_id=robot,
                            values=_values(pairs))


def planner_diagnostic(name: str, state: MissionState, *, mission_id: str = '',
                       revision: int = 0, jobs_done: int = 0, jobs_total: int = 0,
                       solver_status: str = '', gap: float | None = None,
                       replan_latency: float | None = None,
                       blocked_reasons: Iterable[str] = (), warnings: Iterable[str] = (),
                       hardware_id: str = '') -> DiagnosticStatus:
    """The planner's health: its mission's state, the solver's last answer (status and
    relative gap, 0.05 = 5 %), and how long its last re-plan took (seconds from the decision
    to re-plan to the new revision's publication)."""
    blocked, warnings = list(blocked_reasons), list(warnings)
    progress = f'revision {revision}, {jobs_done}/{jobs_total} jobs done'
    if state == MissionState.FAILED:
        level, message = DiagnosticStatus.ERROR, 'mission failed: ' + '; '.join(blocked)
    elif state == MissionState.BLOCKED:
        level, message = DiagnosticStatus.WARN, 'blocked: ' + '; '.join(blocked)
    elif state == MissionState.IDLE:
        level, message = DiagnosticStatus.OK, 'idle: waiting for a mission'
    elif warnings:
        level, message = DiagnosticStatus.WARN, f'{state}, {progress}: ' + '; '.join(warnings)
    else:
        level, message = DiagnosticStatus.OK, f'{state}, {progress}'
    pairs = {'state': state, 'mission': mission_id, 'revision': revision,
             'jobs done': jobs_done, 'jobs total': jobs_total, 'solver status': solver_status,
             'gap': None if gap is None else f'{gap:.1%}',
             'last re-plan latency (s)': replan_latency}
    return DiagnosticStatus(level=level, name=name, message=message,
                            hardware_id=hardware_id, values=_values(pairs))


def diagnostic_array(stamp, statuses: Iterable[DiagnosticStatus]) -> DiagnosticArray:
    """The message for `/diagnostics`; `stamp` a `builtin_interfaces/Time`."""
    array = DiagnosticArray(status=list(statuses))
    array.header.stamp = stamp
    return array
