#!/usr/bin/env bash
# MPI decomposition checks (issue 6): results bitwise identical on 1, 2, 3 and 4 ranks.
# usage: mpi_check.sh CHANSPH SCENES RUNS CASE
#   bitwise2d  2-D channel, 200 steps, every statistics engine, ranks 1-4
#   bitwise3d  3-D LES (Smagorinsky, Reichardt wall law), 200 steps, every engine, ranks 1-4,
#              and 2 ranks x 2 threads
#   resume     3-D LES: 100 steps on 2 ranks, resumed on 3 to step 200; equals the 1-rank run
#   migration  fast 2-D flow (Mach 0.5) on 3 and 4 ranks, ids checked after every step,
#              load checks every 7 steps (4 ranks start from a skewed partition); equals 1 rank
#   too_many   more ranks than the slabs allow: a message naming domain.lx, exit 1
# Compared: the data of particles.nc and stats.nc (ncdump -p 17,17 after "data:"; the headers
# hold the scene text, which differs in the rank-related keys of some cases) and the final
# checkpoint byte for byte (cmp).
set -uo pipefail
chansph=$1 scenes=$2 runs=$3 case=$4
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1
work=$runs/mpi_$case
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail=0

mpi() { # mpi NP ARGS...: run chansph on NP ranks, output in NAME.txt (NAME = --out value)
  local np=$1
  shift
  mpirun --oversubscribe -np "$np" "$chansph" "$@"
}

data() { ncdump -p 17,17 "$1" | sed -n '/^data:/,$p' | md5sum | cut -c1-16; }

compare() { # compare REF RUN STEP [noscene]: noscene = the runs' scene keys differ
  local a b
  for f in particles.nc stats.nc; do
    a=$(data "$1/$f") b=$(data "$2/$f")
    if [ "$a" != "$b" ]; then
      echo "FAIL: $2/$f differs from $1/$f"
      fail=1
    fi
  done
  local ck
  ck=$(printf "checkpoints/ckpt_%010d.h5" "$3")
  if [ "${4:-}" = noscene ]; then
    if ! h5diff --exclude-path /scene "$1/$ck" "$2/$ck" > /dev/null; then
      echo "FAIL: $2/$ck differs from $1/$ck (beyond the scene text)"
      fail=1
    else
      echo "ok: $2 equals $1 (particles.nc, stats.nc data; $ck equal but for the scene text)"
    fi
  elif ! cmp -s "$1/$ck" "$2/$ck"; then
    echo "FAIL: $2/$ck differs from $1/$ck"
    fail=1
  else
    echo "ok: $2 equals $1 (particles.nc, stats.nc data; $ck byte-identical)"
  fi
}

all_engines=(--set "correlations.y_plus=10,30" --set "lagrangian.y_plus=20"
  --set lagrangian.horizon=0.05 --set lagrangian.n_lags=10)

case $case in
  bitwise2d | bitwise3d)
    if [ "$case" = bitwise2d ]; then
      scene=$scenes/poiseuille2d.ini
      args=(--set domain.lx=2.0 --set time.t_end=1000 --set time.max_steps=200 --set init.noise=0.3
        --set init.modes=0.2 --set output.log_every=50 --set output.stats_every=5
        --set "correlations.y_plus=20,60" --set lagrangian.y_plus=40 --set lagrangian.horizon=0.2
        --set lagrangian.n_lags=10 --set stats.u_tau_ref=0.6 --set snapshots.every=0.5)
    else
      scene=$scenes/les395_smoke.ini
      args=(--set domain.lx=2.4 --set time.max_steps=200 --set output.stats_every=5 "${all_engines[@]}")
    fi
    for np in 1 2 3 4; do
      mpi "$np" run "$scene" --out r$np --overwrite "${args[@]}" > r$np.txt 2>&1 ||
        { tail -20 r$np.txt; echo "FAIL: $np ranks exited with $?"; exit 1; }
      grep -h "^decomposition" r$np.txt
    done
    for np in 2 3 4; do compare r1 r$np 200; done
    if [ "$case" = bitwise2d ]; then # particle snapshots, gathered by id on rank 0
      snaps=$(cd r1/snapshots 2> /dev/null && ls snap_*.h5)
      [ -n "$snaps" ] || { echo "FAIL: no snapshots written"; fail=1; }
      for np in 2 3 4; do
        for f in $snaps; do
          cmp -s "r1/snapshots/$f" "r$np/snapshots/$f" ||
            { echo "FAIL: r$np/snapshots/$f differs"; fail=1; }
        done
      done
      echo "snapshots $(echo $snaps) byte-identical on 1-4 ranks"
    fi
    if [ "$case" = bitwise3d ]; then # hybrid: 2 ranks x 2 threads
      OMP_NUM_THREADS=2 mpi 2 run "$scene" --out r2x2 --overwrite "${args[@]}" > r2x2.txt 2>&1 ||
        { tail -20 r2x2.txt; echo "FAIL: 2 ranks x 2 threads"; exit 1; }
      compare r1 r2x2 200
    fi
    ;;
  resume)
    scene=$scenes/les395_smoke.ini
    args=(--set domain.lx=2.4 --set time.max_steps=200 --set output.stats_every=5 "${all_engines[@]}")
    mpi 1 run "$scene" --out r1 --overwrite "${args[@]}" > r1.txt 2>&1 || { echo "FAIL: 1 rank"; exit 1; }
    mpi 2 run "$scene" --out r23 --overwrite "${args[@]}" --max-steps 100 > r23a.txt 2>&1
    rc=$?
    [ $rc -eq 75 ] || { tail r23a.txt; echo "FAIL: the 2-rank job exited with $rc, not 75"; exit 1; }
    mpi 3 resume r23 > r23b.txt 2>&1 || { tail r23b.txt; echo "FAIL: resume on 3 ranks"; exit 1; }
    grep -h "resumed at step\|^decomposition" r23b.txt
    compare r1 r23 200
    ;;
  migration)
    scene=$scenes/poiseuille2d.ini
    args=(--set domain.lx=2.0 --set time.t_end=1000 --set time.max_steps=300 --set init.profile=laminar
      --set drive.force=4 --set init.noise=0.5 --set run.check_ids=1 --set run.balance_every=7
      --set run.balance_threshold=0 --set output.log_every=100)
    for np in 1 3 4; do
      part=()
      [ "$np" = 4 ] && part=(--set run.partition=4,4,4,18) # skewed: the balancer must fix it
      mpi "$np" run "$scene" --out r$np --overwrite "${args[@]}" "${part[@]}" > r$np.txt 2>&1 ||
        { tail -20 r$np.txt; echo "FAIL: $np ranks exited with $?"; exit 1; }
    done
    for np in 3 4; do
      line=$(grep -h "^decomposition: $np ranks" r$np.txt)
      echo "$line"
      migrated=$(echo "$line" | sed -n 's/.* \([0-9]*\) particles migrated.*/\1/p')
      reparts=$(echo "$line" | sed -n 's/.*; \([0-9]*\) re-partitions.*/\1/p')
      # 30 columns: 3 ranks are balanced by the even split; 4 ranks start from 4,4,4,18
      need=$([ "$np" = 4 ] && echo 1 || echo 0)
      if [ -z "$migrated" ] || [ "$migrated" -lt 300 ] || [ -z "$reparts" ] || [ "$reparts" -lt "$need" ]; then
        echo "FAIL: expected a migration per step on average and $need+ re-partitions ($line)"
        fail=1
      fi
      compare r1 r$np 300 "$([ "$np" = 4 ] && echo noscene)"
    done
    echo "ids of all particles checked after each of the 300 steps (run.check_ids = 1)"
    ;;
  too_many)
    if mpi 4 run "$scenes/les395_smoke.ini" --out r4 --overwrite > r4.txt 2>&1; then
      echo "FAIL: 4 ranks on 9 columns were accepted"
      exit 1
    fi
    grep -q "key 'domain.lx': lx = 1.2 gives 9 cell columns .* 4 MPI ranks need at least 16 .* at most 2 ranks" r4.txt ||
      { cat r4.txt; echo "FAIL: message"; exit 1; }
    [ ! -e r4/stats.nc ] || { echo "FAIL: output written"; exit 1; }
    echo "ok: $(grep -h "domain.lx" r4.txt | head -1)"
    ;;
  *)
    echo "unknown case $case"
    exit 2
    ;;
esac
[ $fail -eq 0 ] && echo "PASS: mpi $case"
exit $fail
