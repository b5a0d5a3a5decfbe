#!/usr/bin/env bash
# Bitwise comparison of this tree's chansph against an older commit's, on a few test scenes
# (issue 14: refactoring must leave results bitwise identical). Builds OLD_COMMIT into
# /tmp/chansph_ref_<commit> (once; or set CHANSPH_REF_DIR to a tree already built), runs each scene with both binaries (same thread count,
# same run id) and compares stats.nc and particles.nc (ncdump -p 9,17 of the whole file
# without the provenance attributes, tests/nc_content.sh, and without `source`, which names
# the git commit) and every checkpoint and particle snapshot (h5diff, which compares every dataset and attribute;
# the only attribute allowed to differ is `source`).
# BITWISE_NEW_KEYS="sec.key=value ...": scene keys the new build added, at their defaults (e.g.
# sph.precision=double): the new runs' scene text, which lists every key, is compared with those
# lines removed; BITWISE_NEW_SECTIONS="sec ...": whole sections the new build added (e.g.
# quadrants), removed likewise.
# usage: tests/bitwise_vs.sh OLD_COMMIT [NEW_CHANSPH (default build/chansph)]
set -u
here=$(cd "$(dirname "$0")/.." && pwd)
old=$(git -C "$here" rev-parse --short "${1:?usage: bitwise_vs.sh OLD_COMMIT [NEW_CHANSPH]}")
new=${2:-$here/build/chansph}
ref=${CHANSPH_REF_DIR:-/tmp/chansph_ref_$old}
if [ ! -x "$ref/build/chansph" ]; then
  mkdir -p "$ref" && git -C "$here" archive "$old" | tar -x -C "$ref"
  cmake -S "$ref" -B "$ref/build" -DCMAKE_BUILD_TYPE=Release > "$ref/build.log" 2>&1 &&
    cmake --build "$ref/build" -j2 --target chansph >> "$ref/build.log" 2>&1 ||
    { tail -30 "$ref/build.log"; exit 2; }
fi
export CHANSPH_RUN_ID=bitwise-vs OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}
runs=$(mktemp -d /tmp/bitwise_vs.XXXXXX)
drop_keys() { # remove the lines "key = value" of BITWISE_NEW_KEYS from a scene text (ncdump
  # writes its newlines as \n, h5dump as line breaks)
  local kv args=(-e '')
  for kv in ${BITWISE_NEW_KEYS:-}; do
    local k=${kv%%=*} v=${kv#*=}
    args+=(-e "s/\\\\n${k#*.} = $v\\\\n/\\\\n/" -e "/^ *${k#*.} = $v\$/d")
  done
  local sec
  for sec in ${BITWISE_NEW_SECTIONS:-}; do # a whole new section, up to its blank line
    args+=(-e "/^ *\\[$sec\\]\$/,/^ *\$/d")
  done
  sed "${args[@]}" | perl -pe 'for my $s (split " ", $ENV{BITWISE_NEW_SECTIONS} // "") {
    s/\\n\[\Q$s\E\]\\n.*?\\n\\n/\\n/g }'
}
content() { "$here/tests/nc_content.sh" "$1" | awk '/^\t\t:source = /{skip=1} skip{if (/ ;$/) skip=0; next} 1' | drop_keys; }
status=0
compare() { # NAME RANKS SCENE ARGS...
  local name=$1 np=$2 scene=$3
  shift 3
  local launch=()
  [ "$np" -gt 1 ] && launch=(env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
    OMP_NUM_THREADS=1 mpirun -np "$np" --oversubscribe)
  for side in old new; do
    local bin=$ref/build/chansph
    [ $side = new ] && bin=$new
    "${launch[@]}" "$bin" run "$here/jobs/scenes/$scene" --out "$runs/$name.$side" --overwrite "$@" > /dev/null 2>&1
    local rc=$?
    [ $rc -eq 0 ] || [ $rc -eq 75 ] || { echo "FAIL: $name ($side) exited $rc"; status=1; return; }
  done
  for f in stats.nc particles.nc; do
    if [ ! -f "$runs/$name.old/$f" ]; then echo "$name $f: not written"; continue; fi
    if diff <(content "$runs/$name.old/$f") <(content "$runs/$name.new/$f") > /dev/null; then
      echo "$name $f: identical ($(content "$runs/$name.old/$f" | wc -l) lines of ncdump)"
    else
      echo "$name $f: DIFFERENT"; status=1
    fi
  done
  local n=0
  for c in "$runs/$name.old"/checkpoints/ckpt_*.h5 "$runs/$name.old"/snapshots/snap_*.h5; do
    [ -f "$c" ] || continue
    local d=$runs/$name.new/${c#"$runs/$name.old/"}
    # h5diff -v lists every object (both files: two x) and the differences of each; only the
    # attribute `source` (the git commit) may differ. h5diff cannot compare empty datasets
    # (e.g. no Lagrangian track in flight): their headers (shape, type, attributes) are.
    local report empty=""
    report=$(h5diff -v "$c" "$d" 2>&1)
    if [ -f "$d" ] && printf '%s\n' "$report" | awk -v newkeys="${BITWISE_NEW_KEYS:+1}${BITWISE_NEW_SECTIONS:+1}" '
        /^ +x +\// { if ($2 != "x") bad = 1 } # an object in one file only
        /^(attribute|dataset|group|datatype): / { obj = $0 }
        /^[0-9]+ differences? found/ { if ($1 > 0 && obj !~ /^attribute: <source of/ &&
                                       !(newkeys && obj ~ /^dataset: <\/scene>/)) bad = 1 }
        /[Nn]ot comparable/ && !/is an empty dataset/ && !/^Some objects/ { bad = 1 }
        END { exit bad }'; then
      empty=$(printf '%s\n' "$report" | sed -n 's/^Not comparable: <\([^>]*\)> or .* is an empty dataset$/\1/p')
      for e in $empty; do
        cmp -s <(h5dump -H -d "$e" "$c" | tail -n +2) <(h5dump -H -d "$e" "$d" | tail -n +2) ||
          { echo "$name $(basename "$c") $e: DIFFERENT header"; status=1; }
      done
      # with new keys the scene texts differ by those lines only (h5dump, the size line aside)
      [ -n "${BITWISE_NEW_KEYS:-}${BITWISE_NEW_SECTIONS:-}" ] && ! cmp -s <(h5dump -d /scene "$c" 2>/dev/null | tail -n +2 | grep -v STRSIZE | drop_keys) \
        <(h5dump -d /scene "$d" 2>/dev/null | tail -n +2 | grep -v STRSIZE | drop_keys) &&
        { echo "$name $(basename "$c") /scene: DIFFERENT"; status=1; }
      n=$((n + 1))
    else
      echo "$name $(basename "$c"): DIFFERENT"; status=1
    fi
  done
  echo "$name checkpoints and snapshots: $n identical (h5diff)"
}
compare poiseuille2d 1 poiseuille2d.ini --max-steps 300
compare les395_smoke 1 les395_smoke.ini --max-steps 200
compare qdns180_smoke 1 qdns180_smoke.ini --max-steps 200
# every statistics engine (Eulerian windows, correlations and spectra, Lagrangian tracks),
# on one rank and on two (domain decomposition, parallel statistics snapshot)
allstats=(--set time.t_end=0.6 --set output.t_average_start=0.1 --set stats.window=0.1
  --set stats.u_tau_ref=0.6 --set correlations.y_plus=1,2 --set lagrangian.y_plus=1,2
  --set lagrangian.horizon=0.2 --set lagrangian.release_every=0.1 --set lagrangian.n_lags=10
  --set lagrangian.pdf_x=0.01)
compare allstats 1 poiseuille3d.ini "${allstats[@]}"
# two ranks (domain decomposition, parallel statistics, particle files written by id block): the 2-D
# case of tests/mpi_check.sh bitwise2d
compare mpi2d_np2 2 poiseuille2d.ini --set domain.lx=2.0 --set time.t_end=1000 \
  --set time.max_steps=200 --set init.noise=0.3 --set init.modes=0.2 --set output.stats_every=5 \
  --set "correlations.y_plus=20,60" --set lagrangian.y_plus=40 --set lagrangian.horizon=0.2 \
  --set lagrangian.n_lags=10 --set stats.u_tau_ref=0.6 --set snapshots.every=0.5
[ $status -eq 0 ] && echo "bitwise identical to $old" && rm -rf "$runs"
exit $status
