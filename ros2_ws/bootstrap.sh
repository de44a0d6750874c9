#!/usr/bin/env bash
# Makes the workspace usable from a fresh clone: venv, pinned requirements, colcon build.
# Idempotent: pip runs only when requirements.txt changed, colcon only when src/ changed.
set -euo pipefail

WS="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
REPO="$(dirname "$WS")"
VENV="$WS/.venv"
PYTHON="${PYTHON:-python3}"

fail() { echo "bootstrap: $*" >&2; exit 1; }

command -v "$PYTHON" >/dev/null || fail "'$PYTHON' not found; install Python 3.11+"
"$PYTHON" -c 'import sys; sys.exit(sys.version_info < (3, 11))' \
  || fail "Python 3.11+ needed, '$PYTHON' is $("$PYTHON" --version 2>&1)"
for tool in cmake cc c++; do
  command -v "$tool" >/dev/null || fail "'$tool' not found; fjsp_msgs needs cmake and a C/C++ compiler"
done

if [[ ! -x "$VENV/bin/python" ]]; then
  echo "bootstrap: creating $VENV"
  "$PYTHON" -m venv "$VENV" || fail "could not create the venv (on Debian: apt-get install python3-venv)"
fi

req_hash="$(sha256sum "$WS/requirements.txt" | cut -d' ' -f1)"
req_stamp="$VENV/.requirements.sha256"
if [[ "$(cat "$req_stamp" 2>/dev/null)" != "$req_hash" ]]; then
  echo "bootstrap: installing requirements (first time takes about a minute)"
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check -r "$WS/requirements.txt" \
    || fail "pip could not install $WS/requirements.txt"
  echo "$req_hash" > "$req_stamp"
fi

# Everything colcon reads: sources, package manifests, scenarios installed as data files.
src_hash="$(cd "$REPO" && find src config -type f -not -path '*/__pycache__/*' -print0 \
  | sort -z | xargs -0 sha256sum | sha256sum | cut -d' ' -f1)"
src_stamp="$WS/install/.sources.sha256"
if [[ "$(cat "$src_stamp" 2>/dev/null)" != "$src_hash" ]]; then
  echo "bootstrap: colcon build"
  mkdir -p "$WS/log"
  (
    cd "$WS"
    # shellcheck disable=SC1091
    source "$VENV/bin/activate"
    export AMENT_PREFIX_PATH="$VIRTUAL_ENV" CMAKE_PREFIX_PATH="$VIRTUAL_ENV"
    colcon --log-base "$WS/log" build --base-paths "$REPO/src" \
      --build-base "$WS/build" --install-base "$WS/install" \
      --event-handlers console_cohesion- summary- status- \
      > "$WS/log/colcon-build.out" 2>&1 \
      || { tail -n 40 "$WS/log/colcon-build.out" >&2; exit 1; }
  ) || fail "colcon build failed (full output: $WS/log/colcon-build.out)"
  # Every node process imports the install space. Where PYTHONDONTWRITEBYTECODE is set, none
  # may write its bytecode, so each would compile our sources again on every start.
  "$VENV/bin/python" -m compileall -q "$WS/install" >/dev/null \
    || fail "could not compile the install space's Python sources"
  echo "$src_hash" > "$src_stamp"
fi
