#!/usr/bin/env bash
# Quick start: set up, run the default scene jobs/scenes/quickstart.ini into runs/quickstart/,
# and plot its mean velocity profile against the reference (laminar: analytical Poiseuille).
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
echo "  stats.nc      profiles (u_mean, v_mean, w_mean, n_samples) and time series (ncdump -h)"
echo "  particles.nc  final particle state (x, y, z, u, v, w, rho, p, gamma, mass by id)"
echo "  profile.png   u_mean against the reference profile"
echo "  log.txt       progress log and per-phase timing"
