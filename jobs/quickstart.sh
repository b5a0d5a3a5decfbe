#!/usr/bin/env bash
# Quick start: set up, run the turbulent channel jobs/scenes/quickstart.ini (quasi-DNS at
# Re_tau = 180, dr+ = 6, the converged run's scene and scheme in its 2 x 2 x 1.4 delta box, from
# that run's developed end state in jobs/states/, 0.2 eddy turnover times, 2.5-4 minutes on 2 cores) into runs/quickstart/, compare it with the
# DNS of Moser, Kim & Mansour (1999) and end with one screen: is it turbulent (the evidence),
# its peaks and largest deviations against the DNS beside those of the shipped converged run,
# where the plots and the details are, what to run next. The details (the full comparison
# tables, the momentum and Reynolds-stress budgets) go to runs/quickstart/compare/report.txt.
# usage: jobs/quickstart.sh            set up, run, compare
#        jobs/quickstart.sh --report   compare and summarise an existing run again (no run)
# QUICKSTART_OUT (default runs/quickstart), QUICKSTART_SCENE (default jobs/scenes/quickstart.ini)
# and CHANSPH (default build/chansph) change the run (the tests use a smoke version).
# A laminar check instead: build/chansph run jobs/scenes/poiseuille3d.ini --out runs/laminar
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"
out=${QUICKSTART_OUT:-runs/quickstart}
scene=${QUICKSTART_SCENE:-jobs/scenes/quickstart.ini}
dns=stats/dns/mkm1999/chan180.means
long=jobs/states/mfu180w_dr6c4d_stats.nc
stats=stats/python/chansph-stats
chansph=${CHANSPH:-build/chansph}
took=""
if [ "${1:-}" != "--report" ]; then
  jobs/setup.sh
  echo "quickstart: running $scene into $out/ (3-4 minutes on 2 idle cores)"
  start=$(date +%s)
  "$chansph" run "$scene" --out "$out" --overwrite
  took=" in $(($(date +%s) - start)) s"
fi
[ -f "$out/stats.nc" ] || { echo "error: $out/stats.nc: cannot open: no run there (run jobs/quickstart.sh)"; exit 1; }
mkdir -p "$out/compare"
report=$out/compare/report.txt
details() { # the full comparison, into report.txt; the first failure stops it
  echo "# jobs/quickstart.sh: the details behind its last screen ($(date -u +%FT%TZ))" &&
    echo && echo "## $chansph compare $out/stats.nc --dns $dns --out $out/compare" &&
    echo "# L2, Linf: differences from the DNS in wall units; stderr: our own statistical uncertainty" &&
    "$chansph" compare "$out/stats.nc" --dns "$dns" --out "$out/compare" &&
    echo && echo "## the same in wall units of the driving force balance (--u-tau force)" &&
    "$chansph" compare "$out/stats.nc" --dns "$dns" --out "$out/compare_force" --no-plots \
      --u-tau force &&
    echo && echo "## the convergence line of the run's log ($out/log.txt)" &&
    { grep '^stats:' "$out/log.txt" | tail -1; } &&
    if [ -f "$long" ]; then
      echo && echo "## the shipped long run, for comparison (NOT this run): $long" &&
        "$chansph" compare "$long" --dns "$dns" --out "$out/compare_long" --no-plots
    fi &&
    echo && echo "## the figures: $stats figures $out/stats.nc --out $out/compare" &&
    "$stats" figures "$out/stats.nc" --dns "$dns" --out "$out/compare"
}
details > "$report" 2>&1 ||
  { tail -5 "$report"; echo "error: $report: the comparison failed (above)"; exit 1; }
with_long=()
[ -f "$long" ] && with_long=(--long "$long")
echo
echo "quickstart: ran $scene$took; chansph-stats summary of its stats.nc:"
"$stats" summary "$out/stats.nc" --dns "$dns" "${with_long[@]}"
if [ "$scene" = jobs/scenes/quickstart.ini ]; then
  echo "0.2 turnovers show that the flow is turbulent, not what it converges to; the long run (the"
  echo "same scene, 14.4 turnovers after the first) is the converged answer."
fi
cat <<TXT
Plots:   $out/compare/profiles.png (the five profiles), rs_budget_{uu,vv,ww,uv,k}.png
Details: $report (tables per y+ range, budgets), compare.csv, rs_budget.csv
Next:    docs/user-guide.md (monitor, continue, extract, compare, plot); continue this run with
         build/chansph resume $out --set time.t_end=T   (T in delta/u_tau)
TXT
