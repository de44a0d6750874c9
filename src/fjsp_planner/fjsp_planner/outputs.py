"""Where the fleet's pictures and recordings go unless told otherwise: `out/` of the colcon
workspace fjsp_planner is installed in (the directory holding its `install/`), else
`~/.ros/fjsp/out`. Never the current directory: nodes started from anywhere (a launcher, a
test, a service manager) would scatter files wherever they happened to start."""

import re
from pathlib import Path

FALLBACK = Path('~/.ros/fjsp/out')


def default_out_dir() -> Path:
    from ament_index_python.packages import PackageNotFoundError, get_package_prefix

    try:
        prefix = Path(get_package_prefix('fjsp_planner')).resolve()
    except (PackageNotFoundError, LookupError, ValueError):
        return FALLBACK.expanduser()
    for directory in (prefix, *prefix.parents):
        if directory.name == 'install':
            return directory.parent / 'out'
    return FALLBACK.expanduser()


def safe_file_name(name: str, limit: int = 120) -> str:
    """`name` usable as a file name: a mission id comes off the network and must not be able
    to write outside the output directory."""
    cleaned = re.sub(r'[^A-Za-z0-9_.-]', '_', name).lstrip('.')[:limit]
    return cleaned or 'unnamed'
