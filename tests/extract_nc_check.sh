#!/usr/bin/env bash
# chansph extract --window T0:T1 --nc OUT: the windows of a range written as a stats.nc of their
# own. Its profiles (read back by extract over all its windows) equal those of extract
# --window on the whole run, to the printed digit, its averaging range and window count are the
# range's, `chansph compare` reads it, and an unwritable OUT is an input error naming it
# (exit 1, nothing left behind).
# usage: extract_nc_check.sh CHANSPH STATS.nc T0:T1 DNS WORK
set -u
chansph=$1 stats=$2 range=$3 dns=$4 work=$5
mkdir -p "$work"
out=$work/range.nc
rm -f "$out"
"$chansph" extract "$stats" --window "$range" --nc "$out" || { echo "FAIL: extract --nc"; exit 1; }
vars=u_mean,uu,vv,ww,uv,u_rms,v_rms,w_rms,u_skewness,total_stress,total_stress_expected
a=$("$chansph" extract "$stats" --window "$range" --var $vars | grep -v '^#')
b=$("$chansph" extract "$out" --var $vars | grep -v '^#')
[ -n "$a" ] && [ "$a" = "$b" ] || { echo "FAIL: the profiles of $out are not those of --window $range"; diff <(echo "$a") <(echo "$b") | head; exit 1; }
ha=$("$chansph" extract "$stats" --window "$range" | sed -n 2p)
hb=$("$chansph" extract "$out" | sed -n 2p)
[ "$ha" = "$hb" ] || { echo "FAIL: u_tau line differs: $ha / $hb"; exit 1; }
/usr/bin/python3 - "$out" "$range" << 'PY' || exit 1
import sys
import netCDF4
t0, t1 = (float(x) for x in sys.argv[2].split(":"))
with netCDF4.Dataset(sys.argv[1]) as d:
    s, e, n = float(d.average_start), float(d.average_end), int(d.n_windows)
    rows = d["eulerian"]["windows"].shape[0]
    print(f"range file: t = {s} .. {e}, {n} windows ({rows} rows), scene attribute kept: "
          f"{'scene' in d.ncattrs()}")
    if abs(s - t0) > 1e-9 or abs(e - t1) > 1e-9 or n != rows or "scene" not in d.ncattrs():
        sys.exit("FAIL: the range file's attributes are not those of the range")
PY
"$chansph" compare "$out" --dns "$dns" --out "$work/compare" --no-plots > "$work/compare.log" 2>&1 ||
  { tail -3 "$work/compare.log"; echo "FAIL: chansph compare on the range file"; exit 1; }
msg=$("$chansph" extract "$stats" --window "$range" --nc "$work/no/such/dir/x.nc" 2>&1)
rc=$?
echo "$msg"
[ $rc -eq 1 ] && echo "$msg" | grep -q "error: --nc $work/no/such/dir/x.nc: the directory $work/no/such/dir does not exist: create it first" ||
  { echo "FAIL: a --nc in a missing directory is not an input error saying so (exit $rc)"; exit 1; }
ls "$work/no/such/dir" 2>/dev/null && { echo "FAIL: something was left behind"; exit 1; }
echo "PASS: the range as a stats.nc of its own"
