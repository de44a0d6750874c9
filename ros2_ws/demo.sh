#!/usr/bin/env bash
# The README's first command: build what is needed, then run the planner, the four robot
# agents and the mission monitor on the paper's one-panel solar panel until the mission ends.
# Extra arguments go to the launcher, e.g. `bash ros2_ws/demo.sh --time-scale 0.5`.
set -euo pipefail

WS="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
bash "$WS/bootstrap.sh"
# shellcheck disable=SC1091
source "$WS/env.sh"
cd "$(dirname "$WS")"
exec python "$WS/launch_demo.py" "$@"
