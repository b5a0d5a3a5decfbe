#!/usr/bin/env bash
# The scheme A/B (docs/validation/scheme_ab.md): candidate numerical settings against the
# reference in the wide box at dr+ = 6 with Wendland C4, h = 2 dr (jobs/scenes/mfu180w_dr6_c4_ab.ini,
# 148 680 particles), each run from a developed state of the converged run for T turnovers
# (default 1) with the momentum and Reynolds-stress budgets every 10 steps and windows of 0.1,
# then the scored table (chansph-stats ab_score: redistributed fraction, pressure noise against
# the viscous term, the vv viscous term, the numerical pair stress share, the rms peaks, cost;
# each with its standard error). Two start states (two "seeds"), 7.5 turnovers apart:
#   s16   jobs/states/mfu180w_dr6c4_t16.nc   (t = 16 of the converged C4 run)
#   s8.5  jobs/states/mfu180w_dr6c4_t8.5.nc  (t = 8.5 of the same run)
#   d5    jobs/states/mfu180w_dr6c4d_s3_t5.nc (the delta-SPH run's third segment at its end:
#         the start of the LES against the quasi-DNS on that scheme, *_les and *_dr9)
#   w45   jobs/states/mfu180w_dr45c4d_s3_t1.nc (the dr+ = 4.5 run's third segment at t = 1:
#         the start of *_dr4, the finest point of the resolution series)
# Candidates *_dr9 run at dr+ = 9 (domain.dr = delta/20, 44 000 particles, the start state
# interpolated onto the coarser lattice), *_dr7.2 at dr+ = 7.2 (delta/25, 87 500 particles)
# and *_dr4 at dr+ = 4 (delta/45, 504 630 particles, from w45), and average from t = 1 on:
# give T = 3 or more.
# Each run is a batch job through jobs/chain.sh (checkpoints; start the script again to go on),
# about 15 minutes a turnover with 2 threads on an idle 2-core machine.
# usage: jobs/ab39.sh OUTDIR START [T] [CANDIDATE...]   e.g. jobs/ab39.sh runs/ab39 s16 1 damper_0.1
# The table alone, for runs already made: stats/python/chansph-stats ab_score OUTDIR/*_s16
#   --csv OUTDIR/ab_score.csv --markdown
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 2 ] || { sed -n 2,23p "$0" >&2; exit 1; }
out=$1 start=$2 tend=${3:-1}
shift $(($# >= 3 ? 3 : 2))
scene=jobs/scenes/mfu180w_dr6_c4_ab.ini
case $start in
  s16) state=$root/jobs/states/mfu180w_dr6c4_t16.nc ;;
  s8.5) state=$root/jobs/states/mfu180w_dr6c4_t8.5.nc ;;
  d5) state=$root/jobs/states/mfu180w_dr6c4d_s3_t5.nc ;;
  w45) state=$root/jobs/states/mfu180w_dr45c4d_s3_t1.nc ;;
  *) echo "error: START must be s16, s8.5, d5 or w45 (got '$start')" >&2; exit 1 ;;
esac
# shellcheck disable=SC2034  # read by name in campaign_candidates
declare -A sets=(
  [reference]=""
  [damper_0.05]="--set sph.acoustic_damper=0.05"
  [damper_0.1]="--set sph.acoustic_damper=0.1"
  [damper_0.15]="--set sph.acoustic_damper=0.15"
  [damper_0.3]="--set sph.acoustic_damper=0.3"
  [delta_0.1]="--set sph.diffusion=delta_sph --set sph.delta=0.1"
  [delta_0.2]="--set sph.diffusion=delta_sph --set sph.delta=0.2"
  [delta_0.3]="--set sph.diffusion=delta_sph --set sph.delta=0.3"
  [delta_0.4]="--set sph.diffusion=delta_sph --set sph.delta=0.4"
  [delta_0.4_sub2]="--set sph.diffusion=delta_sph --set sph.delta=0.4 --set sph.diffusion_substeps=2"
  [delta_0.8_sub4]="--set sph.diffusion=delta_sph --set sph.delta=0.8 --set sph.diffusion_substeps=4"
  [damper_0.1_delta_0.1]="--set sph.acoustic_damper=0.1 --set sph.diffusion=delta_sph --set sph.delta=0.1"
  [morris]="--set sph.viscous=morris"
  [lapnorm_trace]="--set sph.laplacian_norm=trace"
  [lapnorm_none]="--set sph.laplacian_norm=none"
  [rho0]="--set init.density=rho0"
  [delta_0.1_rho0]="--set sph.diffusion=delta_sph --set sph.delta=0.1 --set init.density=rho0"
  [shift_cons_0.005]="--set sph.shifting=fickian --set sph.shift_velocity=conservative --set sph.shift_coefficient=0.005"
  [shift_taylor_0.005]="--set sph.shifting=fickian --set sph.shift_velocity=taylor --set sph.shift_coefficient=0.005"
  [delta_0.1_shift_cons_0.005]="--set sph.diffusion=delta_sph --set sph.delta=0.1 --set sph.shifting=fickian --set sph.shift_velocity=conservative --set sph.shift_coefficient=0.005"
  [delta_0.2_morris]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set sph.viscous=morris"
  [delta_0.2_rho0]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set init.density=rho0"
  [delta_0.2_kgc]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set sph.pressure_gradient=kgc"
  [delta_0.2_shift_cons_0.02]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set sph.shifting=fickian --set sph.shift_velocity=conservative --set sph.shift_coefficient=0.02"
  [delta_0.2_les]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set les.model=smagorinsky"
  [delta_0.2_dr9]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set domain.dr=0.05 --set output.t_average_start=1"
  [delta_0.2_dr7.2]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set domain.dr=0.04 --set output.t_average_start=1"
  [delta_0.2_dr4]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set domain.dr=0.022222222222222223 --set output.t_average_start=1"
  [delta_0.2_les_dr9]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set les.model=smagorinsky --set domain.dr=0.05 --set output.t_average_start=1"
  [delta_0.2_c130]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set fluid.c0=130"
  [delta_0.2_shift_cons_0.05]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set sph.shifting=fickian --set sph.shift_velocity=conservative --set sph.shift_coefficient=0.05"
  [delta_0.2_pbneg]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set fluid.p_background=-2.8e-4"
  [delta_0.2_h1.5]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set sph.h_over_dr=1.5"
  [delta_0.2_h2.5]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set sph.h_over_dr=2.5"
  [delta_0.2_nu0.6]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set fluid.nu=0.003333333333333333"
  [delta_0.2_nuprof]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set les.model=profile --set les.profile=$root/jobs/scenes/nu_num_dr6c4d.txt"
  [delta_0.2_nu0.6_flux]="--set sph.diffusion=delta_sph --set sph.delta=0.2 --set fluid.nu=0.003333333333333333 --set drive.mode=flux --set drive.u_bulk=14.5824 --set stats.u_tau_ref=1"
)
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(reference damper_0.1 delta_0.1)
cd "$root" || exit 1
. "$root/jobs/campaign_lib.sh"
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}
campaign_candidates sets "$out" "$start" "$scene" "${names[@]}" -- --set init.from="$state" --set time.t_end="$tend" || exit 1
mapfile -t done_runs < <(campaign_finished "${campaign_runs[@]}")
[ ${#done_runs[@]} -gt 0 ] &&
  "$root/stats/python/chansph-stats" ab_score "${done_runs[@]}" --csv "$out/ab_score_$start.csv" --markdown
