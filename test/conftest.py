"""Makes the domain core importable from the source tree, so its tests need no build, draws
the run's seed for the property tests on generated scenarios (`generated_seeds`), and hands
out the longest files first."""

import os
import random
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
for package in ('fjsp_common', 'fjsp_planner', 'robot_agents'):
    path = str(REPO / 'src' / package)
    if path not in sys.path:
        sys.path.insert(0, path)

from generated_seeds import SEED_VARIABLE  # noqa: E402  (after the path is set)


def pytest_configure(config):
    # Set before collection, and inherited by any worker process, so all agree on the seeds.
    os.environ.setdefault(SEED_VARIABLE, str(random.SystemRandom().randrange(1, 10 ** 6)))


def pytest_report_header(config):
    return (f'generated scenarios: {SEED_VARIABLE}={os.environ[SEED_VARIABLE]} '
            '(set it to repeat this run)')


LONGEST_FIRST = (
    'solving/test_known_optima.py', 'integration/test_mission_service.py',
    'integration/test_robot_drivers.py', 'integration/test_missions.py', 'test_cli.py',
    'solving/bounds/test_bounds.py', 'integration/test_fleet_cli.py',
    'integration/test_failure_modes.py', 'integration/test_ros2_front_end.py',
    'integration/test_generated_fleets.py', 'integration/test_soak.py',
    'integration/test_flood.py', 'integration/test_fleet_respawn.py',
    'integration/test_restarts.py', 'integration/test_faults.py',
    'integration/test_observe_browser.py', 'integration/test_observe.py',
    'integration/test_scenarios.py', 'solving/test_large.py', 'integration/test_late_join.py',
)
"""The files that take longest in a whole run, longest first. With `--dist loadfile
--no-loadscope-reorder` pytest-xdist hands out whole files in the order collected: these go
first, so that no long file starts last while the other processes run out of work (by
default it would hand out the files with the most tests first, and these last)."""


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items) -> None:
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    root = Path(__file__).resolve().parent
    items.sort(key=lambda item: rank.get(item.path.relative_to(root).as_posix(), len(rank)))
