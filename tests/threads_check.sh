#!/usr/bin/env bash
# Bitwise reproducibility: the same scene with OMP_NUM_THREADS=1 and 2 gives identical
# stats.nc and particles.nc data (compared through ncdump with 17 significant digits), with
# every statistics engine on (Eulerian, correlations and spectra, Lagrangian); the LES smoke
# scene covers the model terms (wall law, strain, eddy viscosity, k_r).
set -eu
# the runs compared here share one identity (issue 13: DIR/run_id, stored in every file)
export CHANSPH_RUN_ID=compare-test
# usage: threads_check.sh CHANSPH SCENES RUNS [TAG --set k=v ...]: with a TAG, the 2-D and 3-D
# Poiseuille scenes only, with the extra keys (e.g. particle shifting)
chansph=$1 scenes=$2 runs=$3
shift 3
tag=${1:-} scenes_list="poiseuille2d poiseuille3d poiseuille2d_flux les395_smoke"
if [ -n "$tag" ]; then shift && scenes_list="poiseuille2d poiseuille3d"; fi
status=0
for scene in $scenes_list; do
  for t in 1 2; do
    OMP_NUM_THREADS=$t "$chansph" run "$scenes/$scene.ini" --out "$runs/threads${tag}_${scene}_$t" \
      --overwrite --set time.t_end=1.0 --set output.t_average_start=0.5 --set stats.window=0.1 \
      --set stats.u_tau_ref=0.6 --set correlations.y_plus=1,2 --set lagrangian.y_plus=1,2 \
      --set quadrants.y_plus=1,2 --set pdfs.y_plus=1,2 \
      --set lagrangian.horizon=0.2 --set lagrangian.release_every=0.1 \
      --set lagrangian.n_lags=10 --set lagrangian.pdf_x=0.01 "$@" > /dev/null
  done
  for f in stats.nc particles.nc; do
    if diff <("$(dirname "$0")/nc_content.sh" "$runs/threads${tag}_${scene}_1/$f") \
            <("$(dirname "$0")/nc_content.sh" "$runs/threads${tag}_${scene}_2/$f") > /dev/null; then
      echo "$scene $f: identical for 1 and 2 threads"
    else
      echo "$scene $f: DIFFERENT for 1 and 2 threads"; status=1
    fi
  done
done
exit $status
