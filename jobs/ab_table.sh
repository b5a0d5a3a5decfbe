#!/usr/bin/env bash
# The first A/B table (docs/validation/turbulent_channel.md): each numerical setting
# against the reference of jobs/scenes/mfu180_ab.ini (background pressure 0, h = 1.6 dr), all
# from the same synthetic-eddy start, to t u_tau/delta = T (default 0.6), then the table over
# the second half. usage: jobs/ab_table.sh [OUTDIR] [T]   (about 1 minute a run when idle)
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-runs/ab} tend=${2:-0.6}
mkdir -p "$out"
chansph=${CHANSPH:-$root/build/chansph}
runs=()
ab() { # ab NAME [--set key=value ...]
  local name=$1
  shift
  runs+=("$out/$name")
  [ -f "$out/$name/stats.nc" ] && return
  "$chansph" run "$root/jobs/scenes/mfu180_ab.ini" --out "$out/$name" --overwrite \
    --set time.t_end="$tend" "$@" > "$out/$name.log" 2>&1 ||
    echo "$name: the run failed ($(grep -m1 '^error' "$out/$name.log"))"
}
ab reference
ab pb_0.01 --set fluid.p_background=0.01
ab pb_0.001 --set fluid.p_background=0.001
ab h_1.3 --set sph.h_over_dr=1.3
ab xi_x0.5 --set sph.xi=12.5
ab xi_x2 --set sph.xi=50
ab morris --set sph.viscous=morris
ab wall_weight_analytic --set sph.wall_pressure_weight=analytic
ab c0_15 --set fluid.c0=277.5
ab corrected_gradient --set sph.pressure_gradient=corrected
ab shifting --set sph.shifting=fickian
done=()
for r in "${runs[@]}"; do [ -f "$r/stats.nc" ] && done+=("$r"); done
"$root/stats/python/chansph-stats" ab_table "${done[@]}" --from "$(echo "$tend / 2" | bc -l)" --markdown
