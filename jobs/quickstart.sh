#!/usr/bin/env bash
# Quick start: set up, run the default scene jobs/scenes/quickstart.ini into runs/quickstart/,
# plot its mean velocity profile against the reference (laminar: analytical Poiseuille), and end
# with the profiles and their standard errors (chansph extract) and how converged they are.
# The turbulent quick-start against DNS (chansph compare) comes with the turbulence issue.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"
jobs/setup.sh
out=runs/quickstart
echo "quickstart: running jobs/scenes/quickstart.ini into $out/"
build/chansph run jobs/scenes/quickstart.ini --out "$out" --overwrite
/usr/bin/python3 stats/plot_profile.py "$out/stats.nc" -o "$out/profile.png"
echo
echo "quickstart: results in $out/"
echo "  stats.nc      profiles with standard errors, raw windows, time series (docs/stats-format.md)"
echo "  particles.nc  final particle state (x, y, z, u, v, w, rho, p, gamma, mass by id)"
echo "  profile.png   u_mean against the reference profile"
echo "  log.txt       progress log and per-phase timing"
echo
echo "quickstart: mean profiles (outer units; build/chansph extract $out/stats.nc --units outer)"
build/chansph extract "$out/stats.nc" --units outer --format tsv --var u_mean,uu,uv,total_stress
echo
echo "quickstart: convergence of the statistics (from $out/log.txt):"
grep '^stats:' "$out/log.txt" | tail -1
