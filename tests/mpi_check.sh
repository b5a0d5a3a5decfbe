#!/usr/bin/env bash
# MPI decomposition checks (issue 6): results bitwise identical on 1, 2, 3 and 4 ranks.
# usage: mpi_check.sh CHANSPH SCENES RUNS CASE [PYTHON]
#   bitwise2d  2-D channel, 200 steps, every statistics engine, ranks 1-4
#   bitwise3d  3-D LES (Smagorinsky, Reichardt wall law), 200 steps, every engine, ranks 1-4,
#              and 2 ranks x 2 threads
#   synthetic  3-D quasi-DNS smoke box from the synthetic-eddy start-up (init.profile =
#              synthetic), 20 steps: 1 rank = 2 ranks = 1 rank x 2 threads = 2 ranks x 2 threads
#   migration  fast 2-D flow (Mach 0.5) on 3 and 4 ranks, ids checked after every step,
#              load checks every 7 steps (4 ranks start from a skewed partition); equals 1 rank
#   shift      fast 2-D flow with particle shifting (sph.shifting = fickian; velocities kept,
#              and carried by the conservative transport), 200 steps, ids
#              checked after every step: 2 ranks equal 1 rank
#   damper     fast 2-D flow with the acoustic damper and the delta-SPH diffusion, 200 steps,
#              ids checked after every step: 2 ranks equal 1 rank
#   substeps   the same with the volume diffusion in 3 sub-steps (delta = 0.6): 2 ranks equal 1
#   too_many   more ranks than the blocks allow: a message naming domain.lx and domain.lz, exit 1
#   resume_too_many  a 1-rank checkpoint resumed on more ranks than its slabs allow: the same
#                    message, exit 1, the checkpoints untouched
#   blocks     x-z blocks (run.ranks = Px,Pz) of 2-4 ranks, and 2 x 2 with 2 threads: equal 1 rank
#   blocks_many      the same (30 steps) on 6, 8, 9, 12 and 16 ranks (every factorisation that fits), 4 x 4
#                    with 2 threads
#   blocks_resume    a checkpoint of 2 x 2 resumed on 1, 3 x 1, 1 x 3 and 2 x 2: each equals the
#                    uninterrupted 1-rank run; on 3 ranks with its run.ranks: exit 1, nothing written
#   blocks_resume_many  the same from 4 x 2 to 1, 3 x 1, 2 x 3
#   blocks_kill      3 x 2 blocks, SIGKILL of one rank at random moments (checkpoints every 4
#                    steps), resumed each time: equals the uninterrupted 1-rank run
#   init_from  3-D LES started from another run's particles.nc (init.from), each rank reading
#              only its own part: at the same resolution (with init.density = rho0) and at
#              another (the velocity interpolated), on 1, 3 and 2 x 2 ranks: equal; a source with
#              a repeated id on 2 ranks: exit 1, the message once, nothing written
#   ckpt_resume      3-D LES: 100 steps on 2 ranks (parallel HDF5 checkpoint), resumed on 3 ranks
#                    and on 1 rank to step 200; both equal the uninterrupted 1-rank run
#   ckpt_write_fail  2 ranks under a file-size limit: exit 74, a message, previous checkpoint
#                    intact, no file left behind; resumes once the limit is lifted
#   ckpt_corrupt     checkpoints of a 2-rank run; the newest damaged (flipped bytes, truncated),
#                    resumed on 3 ranks: falls back to the previous one, same results
#   ckpt_bench       les395_small (41 250 particles): checkpoint size, write and read times on 1
#                    and 2 ranks (printed, not checked)
#   snapshots        3-D LES, 2 x 2 blocks, a snapshot every step (6): each rank writes its id
#                    block of the snapshots and of particles.nc (parallel HDF5, netCDF-4); their
#                    datasets equal the 1-rank run's (h5diff), the XDMF opens and its last
#                    snapshot equals particles.nc (snapshot_check.py --les; PYTHON, the 5th argument)
#   particles_write_fail  2 ranks: particles.nc rewritten by a resume of the finished run under a
#                    file-size limit between the sizes of stats.nc and particles.nc: exit 74, a
#                    message naming the file, the earlier particles.nc intact, no .tmp left;
#                    written once the limit is lifted
# Compared: the data of particles.nc and stats.nc (ncdump -p 17,17 after "data:"; the headers
# hold the scene text, which differs in the rank-related keys of some cases) and the content of
# the final checkpoint (h5diff: datasets and attributes; a checkpoint of one rank is built by
# the core driver, one of several ranks by the MPI-IO driver, so their bytes differ; files of
# 2, 3 or 4 ranks are byte-identical among themselves). The same holds for the snapshots
# (h5diff) and particles.nc (its data), which the ranks also write together, each its id block.
set -uo pipefail
# the runs compared here share one identity (issue 13: DIR/run_id, stored in every file)
export CHANSPH_RUN_ID=compare-test
chansph=$1 scenes=$2 runs=$3 case=$4 py=${5:-python3}
here=$(cd "$(dirname "$0")" && pwd)
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
  local exclude=()
  [ "${4:-}" = noscene ] && exclude=(--exclude-path /scene) # the runs' scene keys differ
  if ! h5diff "${exclude[@]}" "$1/$ck" "$2/$ck" > /dev/null; then
    echo "FAIL: $2/$ck differs from $1/$ck (h5diff ${exclude[*]})"
    fail=1
  else
    echo "ok: $2 equals $1 (particles.nc, stats.nc data; $ck content, h5diff ${exclude[*]})"
  fi
}

damage() { # damage HOW FILE: flip 4 bytes of /particles/x, or truncate
  if [ "$1" = truncated ]; then
    truncate -s 60000 "$2"
    return
  fi
  h5dump -d /particles/x -b LE -o x.bin "$2" > /dev/null && python3 -c "
b = bytearray(open('$2', 'rb').read()); x = open('x.bin', 'rb').read()
o = b.find(x[:64]); assert o > 0
for k in range(o + 200, o + 204): b[k] ^= 0x5a
open('$2', 'wb').write(b)" && rm x.bin
}

all_engines=(--set "correlations.y_plus=10,30" --set "lagrangian.y_plus=20" --set "quadrants.y_plus=10,30"
  --set "pdfs.y_plus=10,30" --set lagrangian.horizon=0.05 --set lagrangian.n_lags=10)

case $case in
  bitwise2d | bitwise3d)
    if [ "$case" = bitwise2d ]; then
      scene=$scenes/poiseuille2d.ini
      args=(--set domain.lx=2.0 --set time.t_end=1000 --set time.max_steps=200 --set init.noise=0.3
        --set init.modes=0.2 --set output.log_every=50 --set output.stats_every=5
        --set "correlations.y_plus=20,60" --set lagrangian.y_plus=40 --set lagrangian.horizon=0.2
        --set lagrangian.n_lags=10 --set stats.u_tau_ref=0.6 --set snapshots.every=0.5
        --set "quadrants.y_plus=20,60" --set "pdfs.y_plus=20,60")
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
    if [ "$case" = bitwise2d ]; then # particle snapshots, each rank writing its id block
      snaps=$(cd r1/snapshots 2> /dev/null && ls snap_*.h5)
      [ -n "$snaps" ] || { echo "FAIL: no snapshots written"; fail=1; }
      for np in 2 3 4; do # serial file of 1 rank, parallel HDF5 of several: the same content
        for f in $snaps; do
          h5diff "r1/snapshots/$f" "r$np/snapshots/$f" > /dev/null ||
            { echo "FAIL: r$np/snapshots/$f differs (h5diff)"; fail=1; }
          [ "$np" = 2 ] || cmp -s "r2/snapshots/$f" "r$np/snapshots/$f" ||
            { echo "FAIL: r$np/snapshots/$f differs in bytes from 2 ranks"; fail=1; }
        done
      done
      echo "snapshots $(echo $snaps): 1-4 ranks equal (h5diff), 2-4 ranks byte-identical"
    fi
    if [ "$case" = bitwise3d ]; then # hybrid: 2 ranks x 2 threads
      OMP_NUM_THREADS=2 mpi 2 run "$scene" --out r2x2 --overwrite "${args[@]}" > r2x2.txt 2>&1 ||
        { tail -20 r2x2.txt; echo "FAIL: 2 ranks x 2 threads"; exit 1; }
      compare r1 r2x2 200
    fi
    for np in 3 4; do # parallel HDF5 writes the same bytes on any number of ranks
      cmp -s r2/checkpoints/ckpt_0000000200.h5 r$np/checkpoints/ckpt_0000000200.h5 ||
        { echo "FAIL: the checkpoints of 2 and $np ranks differ in bytes"; fail=1; }
    done
    ;;
  synthetic)
    scene=$scenes/qdns180_smoke.ini
    args=(--set init.profile=synthetic --set init.streaks=0 --set init.modes=0 --set init.noise=0
      --set init.seed=11 --set time.max_steps=20 --set output.stats_every=5)
    for run in 1:1 2:1 1:2 2:2; do
      np=${run%:*} nt=${run#*:}
      OMP_NUM_THREADS=$nt mpi "$np" run "$scene" --out r${np}x$nt --overwrite "${args[@]}" \
        > r${np}x$nt.txt 2>&1 || { tail -20 r${np}x$nt.txt; echo "FAIL: $np ranks x $nt threads"; exit 1; }
    done
    grep -h "init: synthetic" r1x1.txt
    for r in r2x1 r1x2 r2x2; do compare r1x1 $r 20; done
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
  shift) # particle shifting (sph.shifting = fickian): migrating particles carry shift_dy; the
    # conservative momentum transport reads the ghosts' shifts (dd_refresh PR_SHIFT)
    scene=$scenes/poiseuille2d.ini
    for carry in keep conservative; do
      args=(--set domain.lx=2.0 --set time.t_end=1000 --set time.max_steps=200 --set init.profile=laminar
        --set drive.force=4 --set init.noise=0.5 --set run.check_ids=1 --set output.log_every=100
        --set sph.shifting=fickian --set sph.shift_velocity=$carry)
      for np in 1 2; do
        mpi "$np" run "$scene" --out r$np --overwrite "${args[@]}" > r$np.txt 2>&1 ||
          { tail -20 r$np.txt; echo "FAIL: $np ranks exited with $?"; exit 1; }
      done
      grep -h "^decomposition: 2 ranks" r2.txt
      echo "sph.shift_velocity = $carry:"
      compare r1 r2 200
    done
    ;;
  kgc | damper | substeps | les_profile) # terms that read state of other particles or steps, on 1 and 2 ranks:
    # kgc (sph.pressure_gradient = kgc): the force pass and the budget's conservative split read
    # the neighbours' correction matrices B at the ghosts (PR_KGC); statistics from the start,
    # so the budget parts are sampled too. damper (sph.acoustic_damper): migrating particles
    # carry their density rate (term_damper.h), which the pressure of the next step reads.
    # substeps (sph.diffusion_substeps = 3): each sub-step reads the ghosts' densities, refreshed
    # after the previous one (PR_DENSITY). les_profile (les.model = profile): the forces read the
    # neighbours' prescribed nu_r at the ghosts (PR_MODEL); the budget's model part from the start
    scene=$scenes/poiseuille2d.ini
    args=(--set domain.lx=2.0 --set time.t_end=1000 --set time.max_steps=200 --set init.profile=laminar
      --set drive.force=4 --set init.noise=0.5 --set run.check_ids=1 --set output.log_every=100)
    if [ "$case" = kgc ]; then
      args+=(--set output.t_average_start=0 --set sph.pressure_gradient=kgc)
    elif [ "$case" = les_profile ]; then
      args+=(--set output.t_average_start=0 --set sph.viscous=violeau --set les.model=profile
        --set les.profile="$scenes/nu_num_dr6c4d.txt")
    elif [ "$case" = substeps ]; then
      args+=(--set sph.diffusion=delta_sph --set sph.delta=0.6 --set sph.diffusion_substeps=3)
    else
      args+=(--set sph.acoustic_damper=0.1 --set sph.diffusion=delta_sph)
    fi
    for np in 1 2; do
      mpi "$np" run "$scene" --out r$np --overwrite "${args[@]}" > r$np.txt 2>&1 ||
        { tail -20 r$np.txt; echo "FAIL: $np ranks exited with $?"; exit 1; }
    done
    grep -h "^decomposition: 2 ranks" r2.txt
    compare r1 r2 200
    ;;
  too_many)
    if mpi 4 run "$scenes/les395_smoke.ini" --out r4 --overwrite > r4.txt 2>&1; then
      echo "FAIL: 4 ranks on 9 columns and 6 planes were accepted"
      exit 1
    fi
    grep -q "keys 'domain.lx', 'domain.lz': 9 cell columns and 6 planes .* at most 2 x 1 = 2 ranks; this run has 4" r4.txt ||
      { cat r4.txt; echo "FAIL: message"; exit 1; }
    [ ! -e r4/stats.nc ] || { echo "FAIL: output written"; exit 1; }
    echo "ok: $(grep -h "domain.lx" r4.txt | head -1)"
    ;;
  resume_too_many) # issue 13 point 6: an input error (exit 1), not an MPI_Abort (exit 2)
    "$chansph" run "$scenes/poiseuille2d.ini" --out r1 --max-steps 2 > r1.txt 2>&1
    [ $? -eq 75 ] || { cat r1.txt; echo "FAIL: the 1-rank run did not stop at --max-steps"; exit 1; }
    before=$(ls r1/checkpoints)
    mpi 4 resume r1 > r4.txt 2>&1
    rc=$?
    [ $rc -eq 1 ] || { cat r4.txt; echo "FAIL: resume on 4 ranks: exit $rc, expected 1"; exit 1; }
    grep -q "key 'domain.lx': 15 cell columns .* a slab needs at least 4, so at most 3 ranks; this run has 4" r4.txt ||
      { cat r4.txt; echo "FAIL: message"; exit 1; }
    [ "$before" = "$(ls r1/checkpoints)" ] || { echo "FAIL: the checkpoints changed"; exit 1; }
    echo "ok: $(grep -h "domain.lx" r4.txt | head -1)"
    ;;
  blocks | blocks_many) # x-z blocks: every Px x Pz equals 1 rank, bitwise (stats.nc, particles.nc, checkpoint)
    scene=$scenes/les395_smoke.ini
    if [ "$case" = blocks ]; then # 18 x 12 pencils
      lz=1.6 layouts="1,2 1,3 2,2" steps=60
    else # 18 x 16 pencils: 6, 8, 9, 12 and 16 ranks
      lz=2.2 layouts="3,2 2,3 4,2 2,4 3,3 4,3 3,4 4,4" steps=30
    fi
    args=(--set domain.lx=2.4 --set domain.lz=$lz --set time.max_steps=$steps --set output.stats_every=5
      "${all_engines[@]}")
    mpi 1 run "$scene" --out r1 --overwrite "${args[@]}" > r1.txt 2>&1 || { tail r1.txt; echo "FAIL: 1 rank"; exit 1; }
    for l in $layouts; do
      np=$((${l%,*} * ${l#*,}))
      mpi "$np" run "$scene" --out "r$l" --overwrite "${args[@]}" --set run.ranks=$l > "r$l.txt" 2>&1 ||
        { tail "r$l.txt"; echo "FAIL: $l"; exit 1; }
      grep -h "^decomposition: $np MPI ranks" "r$l/log.txt"
      compare r1 "r$l" $steps noscene
    done
    l=2,2 # hybrid: blocks with 2 threads each
    [ "$case" = blocks_many ] && l=4,4
    np=$((${l%,*} * ${l#*,}))
    OMP_NUM_THREADS=2 mpi "$np" run "$scene" --out "r${l}t2" --overwrite "${args[@]}" --set run.ranks=$l \
      > "r${l}t2.txt" 2>&1 || { tail "r${l}t2.txt"; echo "FAIL: $l x 2 threads"; exit 1; }
    compare r1 "r${l}t2" $steps noscene
    ;;
  init_from) # every rank reads its own part of the source: any decomposition starts the same
    scene=$scenes/les395_smoke.ini
    args=(--set domain.lx=2.4 --set domain.lz=1.6 --set output.stats_every=5 "${all_engines[@]}")
    mpi 1 run "$scene" --out src --overwrite "${args[@]}" --set time.max_steps=20 > src.txt 2>&1 ||
      { tail src.txt; echo "FAIL: source run"; exit 1; }
    cp src/particles.nc dup.nc && /usr/bin/python3 -c "
import h5py
with h5py.File('dup.nc', 'r+') as f:
    f['id'][5] = f['id'][6]" || { echo "FAIL: cannot edit the source"; exit 1; }
    for res in same other; do
      extra=(--set "init.from=$PWD/src/particles.nc" --set time.max_steps=20)
      if [ $res = same ]; then extra+=(--set init.density=rho0); else extra+=(--set domain.dr=0.08); fi
      for l in 1 3,1 2,2; do
        np=$((${l%,*} * ${l#*,}))
        ranks=(--set run.ranks=$l)
        [ "$l" = 1 ] && ranks=()
        mpi "$np" run "$scene" --out "r${res}_$l" --overwrite "${args[@]}" "${extra[@]}" "${ranks[@]}" \
          > "r${res}_$l.txt" 2>&1 || { tail "r${res}_$l.txt"; echo "FAIL: $res resolution on $l"; exit 1; }
        [ "$l" = 1 ] && grep -h "init: " "r${res}_$l.txt"
        [ "$l" = 1 ] || compare "r${res}_1" "r${res}_$l" 20 noscene
      done
    done
    mpi 2 run "$scene" --out rbad "${args[@]}" --set "init.from=$PWD/dup.nc" > rbad.txt 2>&1
    rc=$?
    [ $rc -eq 1 ] || { cat rbad.txt; echo "FAIL: a repeated id on 2 ranks: exit $rc, expected 1"; exit 1; }
    n=$(grep -c "dup.nc (init.from): particle id [0-9]* repeated" rbad.txt)
    [ "$n" = 1 ] || { cat rbad.txt; echo "FAIL: the message $n times, expected once"; exit 1; }
    [ -z "$(ls -A rbad 2> /dev/null)" ] || { ls rbad; echo "FAIL: rbad has content"; exit 1; }
    echo "ok: $(grep -h "repeated" rbad.txt)"
    ;;
  blocks_resume | blocks_resume_many) # a checkpoint of one decomposition resumed on others
    scene=$scenes/les395_smoke.ini
    args=(--set domain.lx=2.4 --set domain.lz=1.6 --set time.max_steps=80 --set output.stats_every=5
      "${all_engines[@]}")
    if [ "$case" = blocks_resume ]; then
      first=2,2 others="1 3,1 1,3"
    else
      first=4,2 others="1 3,1 2,3"
      args+=(--set domain.lz=2.2)
    fi
    mpi 1 run "$scene" --out r1 --overwrite "${args[@]}" > r1.txt 2>&1 || { echo "FAIL: 1 rank"; exit 1; }
    np=$((${first%,*} * ${first#*,}))
    mpi "$np" run "$scene" --out rf --overwrite "${args[@]}" --set run.ranks=$first --max-steps 40 > rf.txt 2>&1
    rc=$?
    [ $rc -eq 75 ] || { tail rf.txt; echo "FAIL: the $first job exited with $rc, not 75"; exit 1; }
    for l in $others; do
      cp -a rf "rf_$l"
      if [ "$l" = 1 ]; then
        mpi 1 resume "rf_$l" --set run.ranks= > "rf_$l.txt" 2>&1
      else
        mpi $((${l%,*} * ${l#*,})) resume "rf_$l" --set run.ranks=$l > "rf_$l.txt" 2>&1
      fi || { tail "rf_$l.txt"; echo "FAIL: resume of $first on $l"; exit 1; }
      grep -h "resume: from" "rf_$l/log.txt" | tail -1
      compare r1 "rf_$l" 80 noscene
    done
    # on the first layout again, without --set: the checkpoint's run.ranks
    cp -a rf rf_same
    mpi "$np" resume rf_same > rf_same.txt 2>&1 || { tail rf_same.txt; echo "FAIL: resume on $first"; exit 1; }
    compare r1 rf_same 80 noscene
    # a resume on a rank count that its run.ranks does not fit: exit 1, a message, nothing written
    cp -a rf rf_bad
    before=$(ls -l rf_bad/checkpoints)
    mpi 3 resume rf_bad > rf_bad.txt 2>&1
    rc=$?
    [ $rc -eq 1 ] || { cat rf_bad.txt; echo "FAIL: resume of $first on 3 ranks: exit $rc, expected 1"; exit 1; }
    grep -q "key 'run.ranks': Px x Pz differs from the ranks; this run has 3 MPI ranks" rf_bad.txt ||
      { cat rf_bad.txt; echo "FAIL: message"; exit 1; }
    [ "$before" = "$(ls -l rf_bad/checkpoints)" ] || { echo "FAIL: the checkpoints changed"; exit 1; }
    echo "ok: $(grep -h "run.ranks" rf_bad.txt | head -1)"
    ;;
  blocks_kill) # SIGKILL of a rank at random moments (checkpoints every 4 steps), resumed each time
    scene=$scenes/les395_smoke.ini
    args=(--set domain.lx=2.4 --set domain.lz=1.6 --set time.max_steps=120 --set output.stats_every=5
      --set checkpoint.every_steps=4 --set run.ranks=3,2 "${all_engines[@]}")
    mpi 1 run "$scene" --out r1 --overwrite "${args[@]}" --set run.ranks= > r1.txt 2>&1 ||
      { echo "FAIL: 1 rank"; exit 1; }
    RANDOM=7
    cmd=(run "$scene" --out rk --overwrite "${args[@]}")
    kills=0 in_write=0
    for k in 1 2 3 4 5 6; do
      mpi 6 "${cmd[@]}" > "rk$k.txt" 2>&1 &
      job=$!
      sleep "$(printf '%d.%02d' $((2 + RANDOM % 3)) $((RANDOM % 100)))"
      victim=$(pgrep -x chansph | shuf -n 1 --random-source=<(yes))
      if [ -n "$victim" ] && kill -KILL "$victim" 2> /dev/null; then
        kills=$((kills + 1))
        ls rk/checkpoints/*.tmp > /dev/null 2>&1 && in_write=$((in_write + 1))
      fi
      wait $job
      cmd=(resume rk)
    done
    mpi 6 resume rk > rk_end.txt 2>&1 || { tail rk_end.txt; echo "FAIL: the last resume"; exit 1; }
    echo "killed $kills times ($in_write with a checkpoint file being written)"
    compare r1 rk 120 noscene
    ;;
  ckpt_resume)
    scene=$scenes/les395_smoke.ini
    args=(--set domain.lx=2.4 --set time.max_steps=200 --set output.stats_every=5 "${all_engines[@]}")
    mpi 1 run "$scene" --out r1 --overwrite "${args[@]}" > r1.txt 2>&1 || { echo "FAIL: 1 rank"; exit 1; }
    mpi 2 run "$scene" --out r2 --overwrite "${args[@]}" --max-steps 100 > r2.txt 2>&1
    rc=$?
    [ $rc -eq 75 ] || { tail r2.txt; echo "FAIL: the 2-rank job exited with $rc, not 75"; exit 1; }
    grep -h "^checkpoint " r2/log.txt
    for np in 3 1; do
      cp -a r2 r2to$np
      mpi $np resume r2to$np > r2to$np.txt 2>&1 || { tail r2to$np.txt; echo "FAIL: resume on $np"; exit 1; }
      grep -h "resume: from" r2to$np/log.txt | tail -1
      compare r1 r2to$np 200
    done
    # the 3-rank continuation writes the same bytes as a 2-rank one would: all parallel files
    # of a state are identical; and the 2-rank checkpoint holds the 1-rank run's step 100
    mpi 1 run "$scene" --out r1half --overwrite "${args[@]}" --max-steps 100 > r1half.txt 2>&1
    ck=checkpoints/ckpt_0000000100.h5
    h5diff r1half/$ck r2/$ck > /dev/null || { echo "FAIL: $ck of 2 ranks differs from 1 rank"; fail=1; }
    ;;
  ckpt_write_fail)
    scene=$scenes/poiseuille2d.ini
    args=(--set domain.lx=2.0 --set time.t_end=1 --set output.t_average_start=0.5)
    mpi 2 run "$scene" --out d --overwrite "${args[@]}" --max-steps 20 > d1.txt 2>&1
    [ $? -eq 75 ] || { tail d1.txt; echo "FAIL: first job"; exit 1; }
    ck=d/checkpoints/ckpt_0000000020.h5
    cp "$ck" copy.h5
    size=$(stat -c %s "$ck")
    # a file-size limit below the checkpoint size (ulimit -f counts 1024-byte blocks in bash);
    # PMIX_MCA_gds=hash: PMIx keeps its shared-memory store under the limit
    out=$(ulimit -f $((size / 2048)) && PMIX_MCA_gds=hash timeout 120 mpirun --oversubscribe -np 2 \
      "$chansph" resume d --set checkpoint.every_steps=5 2>&1)
    rc=$?
    echo "$out" | grep -E "^error" | head -n 3
    [ $rc -eq 74 ] || { echo "FAIL: exit status $rc, expected 74"; fail=1; }
    echo "$out" | grep -Eq "error: cannot write checkpoint .*ckpt_0000000025.h5.tmp .*File too large" ||
      { echo "FAIL: no message naming the file and the cause"; fail=1; }
    echo "$out" | grep -q "stopped at step 25: cannot write a checkpoint (the previous ones are intact)" ||
      { echo "FAIL: no stop message"; fail=1; }
    cmp -s "$ck" copy.h5 || { echo "FAIL: the previous checkpoint changed"; fail=1; }
    [ -z "$(ls d/checkpoints | grep -v '^ckpt_0000000020.h5$')" ] ||
      { ls d/checkpoints; echo "FAIL: files left behind"; fail=1; }
    mpi 2 resume d > d2.txt 2>&1 || { tail d2.txt; echo "FAIL: resume after the limit is lifted"; fail=1; }
    ;;
  ckpt_corrupt)
    scene=$scenes/poiseuille2d.ini
    args=(--set domain.lx=2.0 --set time.t_end=1000 --set time.max_steps=120 --set init.noise=0.3
      --set output.t_average_start=0 --set checkpoint.every_steps=50 --set checkpoint.keep=10)
    mpi 2 run "$scene" --out base --overwrite "${args[@]}" > base.txt 2>&1 || { tail base.txt; echo "FAIL: base run"; exit 1; }
    ls base/checkpoints
    for how in flipped truncated; do
      rm -rf $how && cp -a base $how && rm -f $how/stats.nc $how/particles.nc
      damage $how $how/checkpoints/ckpt_0000000120.h5
      mpi 3 resume $how > $how.txt 2>&1 || { tail $how.txt; echo "FAIL: $how: resume on 3 ranks"; fail=1; continue; }
      grep -h "warning" $how.txt | head -n 2
      want="truncated file"
      [ $how = flipped ] && want="/particles/x .*data error detected by Fletcher32 checksum"
      grep -q "warning: .*ckpt_0000000120.h5: .*$want" $how.txt || { echo "FAIL: $how: message"; fail=1; }
      grep -q "resume: from .*ckpt_0000000100.h5" $how/log.txt || { echo "FAIL: $how: no fallback"; fail=1; }
      grep -q "resume: skipped .*ckpt_0000000120.h5 (renamed \*.skipped)" $how/log.txt ||
        { echo "FAIL: $how: not renamed"; fail=1; }
      [ -e $how/checkpoints/ckpt_0000000120.h5.skipped ] || { echo "FAIL: $how: no .skipped file"; fail=1; }
      compare base $how 120
    done
    ;;
  ckpt_bench)
    scene=$scenes/les395_small.ini
    for np in 1 2; do
      mpi $np run "$scene" --out b$np --overwrite --max-steps 4 --set checkpoint.every_steps=1 \
        --set checkpoint.keep=10 > b$np.txt 2>&1
      [ $? -eq 75 ] || { tail b$np.txt; echo "FAIL: $np ranks"; exit 1; }
      mpi $np resume b$np --max-steps 1 > b${np}r.txt 2>&1
      [ $? -eq 75 ] || { tail b${np}r.txt; echo "FAIL: resume on $np ranks"; exit 1; }
      echo "$np rank(s): $(grep -h "fluid +" b$np.txt | head -1)"
      grep -h "^checkpoint .*h5 (step [1-4]," b$np/log.txt | sed "s/^/  write: /"
      grep -h "^resume: from" b$np/log.txt | sed "s/^/  read:  /"
    done
    ;;
  snapshots) # each rank writes its id block of the snapshots and of particles.nc: no gather
    scene=$scenes/les395_smoke.ini
    args=(--set domain.lx=2.4 --set domain.lz=1.6 --set time.max_steps=6 --set output.stats_every=5
      --set snapshots.every=0.0001)
    mpi 1 run "$scene" --out r1 --overwrite "${args[@]}" > r1.txt 2>&1 || { tail r1.txt; echo "FAIL: 1 rank"; exit 1; }
    mpi 4 run "$scene" --out r2,2 --overwrite "${args[@]}" --set run.ranks=2,2 > r2,2.txt 2>&1 ||
      { tail r2,2.txt; echo "FAIL: 2 x 2 blocks"; exit 1; }
    snaps=$(cd r1/snapshots && ls snap_*.h5)
    [ "$(echo $snaps | wc -w)" = 6 ] || { echo "FAIL: snapshots of 1 rank: $snaps"; fail=1; }
    [ "$snaps" = "$(cd r2,2/snapshots && ls snap_*.h5)" ] || { echo "FAIL: other snapshot files"; fail=1; }
    for f in $snaps; do
      h5diff "r1/snapshots/$f" "r2,2/snapshots/$f" > /dev/null ||
        { echo "FAIL: r2,2/snapshots/$f differs from r1 (h5diff)"; fail=1; }
    done
    echo "ok: snapshots $(echo $snaps) of 2 x 2 blocks equal 1 rank (h5diff)"
    "$py" "$here/snapshot_check.py" "r2,2" --les || { echo "FAIL: snapshot_check.py r2,2"; fail=1; }
    compare r1 r2,2 6 noscene
    ;;
  particles_write_fail) # a resume of a finished run writes only stats.nc and particles.nc (the
    # final checkpoint exists, the final snapshot too: snapshots.every ends on the last step)
    scene=$scenes/poiseuille2d.ini
    args=(--set domain.lx=16 --set time.t_end=0.02 --set output.t_average_start=0 --set snapshots.every=0.02)
    mpi 2 run "$scene" --out d --overwrite "${args[@]}" > d1.txt 2>&1 || { tail d1.txt; echo "FAIL: first job"; exit 1; }
    cp d/particles.nc copy.nc
    psize=$(stat -c %s d/particles.nc) ssize=$(stat -c %s d/stats.nc)
    [ "$psize" -gt $((ssize * 3 / 2)) ] ||
      { echo "FAIL: particles.nc ($psize bytes) not well above stats.nc ($ssize): no limit between"; exit 1; }
    # a file-size limit between them (ulimit -f counts 1024-byte blocks in bash); PMIX_MCA_gds=hash:
    # PMIx keeps its shared-memory store under the limit
    out=$(ulimit -f $(((psize + ssize) / 2048)) && PMIX_MCA_gds=hash timeout 120 mpirun --oversubscribe \
      -np 2 "$chansph" resume d 2>&1)
    rc=$?
    echo "$out" | grep -E "^error" | head -n 3
    [ $rc -eq 74 ] || { echo "$out" | tail; echo "FAIL: exit status $rc, expected 74"; fail=1; }
    [ "$(echo "$out" | grep -c "^error")" = 1 ] || { echo "FAIL: not one error message"; fail=1; }
    echo "$out" | grep -Eq "^error: cannot write d/particles.nc.tmp [(]File too large.*an earlier d/particles.nc is kept" ||
      { echo "FAIL: no message naming the file and the cause"; fail=1; }
    cmp -s d/particles.nc copy.nc || { echo "FAIL: the earlier particles.nc changed"; fail=1; }
    [ ! -e d/particles.nc.tmp ] || { echo "FAIL: d/particles.nc.tmp left behind"; fail=1; }
    mpi 2 resume d > d2.txt 2>&1 || { tail d2.txt; echo "FAIL: resume after the limit is lifted"; fail=1; }
    [ "$(data d/particles.nc)" = "$(data copy.nc)" ] || { echo "FAIL: particles.nc rewritten differs"; fail=1; }
    ;;
  *)
    echo "unknown case $case"
    exit 2
    ;;
esac
[ $fail -eq 0 ] && echo "PASS: mpi $case"
exit $fail
