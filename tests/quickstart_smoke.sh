#!/usr/bin/env bash
# The quick-start scene, 40 steps, run from a directory that is not the repository: its relative
# init.from (../states/mfu180_dr45_t4.5.nc) resolves against the scene file, the shipped state loads by
# id, and chansph compare runs on the result. A relative init.from given with --set stays
# relative to the working directory.
# usage: quickstart_smoke.sh CHANSPH SCENES RUNS
set -euo pipefail
chansph=$1 scenes=$2 runs=$3
work=$runs/quickstart_smoke
rm -rf "$work" && mkdir -p "$work" && cd "$work"
state=$(cd "$scenes/../states" && pwd)/mfu180_dr45_t4.5.nc
"$chansph" run "$scenes/quickstart.ini" --out run --set time.t_end=0.007 --set output.stats_every=10 \
  --set output.write_every=0 \
  > out.txt 2>&1 || { cat out.txt; echo "FAIL: quick-start scene did not run"; exit 1; }
grep -q "of 176960 particles from $state" run/log.txt out.txt ||
  { cat out.txt; echo "FAIL: init.from did not resolve to $state"; exit 1; }
grep -q "^from = $state\$" run/scene.used.ini ||
  { grep '^from' run/scene.used.ini; echo "FAIL: scene.used.ini does not hold the absolute path"; exit 1; }
dns=$(cd "$scenes/../../stats/dns/mkm1999" && pwd)/chan180.means
"$chansph" compare run/stats.nc --dns "$dns" --no-plots > compare.txt ||
  { cat compare.txt; echo "FAIL: compare"; exit 1; }
grep -q "^U+       log layer" compare.txt || { cat compare.txt; echo "FAIL: no U+ row"; exit 1; }
# --set: relative to the working directory, named in the message
if "$chansph" run "$scenes/quickstart.ini" --out run2 --set init.from=no_such_state.nc \
  > err.txt 2>&1; then
  echo "FAIL: a missing init.from was accepted"; exit 1
fi
grep -q "error: no_such_state.nc (init.from): cannot open" err.txt ||
  { cat err.txt; echo "FAIL: message for a missing --set init.from"; exit 1; }
echo "PASS: quick-start scene runs from $work, state $state"
