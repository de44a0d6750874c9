"""Makes the domain core importable from the source tree, so its tests need no build, and
draws the run's seed for the property tests on generated scenarios (`generated_seeds`)."""

import os
import random
import sys
from pathlib import Path

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
