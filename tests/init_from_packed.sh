#!/usr/bin/env bash
# Issue 42 point 5: init.from reads CF-packed variables (scale_factor, add_offset, as NCO's
# ncpdq writes them) as their values: the packed state starts the run as the unpacked one
# does (u_bulk, max|v|, rho range of step 0 to the packing's precision), with a note; a packed
# id, and a value equal to its _FillValue, are input errors naming the file and variable.
# usage: init_from_packed.sh CHANSPH SCENE STATE WORK   (STATE: a run's particles.nc)
set -u
chansph=$1 scene=$2 state=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
command -v ncpdq > /dev/null || { echo "SKIP: ncpdq (Debian nco) not found"; exit 77; }
ncpdq -O "$state" "$work/packed.nc" || { echo "FAIL: ncpdq"; exit 1; }
ncdump -h "$work/packed.nc" | grep -q "short u(particle)" || { echo "FAIL: u not packed"; exit 1; }
step0() { # step0 FROM: the step-0 line of a run from FROM (u_bulk, max|v|, rho range)
  "$chansph" run "$scene" --out "$work/run" --overwrite --set init.from="$1" \
    --set time.t_end=0.01 --set output.t_average_start=0 > "$work/run.log" 2>&1 ||
    { tail -3 "$work/run.log"; echo "FAIL: run from $1"; exit 1; }
  grep -E "^step +0 " "$work/run.log" | sed -E 's/.*(u_bulk [^ ]+).*(max\|v\| [^ ]+) +(rho [^]]+\]).*/\1 \2 \3/'
}
a=$(step0 "$state")
b=$(step0 "$work/packed.nc")
grep "init: .* CF-packed" "$work/run.log" || { echo "FAIL: no note of the packing"; exit 1; }
echo "unpacked: $a"
echo "packed:   $b"
/usr/bin/python3 - "$a" "$b" << 'PY' || exit 1
import re, sys
x, y = ([float(v) for v in re.findall(r"[-+0-9.e]+(?=[ ,\]]|$)", s)] for s in sys.argv[1:3])
bad = len(x) != 4 or len(y) != 4 or any(abs(p - q) > 1e-4 * max(abs(p), 1e-3) for p, q in zip(x, y))
sys.exit("FAIL: the packed state does not start as the unpacked one" if bad else 0)
PY
status=0
expect() { # expect REGEX FROM
  "$chansph" run "$scene" --out "$work/bad" --overwrite --set init.from="$2" \
    --set time.t_end=0.01 --set output.t_average_start=0 > "$work/bad.log" 2>&1
  local rc=$?
  grep error "$work/bad.log" | head -1
  [ $rc -eq 1 ] && grep -q -- "$1" "$work/bad.log" || { echo "FAIL: $2: exit $rc"; status=1; }
}
nccopy "$work/packed.nc" "$work/packed_id.nc" && ncatted -h -a scale_factor,id,o,d,1 "$work/packed_id.nc"
expect "packed_id.nc (init.from): variable 'id' is packed (scale_factor, add_offset): the ids must be stored exactly" "$work/packed_id.nc"
fill=$(ncks -H -C -v u -d particle,3 "$work/packed.nc" | grep -oE "u = -?[0-9]+" | grep -oE -- "-?[0-9]+$")
nccopy "$work/packed.nc" "$work/packed_fill.nc" && ncatted -h -a _FillValue,u,o,s,"$fill" "$work/packed_fill.nc"
expect "packed_fill.nc (init.from): variable 'u' is missing at index 3 (its _FillValue)" "$work/packed_fill.nc"
[ $status -eq 0 ] && echo "PASS: CF-packed init.from unpacked; packed ids and fill values refused"
exit $status
