# Source this (after bootstrap.sh) to use the workspace: `source ros2_ws/env.sh`.
# Activates the venv, the install space and, where no real ROS 2 CLI exists, the small
# `ros2` front end in ros2_ws/bin (ros2cli is not on PyPI).

_fjsp_ws="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if [[ ! -x "$_fjsp_ws/.venv/bin/python" || ! -f "$_fjsp_ws/install/setup.bash" ]]; then
  echo "env.sh: workspace not built; run bash $_fjsp_ws/bootstrap.sh first" >&2
  unset _fjsp_ws
  return 1 2>/dev/null || exit 1
fi

# shellcheck disable=SC1091
source "$_fjsp_ws/.venv/bin/activate"
# The install space's setup scripts reference unset variables; keep callers' `set -u` happy.
case "$-" in *u*) _fjsp_nounset=1; set +u ;; *) _fjsp_nounset=0 ;; esac
# shellcheck disable=SC1091
source "$_fjsp_ws/install/setup.bash"
[[ "$_fjsp_nounset" == 1 ]] && set -u

_fjsp_prepend() {  # _fjsp_prepend VAR DIR: put DIR first in the colon list VAR, once
  local current="${!1:-}"
  case ":$current:" in *":$2:"*) ;; *) export "$1=$2${current:+:$current}" ;; esac
}
_fjsp_prepend AMENT_PREFIX_PATH "$VIRTUAL_ENV"
for _fjsp_pkg in "$_fjsp_ws"/install/*/; do
  [[ -d "$_fjsp_pkg/share/ament_index" ]] && _fjsp_prepend AMENT_PREFIX_PATH "${_fjsp_pkg%/}"
done
_fjsp_prepend PATH "$_fjsp_ws/install/fjsp_planner/lib/fjsp_planner"
if ! command -v ros2 >/dev/null 2>&1 || [[ "$(command -v ros2)" == "$_fjsp_ws/bin/ros2" ]]; then
  _fjsp_prepend PATH "$_fjsp_ws/bin"
fi
unset _fjsp_ws _fjsp_pkg _fjsp_nounset
unset -f _fjsp_prepend
