#!/usr/bin/env bash
# The README's second command: build what is needed, lint, then run every test.
set -euo pipefail

WS="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
bash "$WS/bootstrap.sh"
# shellcheck disable=SC1091
source "$WS/env.sh"
cd "$(dirname "$WS")"

ruff check .
status=0
pytest test/ --durations=15 "$@" || status=$?
# pytest exits 5 when it collected nothing: for this suite that is a failure too.
if [[ $status -eq 5 ]]; then
  echo "test.sh: pytest collected no tests" >&2
fi
exit "$status"
