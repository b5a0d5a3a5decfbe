#!/usr/bin/env bash
# Start-up memory per rank (issue 40, point 4): each rank builds, reads (init.from) or resumes
# only its own block, so the memory a rank needs at start-up falls with the rank count. For each
# rank count, one step of SCENE started three ways: a fresh lattice (run), from the particles.nc
# of a one-rank run (init.from) and from that run's checkpoint (resume); printed: the log's line
# "memory: start-up peak resident ..." (mean and max over ranks of the peak resident memory once
# the particles are built and distributed, the part the start-up added, and that part per owned
# + ghost particle), and, where GNU time is installed, the largest peak of any rank over the
# whole one-step process (the only figure an older build without the log line gives).
# A rank count that a build refuses (its memory check) gives a row "refused" and its message.
# Memory, not time: oversubscribed runs on a small machine give the numbers of a cluster's ranks.
#
# usage: tests/bench_startup_memory.sh [CHANSPH] [--ranks "1 4 16"] [--csv FILE]
#                                      [--set key=value ...] [SCENE.ini]
# Default scene: jobs/scenes/mcf1.ini (1.63 M fluid particles; 16 ranks as 4 x 4 blocks).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
chansph=$here/build/chansph ranks="1 4 16" csv="" sets=() scene=$here/jobs/scenes/mcf1.ini
while [ $# -gt 0 ]; do
  case "$1" in
    --ranks) ranks=$2; shift 2 ;;
    --csv) csv=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    -h | --help) sed -n '2,14p' "$0"; exit 0 ;;
    *.ini) scene=$1; shift ;;
    *) chansph=$1; shift ;;
  esac
done
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1
work=$(mktemp -d /tmp/chansph_startmem.XXXXXX)
trap 'rm -rf "$work"' EXIT
gnutime=()
[ -x /usr/bin/time ] && gnutime=(/usr/bin/time -f "maxrss_kB %M" -a -o "$work/rss.txt")
sets+=(--set output.particles=1 --set snapshots.every=0)

# the source: one step on one rank (its particles.nc and its final checkpoint)
"$chansph" run "$scene" --out "$work/src" "${sets[@]}" --set time.max_steps=1 > "$work/src.txt" 2>&1 ||
  { tail "$work/src.txt"; echo "bench_startup_memory: the source run failed" >&2; exit 1; }

out=$work/mem.csv
echo "ranks,start,peak_MB_mean,peak_MB_max,startup_MB_mean,startup_MB_max,B_per_particle_mean,B_per_particle_max,process_peak_MB_max" > "$out"
for np in $ranks; do
  for start in run init_from resume; do
    d=$work/${start}_$np
    rm -f "$work/rss.txt"
    case $start in
      run) cmd=(run "$scene" --out "$d" "${sets[@]}" --set time.max_steps=1) ;;
      init_from) cmd=(run "$scene" --out "$d" "${sets[@]}" --set time.max_steps=1
                      --set "init.from=$work/src/particles.nc") ;;
      resume) cp -a "$work/src" "$d" && cmd=(resume "$d" --set time.max_steps=2) ;;
    esac
    if ! mpirun --oversubscribe -np "$np" "${gnutime[@]}" "$chansph" "${cmd[@]}" > "$d.txt" 2>&1; then
      # a refusal (e.g. the memory check of a build where every rank holds the whole lattice)
      # is a result: its message, and the next case
      echo "$start on $np ranks: $(grep -m1 -i "error" "$d.txt" || tail -1 "$d.txt")"
      echo "$np,$start,refused,,,,,,," >> "$out"
      continue
    fi
    line=$(grep -h "^memory: start-up peak" "$d.txt" | tail -1 || true)
    nums=$(echo "$line" | sed -E 's/[^0-9.]+/ /g' | awk '{print $1","$3","$4","$5","$6","$7}')
    [ -n "$line" ] || nums=",,,,,"
    proc=""
    [ -f "$work/rss.txt" ] && proc=$(awk '/maxrss_kB/ {if ($2 > m) m = $2} END {printf "%.1f", m / 1e3}' "$work/rss.txt")
    echo "$np,$start,$nums,$proc" >> "$out"
  done
done
column -ts, "$out"
[ -z "$csv" ] || cp "$out" "$csv"
