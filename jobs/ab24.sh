#!/usr/bin/env bash
# The A/B at dr+ = 6 (docs/validation/turbulent_channel.md): numerical settings against the
# reference at dr+ = 6 in the minimal unit (jobs/scenes/mfu180_dr6_dev.ini, 74 340 particles),
# each run from a developed start for T turnovers (default 3) with the Reynolds-stress budgets,
# averaged from t = 1 on; then the table (chansph-stats ab_table: sustain, peaks, numerical
# stress share, cost; the redistribution terms of vv and ww against MKM at y+ = 15 and 40 and the
# pressure noise). Two start states (two "seeds"):
#   a  jobs/states/mfu180_dr6_t3.nc      (the dr+ = 6 field after 3 turnovers at dr+ = 6)
#   b  jobs/states/mfu180_dr45_t10.nc    (the developed dr+ = 4.5 field, interpolated)
# and, to screen candidates cheaply first, the box twice the span at dr+ = 9 (NY = 40, 43 680
# particles, about 2 minutes a turnover with 2 threads; the set-up of jobs/les24.sh), from two
# developed wide-box dr+ = 6 states interpolated onto its lattice:
#   w9a  jobs/states/mfu180w_dr6_t12.nc  (t = 12.1 of the converged run)
#   w9b  jobs/states/mfu180w_dr6_t17.nc  (t = 17.8 of the same run, 5.7 turnovers later)
# Each run is a batch job through jobs/chain.sh (checkpoints; start the script again to go on);
# about 4 minutes a turnover at dr+ = 6 and 1.6 at dr+ = 9 (w9*) with 2 threads on an idle
# 2-core machine (h = 2 dr: 1.5 times that): pass the names of the candidates to run only those.
# A finished run is continued with jobs/chain.sh DIR -- --set time.t_end=T (the comparison at
# dr+ = 6 ran c4_h2.0 and the references of both starts to T = 5).
# Results: docs/validation/turbulent_channel.md, "the A/B screened at dr+ = 9" (the best
# setting at dr+ = 6: c4_h2.0).
# usage: jobs/ab24.sh OUTDIR START [T] [CANDIDATE...]   e.g. jobs/ab24.sh runs/ab24 a 3 reference
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 2 ] || { sed -n 2,22p "$0" >&2; exit 1; }
out=$1 start=$2 tend=${3:-3}
shift $(($# >= 3 ? 3 : 2))
scene=jobs/scenes/mfu180_dr6_dev.ini
case $start in
  a) from=(--set init.from=jobs/states/mfu180_dr6_t3.nc) ;;
  b) from=(--set init.from=jobs/states/mfu180_dr45_t10.nc) ;;
  w9a | w9b)
    state=jobs/states/mfu180w_dr6_t12.nc
    [ "$start" = w9b ] && state=jobs/states/mfu180w_dr6_t17.nc
    scene=jobs/scenes/mfu180w_dr6.ini
    from=(--set init.from=$state --set domain.dr=0.05 --set stats.window=0.25) ;;
  *) echo "error: START must be a, b, w9a or w9b (got '$start')" >&2; exit 1 ;;
esac
# shellcheck disable=SC2034  # read by name in campaign_candidates
declare -A sets=(
  [reference]=""
  [shift_taylor]="--set sph.shifting=fickian --set sph.shift_velocity=taylor"
  [xi_x0.5]="--set sph.xi=8.333333333333334"
  [morris]="--set sph.viscous=morris"
  [h_1.8]="--set sph.h_over_dr=1.8"
  [wall_analytic]="--set sph.wall_pressure_weight=analytic"
  [corrected]="--set sph.pressure_gradient=corrected --set sph.wall_collision=reflect"
  [xi_x0.25]="--set sph.xi=4.166666666666667"
  [h_2.0]="--set sph.h_over_dr=2.0"
  [c4]="--set sph.kernel=wendland_c4"
  [c4_h2.0]="--set sph.kernel=wendland_c4 --set sph.h_over_dr=2.0"
  [tvf]="--set sph.shifting=fickian --set sph.shift_velocity=conservative"
)
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(reference xi_x0.5 morris h_1.8 wall_analytic corrected)
cd "$root" || exit 1
. "$root/jobs/campaign_lib.sh"
campaign_candidates sets "$out" "$start" "$scene" "${names[@]}" -- "${from[@]}" \
  --set time.t_end="$tend" --set output.t_average_start=1 || exit 1
mapfile -t done_runs < <(campaign_finished "${campaign_runs[@]}")
[ ${#done_runs[@]} -gt 0 ] &&
  "$root/stats/python/chansph-stats" ab_table "${done_runs[@]}" --from 1 --markdown
