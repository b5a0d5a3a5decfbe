#!/usr/bin/env bash
# Set up chansph and run the whole ctest suite (all labels). Extra arguments go to ctest,
# e.g. tests/run.sh -L unit, or tests/run.sh -LE long.
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"
jobs/setup.sh || exit 1
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
cd build
ctest --output-on-failure -j1 "$@" 2>&1 | tee ctest.log | grep -vE "^\s*$" | tail -n 60
status=${PIPESTATUS[0]}
echo "tests: ctest exit status $status (full log: build/ctest.log)"
exit "$status"
