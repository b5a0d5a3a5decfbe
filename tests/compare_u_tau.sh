#!/usr/bin/env bash
# Issue 26, points 11 and 12: `chansph compare` of a short 2-D channel against the DNS at
# Re_tau = 180.
# u_tau (point 11): the table, compare.csv and the summary name the u_tau (force balance, wall
# stress or a given value) and its span (average_start .. average_end, windows), and the summary
# names the largest error.
# plots (point 12): with one window, each PNG's title (PNG Title text) names the run, Re_tau, the
# u_tau and the windows, its legend has no "2 standard errors", and warnings say that fewer
# than 2 windows give no standard errors and that the Re_tau differs by more than 20%.
# usage: compare_u_tau.sh u_tau|plots CHANSPH SCENES RUNS DNS_DIR PYTHON
set -u
mode=$1 chansph=$2 scenes=$3 runs=$4 dns=$5/mkm1999/chan180.means py=$6
status=0
fail() { echo "FAIL: $*"; status=1; }
d=$runs/compare_$mode
rm -rf "$d"
t_end=$([ "$mode" = plots ] && echo 0.17 || echo 0.3)
"$chansph" run "$scenes/poiseuille2d.ini" --out "$d" --set time.t_end=$t_end \
  --set output.t_average_start=0.1 --set stats.window=0.05 > "$d.log" 2>&1 ||
  { tail "$d.log"; fail "run"; exit 1; }
# t_end 0.3: the 4 windows of 0.05 from 0.1, the last closed by the run's end at its boundary;
# t_end 0.17: one window (0.15 .. 0.2 is open)
span="t = 0.1 .. $t_end s, $([ "$mode" = plots ] && echo 1 || echo 4) windows"
if [ "$mode" = u_tau ]; then
  for c in force:"force balance, $span" wall:"wall stress, $span" 0.05:"given with --u-tau"; do
    out=$("$chansph" compare "$d/stats.nc" --dns "$dns" --out "$d/cmp" --no-plots \
      --u-tau "${c%%:*}" 2>&1) || fail "compare --u-tau ${c%%:*}"
    echo "$out" | grep -E "^(differences|largest|ours)"
    echo "$out" | grep -q "^differences in wall units of u_tau = .* m/s (${c#*:}" ||
      fail "--u-tau ${c%%:*}: the table does not say '${c#*:}'"
    echo "$out" | grep -q "^largest error: .* in the .*: L2 .*% of the DNS" ||
      fail "--u-tau ${c%%:*}: no largest error"
    grep -q "^# wall units of u_tau = .*(${c#*:}" "$d/cmp/compare.csv" ||
      fail "--u-tau ${c%%:*}: compare.csv does not name the u_tau"
  done
  "$chansph" compare "$d/stats.nc" --dns "$dns" --no-plots --u-tau nonsense 2>&1 |
    grep -q "^error: --u-tau nonsense: expected force, wall or a number" ||
    fail "--u-tau nonsense is not refused"
  exit $status
fi
out=$("$chansph" compare "$d/stats.nc" --dns "$dns" --out "$d/cmp" 2>&1) || fail "compare"
echo "$out" | grep warning
echo "$out" | grep -q "^warning: 1 averaging windows: no standard errors" ||
  fail "no warning for fewer than 2 windows"
echo "$out" | grep -q "^warning: the run's Re_tau = .* differs from the DNS's .* by more than 20%" ||
  fail "no warning for the Re_tau mismatch"
"$py" - "$d/cmp/Uplus.png" "$d/stats.nc" << 'PYEOF' || status=1
import re, sys, zlib
data, text = open(sys.argv[1], "rb").read(), {}
i = 8
while i < len(data):
    n, kind = int.from_bytes(data[i:i + 4], "big"), data[i + 4:i + 8]
    if kind == b"tEXt":
        k, _, v = data[i + 8:i + 8 + n].partition(b"\0")
        text[k.decode()] = v.decode("latin-1")
    i += 12 + n
title, legend = text.get("Title", ""), text.get("Description", "")
print("title: %s\nlegend: %s" % (title, legend))
ok = sys.argv[2] in title and re.search(r"Re_tau = [0-9.]+", title) and "u_tau = " in title \
    and "1 windows" in title and "2 standard errors" not in legend
print("PASS" if ok else "FAIL: the plot's title or legend")
sys.exit(0 if ok else 1)
PYEOF
exit $status
