"""Integration tests run real node processes through the public harness,
`fjsp_planner.testing` (docs/testing.md), which needs the built and sourced workspace."""

import os
import shutil

import pytest

if shutil.which('ros2') is None or 'AMENT_PREFIX_PATH' not in os.environ:
    pytest.exit('integration tests need the built workspace: run `bash ros2_ws/test.sh`, or '
                '`bash ros2_ws/bootstrap.sh && source ros2_ws/env.sh` before pytest', 4)

# The harness's fixture, as a user's conftest gets it with pytest_plugins (which pytest
# allows only in the top-level conftest, and the core tests need no ROS).
from fjsp_planner import testing  # noqa: E402
from fjsp_planner.testing import fjsp_fleet, fjsp_network, ros_domain  # noqa: E402, F401

HERE = os.path.dirname(__file__)

# This suite runs several fleets at once (module-scoped fleets beside each test's own): they
# take ids of a range, one each, even where the shell has a ROS_DOMAIN_ID of its own.
os.environ.setdefault(testing.DOMAINS_VARIABLE, f'{testing.DOMAINS[0]}-{testing.DOMAINS[-1]}')


def pytest_collection_modifyitems(items) -> None:
    """Every test here starts processes: marked `integration`, so the fast loop
    (`-m "not integration and not slow"`) leaves them out. Each is run once more if it fails
    (pytest-rerunfailures): on two shared cores a node process can stall for seconds, and a
    test's waits then race its mission. A rerun shows as `R` and in the summary's count, so
    a test that needs one is still seen and looked at."""
    for item in items:
        if str(item.path).startswith(HERE):
            item.add_marker(pytest.mark.integration)
            item.add_marker(pytest.mark.flaky(reruns=1))
    testing.pytest_collection_modifyitems(items)
