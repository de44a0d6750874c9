"""Where the installed package keeps its files, and where a fleet's outputs go by default.

Outputs (charts, recordings, node logs) belong next to the workspace the user built, not in
whatever directory a node happened to be started from; a package installed system-wide (no
colcon workspace) writes under the ROS home directory instead, as ROS's own logs do.
"""

import os
import re
from pathlib import Path

from ament_index_python import packages

PACKAGE = 'fjsp_planner'


def default_out_dir() -> Path:
    """`out/` of the colcon workspace fjsp_planner is installed in (the directory holding its
    install space, e.g. `ros2_ws/out`), else `$ROS_HOME/fjsp/out` (`~/.ros/fjsp/out`)."""
    try:
        prefix = Path(packages.get_package_prefix(PACKAGE)).resolve()
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
        return Path(packages.get_package_prefix(PACKAGE)) / 'share' / PACKAGE / 'scenarios'
    except (LookupError, OSError, ValueError):
        return None


def safe_file_name(name: str, limit: int = 120) -> str:
    """`name` usable as a file name: a mission id comes off the network and must not be able
    to write outside the output directory."""
    cleaned = re.sub(r'[^A-Za-z0-9_.-]', '_', name).lstrip('.')[:limit]
    return cleaned or 'unnamed'
