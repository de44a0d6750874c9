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
from fjsp_planner.testing import (  # noqa: E402, F401
    fjsp_fleet,
    fjsp_network,
    pytest_collection_modifyitems,
    ros_domain,
)
