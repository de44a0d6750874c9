"""Where the installed package keeps its files, and where a fleet's outputs go by default.

Outputs (charts, recordings, node logs) belong next to the workspace the user built, not in
whatever directory a node happened to be started from; a package installed system-wide (no
colcon workspace) writes under the ROS home directory instead, as ROS's own logs do.
"""

import os
from pathlib import Path

from ament_index_python.packages import get_package_prefix

PACKAGE = 'fjsp_planner'


def default_out_dir() -> Path:
    """`out/` of the colcon workspace fjsp_planner is installed in (the directory holding its
    install space, e.g. `ros2_ws/out`), else `$ROS_HOME/fjsp/out` (`~/.ros/fjsp/out`)."""
    try:
        prefix = Path(get_package_prefix(PACKAGE)).resolve()
    except (LookupError, OSError, ValueError):  # not installed, or AMENT_PREFIX_PATH unset
        prefix = None
    if prefix is not None:
        # A merged install space is the prefix itself; an isolated one, its parent.
        for install in (prefix, prefix.parent):
            if (install / '.colcon_install_layout').is_file():
                return install.parent / 'out'
    ros_home = Path(os.environ.get('ROS_HOME') or Path.home() / '.ros').expanduser()
    return ros_home / 'fjsp' / 'out'


def installed_scenarios() -> Path | None:
    """The scenario files installed with the package (`share/fjsp_planner/scenarios`)."""
    try:
        return Path(get_package_prefix(PACKAGE)) / 'share' / PACKAGE / 'scenarios'
    except (LookupError, OSError, ValueError):
        return None
