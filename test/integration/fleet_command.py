"""`ros2 run fjsp_planner fleet` as a test runs it: a subprocess on the test's own ROS domain,
and the node processes it started, found through /proc."""

import os
import subprocess
import time
from pathlib import Path

NODES = 6
"""The planner, the paper's four robots and the monitor."""


def launcher(out: Path, *args, domain: int) -> subprocess.Popen:
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               PYTHONUNBUFFERED='1')
    return subprocess.Popen(['ros2', 'run', 'fjsp_planner', 'fleet', *args, '--out', str(out)],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def identity(pid: int) -> tuple[int, str] | None:
    """(pid, start time) of a live process, None if it is gone or a zombie."""
    try:
        fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    except OSError:
        return None
    return None if fields[0] in 'ZX' else (pid, fields[19])


def children(pid: int) -> set[tuple[int, str]]:
    found = set()
    for entry in Path('/proc').iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / 'stat').read_text().rsplit(')', 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid and fields[0] not in 'ZX':
                found.add((int(entry.name), fields[19]))
    return found


def wait_for_nodes(process: subprocess.Popen, timeout: float = 30.0) -> set:
    deadline = time.monotonic() + timeout
    while len(nodes := children(process.pid)) < NODES:
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, f'only {len(nodes)} nodes after {timeout:g} s'
        time.sleep(0.1)
    return nodes


def still_running(nodes, timeout: float) -> set:
    """The nodes still alive after waiting up to `timeout` seconds for them to go."""
    deadline = time.monotonic() + timeout
    while (alive := {n for n in nodes if identity(n[0]) == n}) and time.monotonic() < deadline:
        time.sleep(0.1)
    return alive


def node_pid(process: subprocess.Popen, word: str) -> int:
    """The pid of the launcher's node whose command line holds `word`."""
    for pid, _ in children(process.pid):
        try:
            command = Path(f'/proc/{pid}/cmdline').read_bytes().replace(b'\0', b' ').decode()
        except OSError:
            continue
        if word in command:
            return pid
    raise AssertionError(f'no node of the launcher runs {word!r}')
