#!/usr/bin/env bash
# The quick-start scene, 40 steps, run from a directory that is not the repository: its relative
# init.from (../states/mfu180w_dr6c4d_s5_t5.62.nc) resolves against the scene file, the shipped state loads by
# id, and chansph compare runs on the result. A relative init.from given with --set stays
# relative to the working directory.
# usage: quickstart_smoke.sh CHANSPH SCENES RUNS
set -euo pipefail
chansph=$1 scenes=$2 runs=$3
work=$runs/quickstart_smoke
rm -rf "$work" && mkdir -p "$work" && cd "$work"
state=$(cd "$scenes/../states" && pwd)/mfu180w_dr6c4d_s5_t5.62.nc
"$chansph" run "$scenes/quickstart.ini" --out run --set time.t_end=0.007 --set output.stats_every=10 \
  --set output.write_every=0 \
  > out.txt 2>&1 || { cat out.txt; echo "FAIL: quick-start scene did not run"; exit 1; }
grep -q "of 148680 particles from $state" run/log.txt out.txt ||
  { cat out.txt; echo "FAIL: init.from did not resolve to $state"; exit 1; }
grep -q "^from = $state\$" run/scene.used.ini ||
  { grep '^from' run/scene.used.ini; echo "FAIL: scene.used.ini does not hold the absolute path"; exit 1; }
dns=$(cd "$scenes/../../stats/dns/mkm1999" && pwd)/chan180.means
"$chansph" compare run/stats.nc --dns "$dns" --no-plots > compare.txt ||
  { cat compare.txt; echo "FAIL: compare"; exit 1; }
grep -q "^U+       log layer" compare.txt || { cat compare.txt; echo "FAIL: no U+ row"; exit 1; }
# the quick-start's report on this run (jobs/quickstart.sh --report): the details in
# compare/report.txt, the plots, and a last screen of at most 30 lines that says what ran, the
# turbulence verdict with its evidence and the table against the DNS and the shipped long run
src=$(cd "$scenes/../.." && pwd)
CHANSPH=$chansph QUICKSTART_OUT=$work/run "$src/jobs/quickstart.sh" --report > screen.txt 2>&1 ||
  { cat screen.txt; echo "FAIL: jobs/quickstart.sh --report"; exit 1; }
last=$(awk 'NF == 0 { n = 0; next } { n++ } END { print n }' screen.txt)
[ "$last" -le 30 ] || { cat screen.txt; echo "FAIL: the last screen has $last lines (> 30)"; exit 1; }
for want in "^quickstart: ran jobs/scenes/quickstart.ini; chansph-stats summary" \
  "^$work/run/stats.nc: Re_tau 180 \(driving force\), quasi-DNS" "^Is the flow turbulent\? (yes|no)" \
  "^-u'v'\+ +\| .*\| 0.723$" "long run, 14.4 turnovers" "^Details: $work/run/compare/report.txt"; do
  grep -Eq "$want" screen.txt || { cat screen.txt; echo "FAIL: no line /$want/ on the last screen"; exit 1; }
done
for f in report.txt compare.csv profiles.png Uplus.png; do
  [ -s "run/compare/$f" ] || { echo "FAIL: run/compare/$f not written"; exit 1; }
done
grep -q "^## the shipped long run" run/compare/report.txt && grep -q "^largest error" run/compare/report.txt ||
  { cat run/compare/report.txt; echo "FAIL: report.txt lacks the comparisons"; exit 1; }
# --set: relative to the working directory, named in the message
if "$chansph" run "$scenes/quickstart.ini" --out run2 --set init.from=no_such_state.nc \
  > err.txt 2>&1; then
  echo "FAIL: a missing init.from was accepted"; exit 1
fi
grep -q "error: no_such_state.nc (init.from): cannot open" err.txt ||
  { cat err.txt; echo "FAIL: message for a missing --set init.from"; exit 1; }
echo "PASS: quick-start scene runs from $work, state $state; last screen $last lines"
