"""The fleet's processes: the planner, one generic robot agent per robot a scenario lists, and
the monitor, each in a process of its own, from start-up to the end of the mission; a node
that ended can be started again as it was (`Fleet.restart`; when to, `launcher.respawn`).

`launch` and `launch_ros` are not published on PyPI, so this is the project's one launcher,
used alike by `ros2 run fjsp_planner fleet`, `ros2_ws/demo.sh`, the test harness
(`fjsp_planner.testing`) and the benchmarks. It finds executables through the ament index as
`ros2 run` does, so it works with this workspace and with a ROS 2 install alike.

No node may outlive the launcher: each runs in a process group of its own (a Ctrl-C in the
terminal reaches the launcher only, which then interrupts each node and kills what does not
stop), and the kernel kills it if the launcher dies (PR_SET_PDEATHSIG), even of a SIGKILL.
"""

import ctypes
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from ament_index_python.packages import get_package_prefix

from fjsp_common.auth import KEY_FILE_VARIABLE, new_key
from fjsp_common.fleet import (
    MONITOR_NODE,
    PLANNER_NODE,
    RECORDER_NODE,
    agent_node_name,
    sim_robot_node_name,
)
from fjsp_planner.launcher.params import (
    read_params_file,
    ros_string,
    sets_parameter,
    write_node_params,
)
from fjsp_planner.model.problem import Problem, ProblemError
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.workspace import default_out_dir, installed_scenarios

MONITOR_OUT_PARAMETER = 'out_dir'
"""The monitor's parameter naming the directory its outputs go to."""
MONITOR_PORT_PARAMETER = 'web_port'
"""The monitor's parameter naming the port of its live page."""
JOURNAL_PARAMETER = 'journal_dir'
"""The planner's parameter naming where its mission journals go."""
REPORTS_PARAMETER = 'reports_dir'
"""The agents' parameter naming where each keeps its task events."""
DEFAULT_SCENARIO = 'solar_panel.yaml'
DEFAULT_TIME_SCALE = 0.2
"""Wall seconds per schedule unit: the paper's 32-unit mission takes about 6 s."""
STOP_GRACE = 5.0
"""Seconds a node has to stop after SIGINT before it is killed."""
MONITOR_FINISH = 30.0
"""Seconds the monitor may take, once the mission ended, to write its summary and chart."""

EXIT_FAILED = 1
EXIT_BAD_INPUT = 2
ROS_NAME = re.compile(r'[A-Za-z][A-Za-z0-9_]*')
"""A robot name usable in node and service names: `agent_<robot>`, `<robot>/inject_fault`."""

_PR_SET_PDEATHSIG = 1


class FleetError(ValueError):
    """A fleet that cannot be started; `problems` lists every reason, each naming the item."""

    def __init__(self, problems):
        self.problems = list(problems)
        super().__init__('\n'.join(self.problems))


def resolve_scenario(scenario=None) -> Path:
    """The scenario file to run: a path, or the name of a scenario installed with the package
    (`truss`, `truss.yaml`); by default the paper's `solar_panel.yaml`."""
    path = Path(scenario if scenario is not None else DEFAULT_SCENARIO).expanduser()
    if path.is_file() or path.parent != Path('.'):
        return path.resolve()
    installed = installed_scenarios()
    for name in (path.name, f'{path.name}.yaml'):
        if installed is not None and (installed / name).is_file():
            return installed / name
    return path.resolve()


def robot_name_problems(problem: Problem) -> list[str]:
    return [f"robot '{r.name}': its name must be usable in ROS names (ASCII letters, digits "
            'and underscores, starting with a letter)'
            for r in problem.robots if not ROS_NAME.fullmatch(r.name)]


def find_executable(package: str, executable: str) -> Path:
    """`<prefix>/lib/<package>/<executable>`, as `ros2 run` finds it."""
    try:
        prefix = get_package_prefix(package)
    except (LookupError, OSError, ValueError):
        raise FleetError([f"package '{package}' not found: is the workspace sourced "
                          '(source ros2_ws/env.sh)?']) from None
    path = Path(prefix) / 'lib' / package / executable
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise FleetError([f"package '{package}' has no executable '{executable}'"])
    return path


def _prepare_node(parent: int):
    """What the child runs between fork and exec.

    The kernel kills it when the launcher dies. SIGINT is ignored until the node installs
    its own handler (every node does first thing; a Python process does not install its
    default one over an ignored SIGINT): a Ctrl-C that catches a node still importing its
    modules would otherwise end it with a traceback; ignored, the node is killed after the
    grace period instead."""
    prctl = ctypes.CDLL(None, use_errno=True).prctl

    def prepare():
        prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != parent:  # the launcher died before the request took effect
            os._exit(1)
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    return prepare


class Fleet:
    """The processes of one fleet: the planner, one `robot_agent` per robot of the scenario,
    the monitor, and any node a test adds.

    Every node gets `params_file` (if given), then the launcher's own parameters, which win
    over it: the scenario, and the time scale and output directory unless the file sets them
    and they were not given here. `planner`, `agents` and `monitor` add parameters of those
    nodes. `prefixes` maps node names to a command the node runs under, e.g.
    `{'agent_R1': ['ip', 'netns', 'exec', 'rover1']}` to start it in another network
    namespace, on every (re)start. Logs go to `<out>/logs/<node>.log`.

    With `resumable`, the planner keeps its mission journal (`journal_dir`) and each agent
    its reports (`reports_dir`) in `<out>/journal/<UTC start time>-<pid>`, unless the
    parameters file sets where: a planner started again resumes the mission and nothing done
    is redone (docs/ros-interfaces.md, "Journal and planner restart").

    With `sim_robots` (a dict of `sim_robot` parameters, maybe empty) every agent runs with
    the `action` driver, and a `sim_robot` node serves the actions of each robot, started
    with its agent (docs/robot-drivers.md).

    Start nodes from a thread that lives as long as the fleet (the main thread): the kernel
    sends the parent-death signal when the thread that started a node ends.
    """

    def __init__(self, scenario=None, *, panels: int | None = None,
                 time_scale: float | None = None, params_file=None, out=None,
                 domain: int | None = None, env: dict | None = None,
                 planner: dict | None = None, agents: dict | None = None,
                 monitor: dict | None = None, key: bool = False,
                 prefixes: dict | None = None, resumable: bool = False,
                 sim_robots: dict | None = None):
        problems = []
        self.scenario = resolve_scenario(scenario)
        self.problem: Problem | None = None
        if not self.scenario.is_file():
            known = installed_scenarios()
            names = sorted(p.name for p in known.glob('*.yaml')) if known else []
            problems.append(f'{scenario}: no such scenario file'
                            + (f' (installed: {", ".join(names)})' if names else ''))
        else:
            try:
                self.problem = load_scenario(self.scenario, panels=panels)
            except ProblemError as error:
                problems += error.problems
            else:
                problems += [f'{self.scenario}: {p}' for p in robot_name_problems(self.problem)]
        self.params_file = Path(params_file).resolve() if params_file is not None else None
        self.params = {}
        if self.params_file is not None:
            self.params, unusable = read_params_file(self.params_file)
            problems += unusable
        executables = [('fjsp_planner', 'planner_node'), ('fjsp_planner', 'monitor_node'),
                       ('robot_agents', 'robot_agent')]
        if sim_robots is not None:
            executables.append(('robot_agents', 'sim_robot'))
        for package, executable in executables:
            try:
                find_executable(package, executable)
            except FleetError as error:
                problems += error.problems
        if problems:
            raise FleetError(problems)

        self.panels = panels
        self.time_scale = time_scale
        self.out_given = out is not None
        self.out = Path(out).expanduser().resolve() if out is not None else default_out_dir()
        self.logs = self.out / 'logs'
        self.env = dict(os.environ, PYTHONUNBUFFERED='1', **(env or {}))
        if domain is not None:
            self.env['ROS_DOMAIN_ID'] = str(domain)
        self.domain = domain
        self.extra = {PLANNER_NODE: dict(planner or {}), 'agents': dict(agents or {}),
                      MONITOR_NODE: dict(monitor or {})}
        self.key_file: Path | None = None
        """With `key`, a fresh fleet key, given to every node and to the tools run with
        this fleet's environment (FJSP_FLEET_KEY_FILE)."""
        if key:
            self.key_file = new_key(self.out / 'fleet.key')
            self.env[KEY_FILE_VARIABLE] = str(self.key_file)
            for params in self.extra.values():
                params.setdefault('fleet_key_file', self.key_file)
        if resumable:
            # A fresh directory per fleet: a planner given one that holds an earlier run's
            # journal of the same scenario would not run the mission again.
            journal = self.out / 'journal' / (
                f"{time.strftime('%Y%m%dT%H%M%S', time.gmtime())}-{os.getpid()}")
            if not self._file_sets(PLANNER_NODE, JOURNAL_PARAMETER):
                self.extra[PLANNER_NODE].setdefault(JOURNAL_PARAMETER, journal)
            if not any(self._file_sets(agent_node_name(r.name), REPORTS_PARAMETER)
                       for r in self.problem.robots):
                self.extra['agents'].setdefault(REPORTS_PARAMETER, journal)
        self.prefixes = {name: list(prefix) for name, prefix in (prefixes or {}).items()}
        self.sim_robots = dict(sim_robots) if sim_robots is not None else None
        self.processes: dict[str, subprocess.Popen] = {}
        self._starts: dict[str, tuple] = {}
        """How each node was last started: the arguments of `start_node`."""
        self._streams: list[threading.Thread] = []

    # --- starting --------------------------------------------------------------------

    def start(self, *, monitor: bool = True, stream_monitor: bool = False,
              recorder: bool = False) -> 'Fleet':
        """The planner, an agent for every robot of the scenario, the monitor, and the
        recorder of the mission's topics."""
        if recorder:
            self.start_recorder()
        if monitor:
            self.start_monitor(stream=stream_monitor)
        self.start_planner()
        for robot in self.problem.robots:
            self.start_agent(robot.name)
        return self

    def start_planner(self, **params) -> subprocess.Popen:
        own = {'scenario': self.scenario}
        if self.panels is not None:
            own['panels'] = self.panels
        if self.time_scale is not None or not self._file_sets(PLANNER_NODE, 'time_scale'):
            own['time_scale'] = self.time_scale or DEFAULT_TIME_SCALE
        return self.start_node(PLANNER_NODE, 'fjsp_planner', 'planner_node',
                               {**own, **self.extra[PLANNER_NODE], **params})

    def start_agent(self, robot: str, executable: str = 'robot_agent',
                    **params) -> subprocess.Popen:
        """The agent of `robot` (`robot_agent`, or a type-pinning alias such as
        `marc_agent`); it need not be a robot of the scenario. With `sim_robots`, its
        simulated robot too, unless it runs already."""
        # The agent reads robot_name before its node, named after it, exists: a `-p`
        # value (for every node of the process) reaches it there.
        name_arg = ('-p', f'robot_name:={ros_string(robot)}')
        own = {}
        if self.sim_robots is not None:
            own['driver'] = 'action'
            sim = self.processes.get(sim_robot_node_name(robot))
            if sim is None or sim.poll() is not None:
                self.start_node(sim_robot_node_name(robot), 'robot_agents', 'sim_robot',
                                self.sim_robots, ros_args=name_arg)
        return self.start_node(agent_node_name(robot), 'robot_agents', executable,
                               {**own, **self.extra['agents'], **params}, ros_args=name_arg)

    def start_monitor(self, stream: bool = False, **params) -> subprocess.Popen:
        """The monitor; with `stream`, its output goes to this process's stdout too."""
        own = {}
        if self.out_given or not self._file_sets(MONITOR_NODE, MONITOR_OUT_PARAMETER):
            own[MONITOR_OUT_PARAMETER] = self.out
        return self.start_node(MONITOR_NODE, 'fjsp_planner', 'monitor_node',
                               {**own, **self.extra[MONITOR_NODE], **params}, stream=stream)

    def start_recorder(self, **params) -> subprocess.Popen:
        """The flight recorder: every mission topic into `<out>/fjsp_<time>.mcap` (what
        verifies with the fleet's key, if it has one)."""
        own = {'out_dir': self.out}
        if self.key_file is not None:
            own['fleet_key_file'] = self.key_file
        return self.start_node(RECORDER_NODE, 'fjsp_planner', 'recorder', {**own, **params})

    def start_node(self, name: str, package: str, executable: str, params=None,
                   ros_args=(), stream: bool = False, prefix=None) -> subprocess.Popen:
        """Start `executable` of `package` as node `name` with `params` (written to
        `<out>/params/<name>.yaml`, after the user's parameters file) and any further ROS
        arguments; its log: `<out>/logs/<name>.log` (a node started again appends to it).
        `prefix` (default: the node's entry of `prefixes`) is a command the node runs under.
        Stopping reaches the node through its process group whatever the prefix does, but
        only a prefix that execs the node (as `ip netns exec`, `nice`, `taskset` do) passes
        on the parent-death signal and the node's own exit code."""
        previous = self.processes.get(name)
        if previous is not None and previous.poll() is None:
            raise FleetError([f"node '{name}' is already running (pid {previous.pid})"])
        self._starts[name] = (package, executable, params, tuple(ros_args), stream, prefix)
        prefix = self.prefixes.get(name, ()) if prefix is None else prefix
        command = [*prefix, str(find_executable(package, executable)), '--ros-args']
        if self.params_file is not None:
            command += ['--params-file', str(self.params_file)]
        if params:
            own = self.out / 'params' / f'{name}.yaml'
            write_node_params(own, name, params)
            command += ['--params-file', str(own)]
        command += list(ros_args)
        self.logs.mkdir(parents=True, exist_ok=True)
        log = (self.logs / f'{name}.log').open('a' if previous else 'w')
        try:
            process = subprocess.Popen(
                command, env=self.env, stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE if stream else log, stderr=subprocess.STDOUT,
                start_new_session=True, preexec_fn=_prepare_node(os.getpid()))
        finally:
            if not stream:
                log.close()
        if stream:
            copier = threading.Thread(target=_copy_lines, args=(process.stdout, log),
                                      name=f'{name}_output', daemon=True)
            copier.start()
            self._streams.append(copier)
        self.processes[name] = process
        return process

    def restart(self, name: str) -> subprocess.Popen:
        """Start node `name`, which has ended, again as it was last started; its log goes
        on."""
        package, executable, params, ros_args, stream, prefix = self._starts[name]
        return self.start_node(name, package, executable, params, ros_args, stream, prefix)

    def _file_sets(self, node: str, parameter: str) -> bool:
        return sets_parameter(self.params, node, parameter)

    # --- watching and stopping -------------------------------------------------------

    def log(self, name: str) -> str:
        return (self.logs / f'{name}.log').read_text()

    def exited(self) -> dict[str, int]:
        """Exit codes of the nodes that have ended (negative: killed by that signal)."""
        return {name: p.returncode for name, p in self.processes.items()
                if p.poll() is not None}

    def kill(self, name: str) -> int:
        """SIGKILL node `name`, as a crash would: it gets no chance to say goodbye."""
        process = self.processes[name]
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
        return process.wait(timeout=STOP_GRACE)

    def stop(self, name: str | None = None, timeout: float = STOP_GRACE) -> dict[str, int]:
        """SIGINT each node's process group (all nodes, or `name`), SIGKILL what is still
        running after `timeout` seconds; the exit codes."""
        names = [name] if name else list(self.processes)
        for n in names:
            if self.processes[n].poll() is None:
                os.killpg(self.processes[n].pid, signal.SIGINT)
        deadline = time.monotonic() + timeout
        codes = {}
        for n in names:
            process = self.processes[n]
            try:
                codes[n] = process.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                codes[n] = process.wait()
        for copier in self._streams:
            copier.join(timeout=1.0)
        return codes

    def __enter__(self) -> 'Fleet':
        return self

    def __exit__(self, *exc) -> None:
        self.stop()


def _copy_lines(source, log) -> None:
    """The streamed node's output to the log and to stdout, line by line, until it ends."""
    with source, log:
        for line in iter(source.readline, b''):
            log.write(line.decode(errors='replace'))
            log.flush()
            sys.stdout.buffer.write(line)
            sys.stdout.flush()


