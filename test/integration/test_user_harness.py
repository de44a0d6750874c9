"""The harness as a user gets it: a project of their own whose conftest.py enables
`fjsp_planner.testing` with `pytest_plugins`, and the README's ten-line test that a robot
failure mid-mission is re-planned to completion, on a fleet that is not the paper's."""

import os
import subprocess
import sys

USER_CONFTEST = "pytest_plugins = ['fjsp_planner.testing']\n"
USER_TEST = """
def test_losing_r1_mid_mission(fjsp_fleet):
    fleet = fjsp_fleet('truss.yaml', time_scale=0.1).start()
    fleet.wait_for(lambda o: o.schedule_time() >= 8, 60, 'schedule time 8')
    fleet.inject_fault('R1', 'fail')
    fleet.check_mission_complete(timeout=120)
    last = fleet.observer.plans[-1]
    assert last.revision >= 2
    assert not next(r for r in last.robots if r.robot == 'R1').tasks
"""


def test_users_own_failure_test_passes(tmp_path):
    (tmp_path / 'conftest.py').write_text(USER_CONFTEST)
    (tmp_path / 'test_truss.py').write_text(USER_TEST)
    done = subprocess.run([sys.executable, '-m', 'pytest', '-q', '-p', 'no:cacheprovider',
                           str(tmp_path)], cwd=tmp_path, env=os.environ, capture_output=True,
                          text=True, timeout=400)
    assert done.returncode == 0, done.stdout + done.stderr
    assert '1 passed' in done.stdout
