#!/usr/bin/env bash
# The halo's traffic per rank and step, slabs against x-z blocks, on one scene (docs/parallel.md,
# "Measured halo"): for each rank count, `chansph run SCENE` for a few steps as P x 1 slabs and
# as the automatic choice (the factorisation with the fewest ghosts), and any further Px x Pz
# blocks asked for; then the log's line "halo per rank and step" (bytes sent, messages, ghosts:
# mean and max over ranks) against the ghosts that docs/parallel_model.py predicts for the same
# decomposition. Counts, not times: they do not depend on the machine's load, so oversubscribed
# runs on a small machine give the numbers of a cluster's ranks.
#
# usage: tests/bench_halo.sh [CHANSPH] [--ranks "2 4 8 16"] [--layouts "2,2 4,4"] [--steps N]
#                            [--csv FILE] [--set key=value ...] [SCENE.ini]
#   --ranks    rank counts run as slabs (P,1) and as the automatic choice
#   --layouts  further Px,Pz blocks to run (run.ranks)
# Default scene: jobs/scenes/les395_small.ini with domain.lx = 6.25 and domain.lz = 3.125
# (76 x 38 cell pencils, 155 000 fluid particles: 16 slabs fit).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
chansph=$here/build/chansph ranks="2 4 8 16" layouts="" steps=5 csv="" sets=() scene=""
while [ $# -gt 0 ]; do
  case "$1" in
    --ranks) ranks=$2; shift 2 ;;
    --layouts) layouts=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    --csv) csv=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    -h | --help) sed -n '2,16p' "$0"; exit 0 ;;
    *.ini) scene=$1; shift ;;
    *) chansph=$1; shift ;;
  esac
done
if [ -z "$scene" ]; then
  scene=$here/jobs/scenes/les395_small.ini
  [ ${#sets[@]} -gt 0 ] || sets=(--set domain.lx=6.25 --set domain.lz=3.125)
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1
work=$(mktemp -d /tmp/chansph_halo.XXXXXX)
trap 'rm -rf "$work"' EXIT
out=$work/halo.csv
echo "ranks,layout,px,pz,kB_mean,kB_max,messages_mean,messages_max,ghosts_mean,ghosts_max,ghosts_per_owned,ncol,nplane" > "$out"
cases=()
for p in $ranks; do cases+=("$p,1" "$p:auto"); done
for l in $layouts; do cases+=("$l"); done
for c in "${cases[@]}"; do
  lay=()
  if [[ $c == *:auto ]]; then
    p=${c%:auto} kind=auto
  else
    p=$((${c%,*} * ${c#*,})) kind=${c/,/x}
    lay=(--set "run.ranks=$c")
  fi
  d=$work/r_${kind}_$p
  if ! mpirun -np "$p" --oversubscribe --bind-to none "$chansph" run "$scene" --out "$d" --overwrite \
    "${sets[@]}" "${lay[@]}" --set time.max_steps="$steps" > "$d.txt" 2>&1; then
    echo "bench_halo: $p ranks as $kind: $(grep -m1 -i "error" "$d.txt" || tail -1 "$d.txt")" >&2
    continue
  fi
  /usr/bin/python3 - "$d/log.txt" "$p" "$kind" >> "$out" << 'PY'
import re, sys
log, p, kind = sys.argv[1], sys.argv[2], sys.argv[3]
txt = open(log).read()
d = re.search(r"decomposition: \d+ ranks \((\d+) x (\d+) blocks\), (\d+) x (\d+) cell pencils", txt)
h = re.search(r"halo per rank and step .*?: ([\d.]+) kB, ([\d.]+) kB sent in ([\d.]+), ([\d.]+) "
              r"messages; (\d+), (\d+) ghosts; ghosts / owned ([\d.]+)", txt)
px, pz, ncol, nplane = d.groups()
print(",".join([p, kind, px, pz] + list(h.groups()) + [ncol, nplane]))
PY
done
[ -z "$csv" ] || cp "$out" "$csv"
/usr/bin/python3 "$here/docs/parallel_model.py" --measured "$out"
