#!/usr/bin/env bash
# The cost of the LES step against the quasi-DNS step (issue 11, acceptance 2), measured
# directly: alternated pairs of `chansph bench SCENE --steps S` with the scene's model and with
# `--set les.model=none`, for one or more builds in turn within each rep, so that the
# machine's changes of speed hit all runs of a rep alike. Run it on an idle machine.
#
# usage: tests/bench_les_ratio.sh [--reps N] [--steps S] [--scene FILE] [LABEL=CHANSPH ...]
#   --reps N     pairs per build (default 15)
#   --steps S    timed steps per bench run (default 40)
#   --scene F    the LES scene (default jobs/scenes/les395_small.ini)
#   LABEL=PATH   builds to compare (default: this tree's build/chansph, labelled "tree")
# Threads: OMP_NUM_THREADS (default 2).
#
# Prints per build: the median ms/step of the LES and of the quasi-DNS runs, the ratio of the
# medians, the median and quartiles of the paired ratios (LES / quasi-DNS of the same rep), and
# the LES's extra force-phase time in units of each run's own neighbour phase (the same code
# with and without the model: the number least moved by the machine's noise).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
reps=15 steps=40 scene=$here/jobs/scenes/les395_small.ini builds=()
while [ $# -gt 0 ]; do
  case $1 in
    --reps) reps=$2 && shift 2 ;;
    --steps) steps=$2 && shift 2 ;;
    --scene) scene=$2 && shift 2 ;;
    *=*) builds+=("$1") && shift ;;
    *) echo "bench_les_ratio: unknown argument '$1' (see the header of $0)" >&2 && exit 1 ;;
  esac
done
[ ${#builds[@]} -gt 0 ] || builds=("tree=$here/build/chansph")
for lb in "${builds[@]}"; do
  [ -x "${lb#*=}" ] || { echo "bench_les_ratio: ${lb#*=} is not an executable" >&2 && exit 1; }
done
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}
out=$(mktemp /tmp/bench_les_ratio.XXXXXX)
trap 'rm -f "$out"' EXIT
for ((r = 1; r <= reps; r++)); do
  for lb in "${builds[@]}"; do
    for model in scene none; do
      set_args=()
      [ $model = none ] && set_args=(--set les.model=none)
      "${lb#*=}" bench "$scene" --steps "$steps" "${set_args[@]}" 2>&1 |
        awk -v l="${lb%%=*}" -v m=$model -v r=$r '
          /^forces /{f=$2} /^neighbours /{nb=$2}
          /ms\/step/{for (i = 1; i <= NF; i++) if ($i == "ms/step)") ms = $(i - 1)}
          END{gsub(/\(/, "", ms); if (ms == "" || f == "" || nb == "") exit 1; print l, m, r, nb, f, ms}' \
          >> "$out" || { echo "bench_les_ratio: a bench run of ${lb#*=} failed" >&2 && exit 1; }
    done
  done
  echo "bench_les_ratio: rep $r of $reps done" >&2
done
/usr/bin/python3 - "$out" "$reps" "$steps" "$OMP_NUM_THREADS" <<'PY'
import collections, statistics as st, sys
runs = collections.defaultdict(dict)
for line in open(sys.argv[1]):
    label, model, rep, nb, forces, ms = line.split()
    runs[label][(rep, model)] = (float(nb), float(forces), float(ms))
print(f"LES / quasi-DNS, {sys.argv[2]} alternated pairs of {sys.argv[3]} steps, {sys.argv[4]} threads")
print("build      LES ms/step  QDNS ms/step  ratio of medians  paired ratio: median (quartiles; range)  LES extra forces / neighbours")
for label, d in runs.items():
    reps = sorted({k[0] for k in d})
    les = [d[(r, "scene")] for r in reps]
    qd = [d[(r, "none")] for r in reps]
    pr = sorted(a[2] / b[2] for a, b in zip(les, qd))
    q = st.quantiles(pr, n=4) if len(pr) > 1 else [pr[0]] * 3
    extra = st.median(a[1] / a[0] for a in les) - st.median(b[1] / b[0] for b in qd)
    ml, mq = st.median(a[2] for a in les), st.median(b[2] for b in qd)
    print(f"{label:10s} {ml:11.2f}  {mq:12.2f}  {ml / mq:16.3f}  {q[1]:.3f} ({q[0]:.3f}-{q[2]:.3f}; "
          f"{pr[0]:.2f}-{pr[-1]:.2f})  {extra:.3f}")
PY
