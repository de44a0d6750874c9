#!/usr/bin/env bash
# The README's first command: build what is needed, then run one mission on the node network
# with the fleet launcher (`ros2 run fjsp_planner fleet`): the planner, one agent per robot of
# the scenario and the monitor, stopped when the mission ends. The scenario is the paper's
# one-panel solar panel unless `--scenario FILE` names another; every other argument goes to
# the launcher, e.g. `bash ros2_ws/demo.sh --scenario my.yaml --time-scale 0.5`.
set -euo pipefail

WS="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
bash "$WS/bootstrap.sh"
# shellcheck disable=SC1091
source "$WS/env.sh"

scenario=''
launcher_args=()
while (($#)); do
  case "$1" in
    --scenario)
      [[ $# -ge 2 ]] || { echo 'demo.sh: --scenario needs a file' >&2; exit 2; }
      scenario="$2"; shift 2 ;;
    --scenario=*) scenario="${1#--scenario=}"; shift ;;
    *) launcher_args+=("$1"); shift ;;
  esac
done
if [[ -z "$scenario" ]]; then
  scenario="$(python -c 'from fjsp_planner.workspace import installed_scenarios
print(installed_scenarios() / "solar_panel.yaml")')"
fi
# A demo stays on this machine unless the caller says otherwise.
export ROS_AUTOMATIC_DISCOVERY_RANGE="${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}"
# --timeout first, so that one given by the caller wins.
exec ros2 run fjsp_planner fleet "$scenario" --exit-on-complete --timeout 600 \
  "${launcher_args[@]}"
