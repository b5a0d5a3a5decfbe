#!/usr/bin/env bash
# The LES against the quasi-DNS from a developed field (docs/validation/turbulent_channel.md,
# "The LES against the quasi-DNS from a developed field"): the
# quasi-DNS against the LES (Smagorinsky + Yoshizawa + van Driest, with and without the
# Reichardt wall law) at one resolution, each from the same developed field: the wide-box
# dr+ = 6 state jobs/states/mfu180w_dr6_t12.nc (2 x 2 x 1.4 delta, t = 12.1 of the converged
# run), interpolated onto the lattice of dr = 2 delta / NY by init.from. Each run is a batch job
# through jobs/chain.sh (start the script again to go on), averaged from t = 1 (the first
# turnover after the interpolation left out), the Reynolds-stress budgets on; then
# chansph-stats ab_table (peaks, numerical pair stress and budgets) and window_peaks against
# MKM 180.
# Candidates: qdns (no model), les (Smagorinsky + Yoshizawa + van Driest, laminar wall shear),
# les_wall (the same with the Reichardt wall law of the wall shear term).
# Cost on 2 idle cores: dr+ = 9 (NY = 40, 44 000 particles) about 2-3 minutes a turnover;
# dr+ = 6 (NY = 60, 148 680 particles) about 10 (the LES about 1.2 times the quasi-DNS).
# usage: jobs/les24.sh OUTDIR NY [T] [CANDIDATE...]   e.g. jobs/les24.sh runs/les24 40 4
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 2 ] || { sed -n 2,16p "$0" >&2; exit 1; }
out=$1 ny=$2 tend=${3:-4}
shift $(($# >= 3 ? 3 : 2))
case $ny in
  '' | *[!0-9]*) echo "error: NY must be a positive integer (got '$ny')" >&2; exit 1 ;;
esac
dr=$(python3 -c "print(repr(2.0 / $ny))")
# shellcheck disable=SC2034  # read by name in campaign_candidates
declare -A sets=(
  [qdns]=""
  [les]="--set les.model=smagorinsky"
  [les_wall]="--set les.model=smagorinsky --set wall.law=reichardt"
)
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(qdns les les_wall)
cd "$root" || exit 1
. "$root/jobs/campaign_lib.sh"
campaign_candidates sets "$out" "ny$ny" jobs/scenes/mfu180w_dr6.ini "${names[@]}" -- \
  --set domain.dr="$dr" --set init.from=jobs/states/mfu180w_dr6_t12.nc --set time.t_end="$tend" \
  --set output.t_average_start=1 --set stats.window=0.25 --set sph.wall_collision=reflect || exit 1
mapfile -t done_runs < <(campaign_finished "${campaign_runs[@]}")
[ ${#done_runs[@]} -gt 0 ] || exit 0
specs=()
for r in "${done_runs[@]}"; do specs+=("$(basename "$r")=$r@1:$tend"); done
"$root/stats/python/chansph-stats" ab_table "${done_runs[@]}" --from 1 --markdown
"$root/stats/python/chansph-stats" window_peaks --dns "$root/stats/dns/mkm1999/chan180.means" \
  "${specs[@]}"
