#!/usr/bin/env bash
# The accuracy of sph.precision = mixed against double (issue 11, item 4): the validations whose
# numbers a user would compare, each run with both settings, printed as one markdown table.
#   - steady Poiseuille, relative L2 error of U (2-D and 3-D, Morris; 3-D Violeau)
#   - flux controller, relative error of the bulk velocity (poiseuille2d_flux.ini)
#   - Smagorinsky channel, relative L2 error of U against the model's own steady profile
#   - Taylor-Green Pi_xx (tests/taylor_green --mixed), L2 error at N = 32, lattice and jittered
#   - turbulent smoke scenes (les395_smoke, qdns180_smoke from their shipped starts, 2000 steps,
#     t u_tau/delta about 1, ten windows of 0.1): the largest |mixed - double| of u_mean, uu, vv,
#     ww and uv, over the profile's maximum and over the double run's standard error; a third
#     run in double with the start perturbed at round-off level is the chaotic yardstick
# usage: tests/precision_table.sh [CHANSPH (default build/chansph)] [WORK (default a temp dir)]
# Threads: OMP_NUM_THREADS (results do not depend on it).
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$here/build/chansph}
tg=$(dirname "$bin")/tests/taylor_green
work=${2:-$(mktemp -d /tmp/precision.XXXXXX)}
py=/usr/bin/python3
check() { # WHAT SCENE PRECISION ARGS... -> the check's summary line
  local what=$1 scene=$2 p=$3
  shift 3
  "$py" "$here/tests/poiseuille_check.py" --chansph "$bin" --runs "$work/$p" "$what" \
    "$here/jobs/scenes/$scene" --set sph.precision="$p" "$@" | grep -E "L2 error|Eq. 3.43" | head -1
}
num() { # the number after "= " (first match of PATTERN) in a summary line
  sed -n "s/.*$1[^=0-9]*[= ]*\([-0-9.e+]*\).*/\1/p" | head -1
}
echo "| validation | double | mixed | double, start perturbed by 2e-7 |"
echo "|---|---|---|---|"
row() { # LABEL PATTERN WHAT SCENE ARGS...
  local label=$1 pat=$2
  shift 2
  local d m
  d=$(check "$1" "$2" double "${@:3}" | num "$pat")
  m=$(check "$1" "$2" mixed "${@:3}" | num "$pat")
  echo "| $label | $d | $m | |"
}
row "Poiseuille 2-D (Morris), L2 error of U" "L2 error" steady poiseuille2d.ini
row "Poiseuille 3-D (Morris), L2 error of U" "L2 error" steady poiseuille3d.ini
row "Poiseuille 3-D (Violeau), L2 error of U" "L2 error" steady poiseuille3d.ini \
  --set sph.viscous=violeau
row "flux controller 2-D (Eq. 3.43), max relative error of U_b" "max relative error" flux \
  poiseuille2d_flux.ini
row "Smagorinsky channel 2-D, L2 error of U" "L2 error" smagorinsky poiseuille2d.ini \
  --set les.cs=1 --set les.a_plus=1
for j in 0 0.2; do
  d=$("$tg" --jitter $j | awk '$1 == 32 {print $3 " / " $5}')
  m=$("$tg" --jitter $j --mixed | awk '$1 == 32 {print $3 " / " $5}')
  echo "| Taylor-Green Pi_xx, N = 32, jitter $j dr: L2 standard / corrected | $d | $m | |"
done
# The turbulent runs are chaotic: any change at round-off level grows. The third column is the
# yardstick for that: double again, with the start's noise amplitude changed by 2e-7 of itself
# (init.noise 0.5 -> 0.5000001, about float round-off).
for s in les395_smoke qdns180_smoke; do
  for p in double mixed perturbed; do
    prec=$p extra=()
    [ $p = perturbed ] && prec=double extra=(--set init.noise=0.5000001)
    "$bin" run "$here/jobs/scenes/$s.ini" --out "$work/$s.$p" --overwrite \
      --set sph.precision=$prec --set time.max_steps=2000 --set time.t_end=10 \
      --set output.t_average_start=0 --set stats.window=0.1 "${extra[@]}" > /dev/null 2>&1 ||
      { echo "FAIL: $s ($p)"; exit 1; }
  done
  "$py" - "$work/$s" "$s" << 'EOF'
import sys
import netCDF4
import numpy as np
d = {p: netCDF4.Dataset("%s.%s/stats.nc" % (sys.argv[1], p)) for p in ("double", "mixed", "perturbed")}
rows = {}
for p in ("mixed", "perturbed"):
    rel, sig = [], []
    for v in ("u_mean", "uu", "vv", "ww", "uv"):
        x, y = d["double"][v][:].filled(np.nan), d[p][v][:].filled(np.nan)
        e = d["double"][v + "_stderr"][:].filled(np.nan)
        ok = np.isfinite(x) & np.isfinite(y)
        rel.append(np.abs(x - y)[ok].max() / np.abs(x[ok]).max())
        good = ok & np.isfinite(e) & (e > 0)
        sig.append((np.abs(x - y)[good] / e[good]).max())
    rows[p] = (", ".join("%.1e" % r for r in rel), ", ".join("%.1f" % s for s in sig))
s = sys.argv[2]
print("| %s, 2000 steps: max of the difference from double over the profile's max (u_mean, uu, "
      "vv, ww, uv) | 0 | %s | %s |" % (s, rows["mixed"][0], rows["perturbed"][0]))
print("| %s: the same over the double run's standard error | 0 | %s | %s |"
      % (s, rows["mixed"][1], rows["perturbed"][1]))
EOF
done
