#!/usr/bin/env bash
# Compare the speed of two builds of chansph on the benchmark cases, interleaved in one go.
#
# usage: tests/bench_compare.sh OLD_COMMIT [NEW] [--reps N] [--threads N] [--set key=value]
#                               [--new-set key=value]
#   OLD_COMMIT  a commit to build (generic Release build, as jobs/setup.sh makes it)
#   NEW         a commit, or "." (default) for the working tree's build/chansph
#   --reps N    runs of each build on each case (default 3); medians are printed
#   --threads N OpenMP threads (default 2)
#   --set k=v   passed to every bench run (e.g. --set sph.precision=double)
#   --new-set k=v  passed to the new build's runs only (e.g. HEAD against the working tree with
#               --new-set sph.precision=mixed: one build, two settings)
#   --case 'NAME|SCENE [--set k=v ...]|STEPS'  a case of your own instead of the four below
#               (repeatable; SCENE relative to the repository root), e.g. the volume diffusion
#               in sub-steps against the default setting, one build:
#               tests/bench_compare.sh HEAD --case 'dr9|jobs/scenes/mfu180w_dr6_c4_delta.ini
#               --set domain.dr=0.05|20' --new-set sph.delta=0.4 --new-set sph.diffusion_substeps=2
#   --callgrind count instructions instead of timing: each case once per build under
#               `valgrind --tool=callgrind --toggle-collect=sim_step` (the step only, not the
#               set-up), 1 thread, 3 steps; deterministic, so it resolves differences far below
#               the run-to-run noise of a shared machine (valgrind runs the AVX2 path, not
#               AVX-512). Prints the instructions per particle-step of each build and the ratio
#               new / old.
#
# Cases: the default bench case, jobs/scenes/les395_small.ini (LES), the same scene without
# the model (les.model=none: the LES / quasi-DNS cost ratio) and jobs/scenes/qdns180_small.ini.
# Each run is `chansph bench CASE --steps S`; the runs of the two builds alternate
# (old, new, old, new, ...) so that a change of the machine's load hits both alike.
# Prints per case: the medians of particle-steps/s and of ms/step for each build and the ratio
# new / old of particle-steps/s. Run it on an idle machine.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
old="" new="." reps=3 threads=2 sets=() new_sets=() callgrind=0 own_cases=()
while [ $# -gt 0 ]; do
  case "$1" in
    --reps) reps=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    --new-set) new_sets+=(--set "$2"); shift 2 ;;
    --callgrind) callgrind=1; shift ;;
    --case) own_cases+=("$2"); shift 2 ;;
    -h|--help) sed -n '2,30p' "$0"; exit 0 ;;
    *) if [ -z "$old" ]; then old=$1; else new=$1; fi; shift ;;
  esac
done
[ -n "$old" ] || { echo "usage: tests/bench_compare.sh OLD_COMMIT [NEW] [--reps N]" >&2; exit 1; }
work=${BENCH_WORK:-$(mktemp -d /tmp/chansph_bench.XXXXXX)}

build_commit() { # commit dir
  local c=$1 d=$2
  if [ -x "$d/build/chansph" ] && [ "$(cat "$d/commit" 2>/dev/null)" = "$(git -C "$here" rev-parse "$c")" ]; then
    return
  fi
  rm -rf "$d" && mkdir -p "$d/src"
  git -C "$here" archive "$c" | tar -x -C "$d/src"
  echo "bench_compare: building $c in $d" >&2
  cmake -S "$d/src" -B "$d/build" -DCMAKE_BUILD_TYPE=Release > "$d/build.log" 2>&1
  cmake --build "$d/build" -j"$(nproc)" --target chansph >> "$d/build.log" 2>&1 ||
    { tail -30 "$d/build.log"; exit 1; }
  git -C "$here" rev-parse "$c" > "$d/commit"
}

build_commit "$old" "$work/old"
old_bin=$work/old/build/chansph
if [ "$new" = "." ]; then
  new_bin=$here/build/chansph
  [ -x "$new_bin" ] || { echo "bench_compare: build/chansph missing (run jobs/setup.sh)" >&2; exit 1; }
  new_name="working tree ($(git -C "$here" rev-parse --short HEAD)+)"
else
  build_commit "$new" "$work/new"
  new_bin=$work/new/build/chansph
  new_name=$(git -C "$here" rev-parse --short "$new")
fi

S=$here/jobs/scenes
cases=("default|" "les395_small|$S/les395_small.ini" "les395_small_qdns|$S/les395_small.ini --set les.model=none"
       "qdns180_small|$S/qdns180_small.ini")
steps=(40 40 40 20)
if [ ${#own_cases[@]} -gt 0 ]; then
  cases=() steps=()
  for c in "${own_cases[@]}"; do
    IFS='|' read -r cname cargs csteps <<< "$c"
    [ -n "$cname" ] && [ -n "$cargs" ] && [ -n "$csteps" ] ||
      { echo "bench_compare: --case '$c': give NAME|SCENE [--set k=v ...]|STEPS" >&2; exit 1; }
    case $cargs in /*) ;; *) cargs=$here/$cargs ;; esac
    cases+=("$cname|$cargs") steps+=("$csteps")
  done
fi

if [ $callgrind = 1 ]; then # instruction counts of sim_step, one run per build and case
  command -v valgrind > /dev/null || { echo "bench_compare: --callgrind needs valgrind" >&2; exit 1; }
  export OMP_NUM_THREADS=1
  echo "old: $(git -C "$here" rev-parse --short "$old")  new: $new_name  callgrind, sim_step, 1 thread, 3 steps ${sets[*]} new: ${new_sets[*]}"
  printf '%-20s %16s %16s %10s\n' case "old instr/p-step" "new instr/p-step" "new / old"
  for i in "${!cases[@]}"; do
    name=${cases[$i]%%|*} args=${cases[$i]#*|}
    declare -A ir=()
    for which in old new; do
      bin=$old_bin extra=()
      [ $which = new ] && bin=$new_bin extra=("${new_sets[@]}")
      cg=$work/callgrind.$name.$which
      # shellcheck disable=SC2086
      valgrind --tool=callgrind --toggle-collect=sim_step --callgrind-out-file="$cg" \
        "$bin" bench $args --steps 3 "${sets[@]}" "${extra[@]}" > "$cg.log" 2>&1 ||
        { tail -5 "$cg.log"; echo "bench_compare: $which failed on $name under valgrind" >&2; exit 1; }
      # the fluid particles of the case (bench's first line) times 3 steps
      np=$(sed -n 's/^chansph bench: [23]D, \([0-9]*\) fluid.*/\1/p' "$cg.log" | head -1)
      ir[$which]=$(awk '/^(summary|totals):/ {print $2; exit}' "$cg")
      [ -n "${ir[$which]}" ] && [ -n "$np" ] || { tail -5 "$cg.log"; echo "bench_compare: no count for $which on $name" >&2; exit 1; }
      ir[$which]=$(echo "${ir[$which]} $np" | awk '{printf "%.1f", $1 / ($2 * 3)}')
    done
    printf '%-20s %16s %16s %10s\n' "$name" "${ir[old]}" "${ir[new]}" \
      "$(echo "${ir[new]} ${ir[old]}" | awk '{printf "%.4f", $1 / $2}')"
  done
  exit 0
fi
export OMP_NUM_THREADS=$threads
log=$work/runs.log
: > "$log"
for ((r = 1; r <= reps; r++)); do
  for i in "${!cases[@]}"; do
    name=${cases[$i]%%|*} args=${cases[$i]#*|}
    for which in old new; do
      bin=$old_bin extra=()
      [ $which = new ] && bin=$new_bin extra=("${new_sets[@]}")
      # shellcheck disable=SC2086
      out=$("$bin" bench $args --steps "${steps[$i]}" "${sets[@]}" "${extra[@]}" 2>&1)
      ps=$(echo "$out" | awk '/^particle-steps\/s:/ {print $2}')
      ms=$(echo "$out" | sed -n 's/.*(\([0-9.]*\) ms\/step).*/\1/p')
      [ -n "$ps" ] || { echo "$out" | tail -5; echo "bench_compare: $which failed on $name" >&2; exit 1; }
      echo "$name $which $ps $ms" >> "$log"
      echo "bench_compare: rep $r $name $which: $ps particle-steps/s, $ms ms/step" >&2
    done
  done
done

echo "old: $(git -C "$here" rev-parse --short "$old")  new: $new_name  threads: $threads  reps: $reps ${sets[*]} new: ${new_sets[*]}"
/usr/bin/python3 - "$log" <<'EOF'
import sys, statistics as st
rows = [l.split() for l in open(sys.argv[1]) if l.strip()]
cases = list(dict.fromkeys(r[0] for r in rows))
med = {}
print(f"{'case':<20} {'old Mps/s':>10} {'new Mps/s':>10} {'ratio':>6} {'old ms/step':>12} {'new ms/step':>12}")
for c in cases:
    for w in ("old", "new"):
        ps = [float(r[2]) for r in rows if r[0] == c and r[1] == w]
        ms = [float(r[3]) for r in rows if r[0] == c and r[1] == w]
        med[c, w] = (st.median(ps), st.median(ms))
    o, n = med[c, "old"], med[c, "new"]
    print(f"{c:<20} {o[0]/1e6:10.3f} {n[0]/1e6:10.3f} {n[0]/o[0]:6.2f} {o[1]:12.1f} {n[1]:12.1f}")
if ("les395_small", "old") in med and ("les395_small_qdns", "old") in med:
    for w in ("old", "new"):
        print(f"LES / quasi-DNS step cost on les395_small ({w}): "
              f"{med['les395_small', w][1] / med['les395_small_qdns', w][1]:.2f}")
EOF
