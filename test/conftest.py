"""Makes the domain core importable from the source tree, so its tests need no build."""

import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
for package in ('fjsp_common', 'fjsp_planner', 'robot_agents'):
    path = str(REPO / 'src' / package)
    if path not in sys.path:
        sys.path.insert(0, path)
