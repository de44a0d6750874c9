#!/usr/bin/env bash
# The README's second command: build what is needed, lint, then run every test. Arguments,
# if any, are handed to one pytest run instead (e.g. `-m "not integration and not slow"`).
set -euo pipefail

WS="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
bash "$WS/bootstrap.sh"
# shellcheck disable=SC1091
source "$WS/env.sh"
cd "$(dirname "$WS")"

ruff check .
status=0
if [[ $# -gt 0 ]]; then
  pytest "$@" || status=$?
else
  # Fast DDS lists the network interfaces once per process: the tests across network
  # namespaces run in a process of their own, beside the others (they mostly wait on their
  # links); their output follows the others'.
  links_log="$(mktemp)"
  pytest test/integration/test_network_links.py --durations=5 >"$links_log" 2>&1 &
  links=$!
  # The rest on FJSP_TEST_WORKERS processes (pytest-xdist), a file per process at a time,
  # the longest files first (test/conftest.py): integration tests mostly wait on their time
  # scales, so three share two cores.
  pytest test/ --ignore=test/integration/test_network_links.py \
    -n "${FJSP_TEST_WORKERS:-3}" --dist loadfile --no-loadscope-reorder --durations=15 \
    || status=$?
  links_status=0
  wait "$links" || links_status=$?
  cat "$links_log"
  rm -f "$links_log"
  if [[ $status -eq 0 ]]; then status=$links_status; fi
fi
# pytest exits 5 when it collected nothing: for this suite that is a failure too.
if [[ $status -eq 5 ]]; then
  echo "test.sh: pytest collected no tests" >&2
fi
exit "$status"
