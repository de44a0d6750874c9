"""How the planner runs missions: the planner node's parameters, and the settings the mission
controller takes from them.

`PARAMETERS` defines each of the node's parameters once (name, default, description, range,
read-only); the node declares them from it, and `Settings` takes its defaults from it.
"""

from collections.abc import Mapping
from dataclasses import dataclass, fields

from fjsp_common.fleet import HEARTBEAT_TIMEOUT
from fjsp_common.parameters import ParameterSpec, table
from fjsp_planner.solving.solve import SOLVERS

PARAMETERS = table(
    ParameterSpec('scenario', '', 'scenario file of a mission to run at start-up; empty: wait '
                  'for RunMission goals'),
    ParameterSpec('panels', 0, "panels of the scenario's job set; 0: the file's", low=0,
                  high=50),
    ParameterSpec('shift', -1.0, "distance added per panel apart; negative: the file's",
                  low=-1.0, high=1e6),
    ParameterSpec('solver', 'cpsat', 'solver of the first plan', choices=SOLVERS),
    ParameterSpec('time_limit', 10.0, 'seconds the first plan may take', low=0.01,
                  high=3600.0, read_only=False),
    ParameterSpec('replan_time_limit', 1.0, 'seconds a re-plan may take', low=0.01,
                  high=600.0, read_only=False),
    ParameterSpec('workers', 2, 'CP-SAT search workers', low=1, high=64, read_only=False),
    ParameterSpec('heartbeat_timeout', HEARTBEAT_TIMEOUT,
                  'seconds without a robot state, while others are heard, before a robot is '
                  'offline (three times as long when none is)', low=0.05,
                  high=600.0, read_only=False),
    ParameterSpec('delay_threshold', 2.0,
                  'schedule units an operation may run late before a re-plan', low=0.0,
                  high=1e6, read_only=False),
    ParameterSpec('drift_threshold', 0.0,
                  "share by which the projected makespan may exceed the plan's before the "
                  'rest is re-planned; 0: never', low=0.0, high=10.0, read_only=False),
    ParameterSpec('robot_wait_timeout', 15.0,
                  'seconds to wait for every robot to report before planning without it',
                  low=0.0, high=3600.0, read_only=False),
    ParameterSpec('plan_uptake_timeout', 10.0,
                  'seconds a reporting robot may stay on an older plan revision than the '
                  'latest before it is planned without', low=0.1, high=3600.0,
                  read_only=False),
    ParameterSpec('time_scale', 0.05, 'wall seconds per schedule unit', low=1e-4,
                  high=1000.0),
    ParameterSpec('start_delay', 0.5, 'seconds from the first plan to the mission start',
                  low=0.0, high=3600.0),
    ParameterSpec('status_period', 0.5, 'seconds between periodic status publications',
                  low=0.01, high=60.0),
    ParameterSpec('journal_dir', '', 'directory of the mission journals that let a restarted '
                  'planner resume its mission; empty: no journal'),
    ParameterSpec('rival_timeout', 3.0, 'seconds a planner listens for another planner on '
                  'its ROS domain before it takes charge; a planner standing by takes charge '
                  'once the one in charge has been silent this long', low=0.5, high=600.0),
    ParameterSpec('queue_limit', 16, 'missions that may wait their turn behind the running '
                  'one; 0: a goal sent while a mission runs is refused', low=0, high=1000,
                  read_only=False),
)
"""The planner node's parameters, in the order it declares them. Those not read-only are
honoured when set at run time (read at each use)."""


def _default(name: str):
    return PARAMETERS[name].default


@dataclass(frozen=True)
class Settings:
    """How the planner runs missions; the node refreshes them when its parameters change.

    A mission keeps the time limits, start delay, time scale and blocked timeout it started
    with (a goal may set them); the heartbeat, delay, robot wait and plan uptake thresholds
    are always the controller's current ones, so a change applies to the running mission."""

    time_limit: float = _default('time_limit')
    replan_time_limit: float = _default('replan_time_limit')
    heartbeat_timeout: float = _default('heartbeat_timeout')
    delay_threshold: float = _default('delay_threshold')
    drift_threshold: float = _default('drift_threshold')
    robot_wait_timeout: float = _default('robot_wait_timeout')
    start_delay: float = _default('start_delay')
    time_scale: float = _default('time_scale')
    blocked_timeout: float = 0.0
    """Seconds a mission may stay blocked before it fails; 0: it waits for the fleet. Not a
    parameter: a RunMission goal sets it."""
    plan_uptake_timeout: float = _default('plan_uptake_timeout')
    """Seconds a robot that reports may stay on an older plan revision than the latest before
    it is planned without, until it reports the latest."""
    queue_limit: int = _default('queue_limit')
    """Missions that may wait in the queue behind the running one."""

    @classmethod
    def from_parameters(cls, values: Mapping[str, object]) -> 'Settings':
        """The settings that `values` (parameter name -> value) give; the others default."""
        return cls(**{f.name: values[f.name] for f in fields(cls) if f.name in values})


SETTINGS_PARAMETERS = tuple(f.name for f in fields(Settings) if f.name in PARAMETERS)
"""The parameters `Settings` takes."""
