#!/bin/bash
# Issue 44: old (a5e68b9) and new chansph builds on one 16-core node, interleaved:
# chansph bench mcf1.ini --steps 8 at 1, 2, 4, 8, 16 threads and 16x1, 8x2, 4x4, 2x8 ranks x
# threads; passes over all cases until the deadline (medians of up to 3 per build).
# usage: node16.sh BUNDLE_DIR OUT_DIR DEADLINE_S [quick]
# BUNDLE_DIR holds bin/chansph_old (a5e68b9) and bin/chansph_new (generic Release builds), the
# shared libraries they need (lib/; glibc in glibc/, used only where the system's is older),
# Open MPI 4.1.4's orterun, orted, plugins (ompi/lib/openmpi3), help files and parameters
# (ompi/share, ompi/etc), PMIx's plugins (pmix/) and mcf1.ini: the node had no MPI of its own.
# Environment: CASES ("RANKS:THREADS ..."), REPS (passes), SANITY (builds of the 2-rank check).
# Run 1 (docs/perf/node16_run1.log): node16.sh /tmp/b $OUT 450; run 2 (node16_run2.log, with the
# width-1 permute loops and the sort's counts allocated with the grid):
# SANITY= CASES="1:1 1:16 16:1 1:2" REPS=3 node16.sh /tmp/b $OUT 195.
B=$1 OUT=$2 DEADLINE=${3:-470} MODE=${4:-full}
T0=$(date +%s)
elapsed() { echo $(( $(date +%s) - T0 )); }
export OPAL_PREFIX=$B/ompi OPAL_PKGDATADIR=$B/ompi/share/openmpi OPAL_PKGLIBDIR=$B/ompi/lib/openmpi3
export OPAL_SYSCONFDIR=$B/ompi/etc OPAL_BINDIR=$B/bin OPAL_LIBDIR=$B/lib
export OMPI_MCA_mca_base_component_path=$B/ompi/lib/openmpi3 OMPI_MCA_mca_base_component_show_load_errors=0
export PMIX_MCA_mca_base_component_path=$B/pmix PMIX_MCA_mca_base_component_show_load_errors=0
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl=self,vader OMPI_MCA_pml=ob1 OMPI_MCA_btl_vader_single_copy_mechanism=none
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_hwloc_base_binding_policy=none
export TMPDIR=/tmp OMPI_MCA_plm=isolated
if ! touch /dev/shm/.w 2>/dev/null; then export OMPI_MCA_btl_vader_backing_directory=/tmp; fi
rm -f /dev/shm/.w
# the bundle's glibc (2.36) only if the system's is older: then every binary goes through its loader
sysglibc=$(getconf GNU_LIBC_VERSION 2>/dev/null | awk '{print $2}')
if [ -z "${FORCE_LOADER:-}" ] && [ -n "$sysglibc" ] && [ "$(printf '%s\n2.36\n' "$sysglibc" | sort -V | head -1)" = 2.36 ]; then
  export LD_LIBRARY_PATH=$B/lib; PRE=()
else
  PRE=("$B/glibc/ld-linux-x86-64.so.2" --library-path "$B/lib:$B/glibc")
fi
echo "host: $(nproc) cpus, glibc ${sysglibc:-?}, loader ${PRE[0]:-system}; $(grep -m1 'model name' /proc/cpuinfo)"
MPIRUN=("${PRE[@]}" "$B/bin/orterun" --allow-run-as-root --oversubscribe --bind-to none)
SOLO=0 # 1: mpirun failed; one rank runs without it (threads only)
run() { # build ranks threads rep
  local b=$1 r=$2 t=$3 rep=$4 t1 t2 log=$OUT/raw.log
  t1=$(date +%s.%N)
  { echo "=== build=$b ranks=$r threads=$t rep=$rep start=$(elapsed)s"
    if [ $SOLO = 1 ]; then
      OMP_NUM_THREADS=$t OMPI_MCA_ess_singleton_isolated=1 timeout 150 \
        "${PRE[@]}" "$B/bin/chansph_$b" bench "$B/mcf1.ini" --steps 8 2>&1
    else
      OMP_NUM_THREADS=$t timeout 150 "${MPIRUN[@]}" -np "$r" -x OMP_NUM_THREADS="$t" \
        "${PRE[@]}" "$B/bin/chansph_$b" bench "$B/mcf1.ini" --steps 8 2>&1
    fi
    echo "=== rc=$? wall=$(awk -v a="$t1" -v b="$(date +%s.%N)" 'BEGIN{print b-a}')"; } > "$OUT/one.log" 2>&1
  cat "$OUT/one.log" >> "$log"
  printf '%s %2dx%-2d rep %d: %s | %s\n' "$b" "$r" "$t" "$rep" \
    "$(grep -o '[0-9.]* ms/step' "$OUT/one.log")" "$(grep 'particle-steps/s' "$OUT/one.log")"
}
# sanity: 2 ranks of the small built-in case, both builds
for b in ${SANITY-old new}; do
  OMP_NUM_THREADS=1 timeout 60 "${MPIRUN[@]}" -np 2 -x OMP_NUM_THREADS=1 "${PRE[@]}" \
    "$B/bin/chansph_$b" bench --steps 2 > "$OUT/sanity_$b.log" 2>&1
  rc=$?; echo "sanity $b: rc=$rc $(grep -o '[0-9.]* ms/step' "$OUT/sanity_$b.log")"
  [ $rc -eq 0 ] || { tail -30 "$OUT/sanity_$b.log"; SOLO=1; }
done
if [ $SOLO = 1 ]; then # without mpirun: one rank, threads only
  OMP_NUM_THREADS=1 OMPI_MCA_ess_singleton_isolated=1 timeout 60 "${PRE[@]}" "$B/bin/chansph_new" \
    bench --steps 2 > "$OUT/sanity_solo.log" 2>&1 || { tail -20 "$OUT/sanity_solo.log"; exit 3; }
  echo "mpirun failed: threads only, without it"
fi
[ "$MODE" = quick ] && exit 0
cases=${CASES:-"1:1 1:16 16:1 2:8 4:4 8:2 1:8 1:4 1:2"}
declare -A dur
for rep in $(seq 1 "${REPS:-3}"); do
  for c in $cases; do
    r=${c%%:*} t=${c##*:}
    [ $SOLO = 1 ] && [ "$r" != 1 ] && continue
    need=${dur[$c]:-0}
    if [ $(( $(elapsed) + need )) -gt "$DEADLINE" ]; then echo "skip $c rep $rep (time)"; continue; fi
    s=$(date +%s)
    run old "$r" "$t" "$rep"; run new "$r" "$t" "$rep"
    dur[$c]=$(( $(date +%s) - s ))
  done
done
echo "done in $(elapsed) s"
