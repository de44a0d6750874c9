"""The planner survives its own disk: a `journal_dir` that cannot be one stops it at start
(exit 2), and a journal that fills its disk sets the mission aside — blocked, with the reason —
until there is room again, when the mission resumes and completes.

The full disk is real: the planner runs in a mount namespace of its own (`unshare`, as root
or through a user namespace) on a 64 KiB tmpfs that a filler file leaves one page of; the
test frees it through the planner's view of its mounts, /proc/<pid>/root. A file size limit
(RLIMIT_FSIZE) would also cut the planner's log, and a read-only directory does not stop
root."""

import os
import subprocess
from pathlib import Path

import pytest

from fjsp_msgs.msg import MissionStatus
from fjsp_planner.launcher.supervision import find_executable

from repo_paths import PAPER

TMPFS = 64 * 1024
FILLER = TMPFS - 4096
"""Leaves one page: the mission's first record, not its first plan."""


def test_a_journal_dir_that_is_a_file_stops_the_planner_at_start(tmp_path, ros_domain):
    file = tmp_path / 'journal'
    file.write_text('')
    env = dict(os.environ, ROS_DOMAIN_ID=str(ros_domain),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    done = subprocess.run([str(find_executable('fjsp_planner', 'planner_node')), '--ros-args',
                           '-p', f'journal_dir:={file}'], env=env, capture_output=True,
                          text=True, timeout=60)
    output = done.stdout + done.stderr
    assert done.returncode == 2, output
    assert f"parameter 'journal_dir': {file}: is not a directory" in output
    assert 'Traceback' not in output


def on_tmpfs(directory: Path) -> list[str]:
    """A command prefix running a node with `directory` on a small tmpfs of its own, filled
    but for one page; skips the test where mount namespaces cannot be made."""
    user = [] if os.geteuid() == 0 else ['--map-root-user']
    mount = (f'mount -t tmpfs -o size={TMPFS} tmpfs "$0" && '
             f'head -c {FILLER} /dev/zero > "$0/filler" && exec "$@"')
    prefix = ['unshare', *user, '--mount', '--propagation', 'private', 'sh', '-c', mount,
              str(directory)]
    try:
        tried = subprocess.run([*prefix, 'true'], capture_output=True, text=True, timeout=10)
    except FileNotFoundError:
        pytest.skip('no unshare command')
    if tried.returncode != 0:
        pytest.skip(f'cannot mount a private tmpfs here: {tried.stderr.strip()}')
    return prefix


def test_a_full_journal_disk_blocks_the_mission_until_it_has_room(fjsp_fleet, tmp_path):
    journal = tmp_path / 'journal'
    journal.mkdir()
    fleet = fjsp_fleet(PAPER, time_scale=0.05, planner={'journal_dir': journal},
                       prefixes={'planner': on_tmpfs(journal)}).start()
    fleet.wait_for(lambda o: o.status.state == MissionStatus.STATE_BLOCKED
                   and any('No space left on device' in r for r in o.status.blocked_reasons),
                   60, 'the mission blocked by its full journal')
    assert not fleet.observer.plans, 'a plan the journal does not hold was published'
    assert 'planner' not in fleet.exited()
    planner = fleet.processes['planner'].pid
    (Path(f'/proc/{planner}/root') / journal.relative_to('/') / 'filler').unlink()
    fleet.check_mission_complete(timeout=120)
    assert 'Traceback' not in fleet.log('planner')
    assert 'set aside' in fleet.log('planner')
