"""The workspace's `ros2` front end against a real fleet: every `ros2 ...` command that
README.md and docs/*.md show in a code block (but `ros2 run`, which the other tests cover),
run as written, so a doc example that stops working fails here; and the verbs' answers to bad
nodes, parameters, types and values.

One fleet (the paper's, with the monitor) serves the whole module: each command is a fresh
process that joins the graph, as a user's shell would.
"""

import re
import shlex
import signal
import subprocess
import threading
import time

import pytest

from fjsp_planner.testing import FleetHarness

from repo_paths import PAPER, REPO

pytestmark = pytest.mark.slow

DOCS = [REPO / 'README.md', *sorted((REPO / 'docs').glob('*.md'))]

# What each verb's output must show against the paper's fleet; a command whose verb is not
# here must print something.
EXPECTED = {
    ('node', 'list'): r'(?m)^/planner$',
    ('node', 'info'): r'Publishers:',
    ('topic', 'list'): r'(?m)^/mission_status( \[fjsp_msgs/msg/MissionStatus\])?$',
    ('topic', 'echo'): r'(?m)^---$',
    ('topic', 'hz'): r'average rate: \d+\.\d{3}\n\tmin: ',
    ('topic', 'info'): r'Publisher count: [1-9]',
    ('param', 'list'): r'(?m)^  time_limit$',
    ('param', 'get'): r'value is: ',
    ('param', 'set'): r'^Set parameter successful',
    ('param', 'describe'): r'^Parameter name: \w+\n  Type: ',
    ('param', 'dump'): r'^/\w+:\n  ros__parameters:\n',
    ('action', 'list'): r'(?m)^/run_mission',
    ('action', 'info'): r'Action servers: 1',
    ('service', 'list'): r'(?m)^/cancel_mission',
    ('interface', 'show'): r'\w+ \w+',
}
# A command still running this long after its output showed what it must is streaming (echo
# without --once, hz): it gets Ctrl-C, as a user would give it, and must end with exit code 0.
STREAMING_GRACE = 5.0
PLACEHOLDER = re.compile(r'<[\w -]+>|\[-|\.\.\.')  # <node>, [-t], name...
COMMAND_TIMEOUT = 60.0


def doc_commands() -> list[tuple[str, str]]:
    """(command line, where it is shown) for each `ros2` line of a fenced code block."""
    found = {}
    for path in DOCS:
        fenced = False
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if line.lstrip().startswith('```'):
                fenced = not fenced
                continue
            text = line.strip()
            if fenced and text.startswith('ros2 ') and not text.startswith('ros2 run '):
                found.setdefault(shlex.join(shlex.split(text, comments=True)),
                                 f'{path.relative_to(REPO)}:{number}')
    return sorted(found.items())


COMMANDS = doc_commands()


def test_the_docs_show_the_verbs_users_reach_for():
    shown = {command for command, _ in COMMANDS}
    for command in ('ros2 param describe /planner delay_threshold',
                    'ros2 param set /planner delay_threshold 3.0', 'ros2 param dump /planner',
                    'ros2 topic hz /robot_states', 'ros2 node list', 'ros2 action list'):
        assert command in shown, f'{command!r} is no longer shown in README.md or docs/'


@pytest.fixture(scope='module')
def fleet(tmp_path_factory):
    with FleetHarness(PAPER, out=tmp_path_factory.mktemp('front_end')) as fleet:
        fleet.start(monitor=True)
        fleet.wait_for(lambda o: o.status is not None and o.plans, 60, 'the first plan')
        yield fleet


def takes_ctrl_c():
    """Run in the command's process before it starts: a command typed in a terminal takes
    Ctrl-C, even when these tests run in a background job (which ignores SIGINT, and its
    children inherit that)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


class Run:
    """A `ros2` command as a user runs it in a shell: its output read as it comes, Ctrl-C
    once it is streaming."""

    def __init__(self, argv: list[str], env: dict, expected: str | None):
        self.process = subprocess.Popen(argv, env=env, cwd=REPO, text=True,
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        preexec_fn=takes_ctrl_c)
        self.stdout, self.interrupted = '', False
        reader = threading.Thread(target=self._read, daemon=True)
        reader.start()
        shown_at, deadline = None, time.monotonic() + COMMAND_TIMEOUT
        while self.process.poll() is None and time.monotonic() < deadline:
            time.sleep(0.1)
            if shown_at is None and re.search(expected or r'\S', self.stdout):
                shown_at = time.monotonic()
            if shown_at is not None and time.monotonic() - shown_at > STREAMING_GRACE:
                self.interrupted = True
                self.process.send_signal(signal.SIGINT)
                break
        try:
            self.process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        reader.join(timeout=5)
        self.stderr = self.process.stderr.read()
        self.code = self.process.returncode

    def _read(self):
        for line in self.process.stdout:
            self.stdout += line

    def __str__(self):
        return (f'exit code {self.code}{" after Ctrl-C" if self.interrupted else ""}\n'
                f'stdout:\n{self.stdout[-3000:]}\nstderr:\n{self.stderr[-3000:]}')


@pytest.mark.parametrize('command, where', COMMANDS, ids=[c for c, _ in COMMANDS])
def test_doc_command(fleet, command, where):
    assert not PLACEHOLDER.search(command), \
        f'{where}: {command!r} has a placeholder; show a command that runs as written'
    argv = shlex.split(command)
    expected = EXPECTED.get(tuple(argv[1:3]))
    run = Run(argv, fleet.env, expected)
    assert run.code == 0, f'{where}: {command}\n{run}'
    assert 'Traceback' not in run.stderr, f'{where}: {command}\n{run}'
    assert re.search(expected or r'\S', run.stdout), \
        f'{where}: {command} does not show {expected or "anything"}\n{run}'


def ros2(fleet, *args, timeout: float = COMMAND_TIMEOUT) -> subprocess.CompletedProcess:
    return subprocess.run(['ros2', *args], env=fleet.env, cwd=REPO, capture_output=True,
                          text=True, timeout=timeout)


@pytest.mark.parametrize('args, error', [
    (('node', 'info', '/nope', '--spin-time', '1'),
     "ros2 node info: node '/nope' not found (waited 1 s for discovery)"),
    (('param', 'get', '/nope', 'x', '--spin-time', '1'),
     "ros2 param get: node '/nope' not found"),
    (('param', 'get', '/planner', 'no_such_parameter'),
     "ros2 param get: node '/planner' has no parameter 'no_such_parameter'"),
    (('param', 'describe', '/planner', 'time_limit', 'no_such_parameter'),
     "ros2 param describe: node '/planner' has no parameter 'no_such_parameter'"),
    (('param', 'set', '/planner', 'delay_threshold', '-1.0'),
     'Setting parameter failed: Parameter delay_threshold out of range'),
    (('param', 'set', '/planner', 'delay_threshold', 'soon'),
     "Setting parameter failed: Wrong parameter type, expected 'Type.DOUBLE' got "
     "'Type.STRING'"),
    (('param', 'set', '/planner', 'time_scale', '1.0'),
     'Setting parameter failed: Trying to set a read-only parameter: time_scale.'),
    (('service', 'type', '/nope', '--spin-time', '1'),
     "ros2 service type: service '/nope' not found (waited 1 s for discovery)"),
    (('service', 'call', '/MARC1/inject_fault', 'fjsp_msgs/srv/InjectFault', '{fault: 256}'),
     "ros2 service call: field 'fault' is a uint8, which 256 is not"),
    (('service', 'call', '/cancel_mission', 'fjsp_msgs/srv/Cancel'),
     "ros2 service call: unknown service type 'fjsp_msgs/srv/Cancel'"),
    (('action', 'info', '/nope', '--spin-time', '1'),
     "ros2 action info: action '/nope' not found"),
    (('action', 'send_goal', '/run_mission', 'fjsp_msgs/action/RunMission', '{panels: -1}'),
     "ros2 action send_goal: field 'panels' is a uint32, which -1 is not"),
    (('topic', 'hz', '/nope', '--spin-time', '1'),
     "ros2 topic hz: topic '/nope' not found (waited 1 s for discovery)"),
    (('topic', 'echo', '/plan', '--field', 'robots.nope', '--once'),
     "ros2 topic echo: fjsp_msgs/msg/Plan has no field 'robots.nope'"),
    (('interface', 'show', 'fjsp_msgs/msg/Nope'),
     "ros2 interface show: unknown interface 'fjsp_msgs/msg/Nope'"),
])
def test_bad_input_is_one_line_naming_it(fleet, args, error):
    done = ros2(fleet, *args)
    assert done.returncode == 1, done
    assert error in done.stderr and len(done.stderr.splitlines()) == 1, done.stderr


def test_param_set_takes_effect_and_load_sets_a_file(fleet, tmp_path):
    assert ros2(fleet, 'param', 'set', '/planner', 'heartbeat_timeout', '1.25').returncode == 0
    got = ros2(fleet, 'param', 'get', '/planner', 'heartbeat_timeout')
    assert got.stdout == 'Double value is: 1.25\n', got
    (tmp_path / 'planner.yaml').write_text(
        '/planner:\n  ros__parameters:\n    workers: 1\n    replan_time_limit: 2.5\n')
    loaded = ros2(fleet, 'param', 'load', '/planner', str(tmp_path / 'planner.yaml'))
    assert loaded.returncode == 0, loaded
    assert loaded.stdout.splitlines() == ['Set parameter workers successful',
                                          'Set parameter replan_time_limit successful']
    dumped = ros2(fleet, 'param', 'dump', '/planner')
    assert '    replan_time_limit: 2.5\n' in dumped.stdout
    assert '    workers: 1\n' in dumped.stdout
    assert '    heartbeat_timeout: 1.25\n' in dumped.stdout


def test_service_call_reaches_an_agent(fleet):
    done = ros2(fleet, 'service', 'call', '/MARC2/inject_fault', 'fjsp_msgs/srv/InjectFault',
                '{fault: 1}')
    assert done.returncode == 0, done
    # RECOVER of a robot that did not fail: refused by the agent, which names it.
    assert re.search(r'response:\nfjsp_msgs.srv.InjectFault_Response\(success=False, '
                     r'message=\".*MARC2.*\"\)', done.stdout), done.stdout


def test_topic_pub_reaches_echo(fleet):
    echo = subprocess.Popen(['ros2', 'topic', 'echo', '/front_end_check',
                             'std_msgs/msg/String', '--once'], env=fleet.env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        published = ros2(fleet, 'topic', 'pub', '/front_end_check', 'std_msgs/msg/String',
                         '{data: hello fleet}', '--once')
        assert published.returncode == 0, published
        assert "publishing #1: std_msgs.msg.String(data='hello fleet')" in published.stdout
        out, err = echo.communicate(timeout=30)
    finally:
        echo.kill()
    assert out == 'data: hello fleet\n---\n', (out, err)


def test_topic_hz_stops_after_its_duration(fleet):
    done = ros2(fleet, 'topic', 'hz', '/robot_states', '--duration', '4')
    assert done.returncode == 0, done
    # Four agents, each at least one state per heartbeat_period (0.2 s): about 20 a second,
    # once the command has discovered them all (the last report).
    rate = float(re.findall(r'average rate: (\d+\.\d+)', done.stdout)[-1])
    assert 5 < rate < 100, done.stdout


def test_node_and_topic_info(fleet):
    info = ros2(fleet, 'node', 'info', '/agent_MARC1')
    assert info.returncode == 0, info
    assert '  Service Servers:\n' in info.stdout
    assert '    /MARC1/inject_fault: fjsp_msgs/srv/InjectFault\n' in info.stdout
    assert '    /robot_states: fjsp_msgs/msg/RobotState\n' in info.stdout
    topic = ros2(fleet, 'topic', 'info', '/plan', '--verbose')
    assert topic.stdout.startswith('Type: fjsp_msgs/msg/Plan\n\nPublisher count: 1\n\n'
                                   'Node name: planner\n'), topic.stdout
    assert 'Durability: TRANSIENT_LOCAL' in topic.stdout


@pytest.mark.parametrize('args, code', [
    (('topic', 'echo', '/front_end_quiet', 'std_msgs/msg/String'), 0),  # nothing published
    (('topic', 'hz', '/robot_states'), 0),
    (('topic', 'pub', '/front_end_quiet', 'std_msgs/msg/String', '{data: x}', '-r', '5'), 0),
    (('param', 'get', '/nope', 'x', '--spin-time', '60'), 130),  # interrupted while waiting
])
def test_ctrl_c_ends_quietly(fleet, args, code):
    process = subprocess.Popen(['ros2', *args], env=fleet.env, text=True,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               preexec_fn=takes_ctrl_c)
    # Interrupted once it is on the graph (a loaded machine can take seconds to get there:
    # a Ctrl-C before is one at startup, not one ending the verb).
    fleet.wait_for(lambda o: f'_ros2cli_{process.pid}' in o.node.get_node_names(), 60,
                   'the command to join the graph')
    time.sleep(1)
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=30)
    assert process.returncode == code, (out, err)
    assert err == '', err
