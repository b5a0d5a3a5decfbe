#!/usr/bin/env bash
# A run's stats.nc and particles.nc open read-only in the tools that change a file in place
# (netCDF-C 4.9's in-memory files, docs/formats.md); the copy the docs give, nccopy, opens for
# writing (ncatted adds an attribute) and holds the same data (ncdump of the copy without the
# new attribute equals ncdump of the original, names aside); chansph extract's output opens
# for writing too.
# usage: nc_writable_copy.sh CHANSPH RUN_DIR WORK
set -u
chansph=$1 run=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail=0
check() { if [ "$1" = 0 ]; then echo "PASS: $2"; else echo "FAIL: $2"; fail=1; fi; }
for f in stats particles; do
  nccopy "$run/$f.nc" "$work/$f.nc"
  check $? "nccopy $f.nc"
  ncatted -h -a chansph_note,global,c,c,"annotated" "$work/$f.nc"
  check $? "ncatted writes to the copy of $f.nc"
  ncdump -h "$work/$f.nc" | grep -q 'chansph_note = "annotated"'
  check $? "the copy of $f.nc holds the new attribute"
  diff <(ncdump "$run/$f.nc" | sed 1d) <(ncdump "$work/$f.nc" | grep -v chansph_note | sed 1d) \
    > "$work/$f.diff"
  check $? "the copy of $f.nc has the original's content ($(wc -l < "$work/$f.diff") lines differ)"
done
"$chansph" extract "$run/stats.nc" --nc "$work/extract.nc" > "$work/extract.log" 2>&1
check $? "chansph extract"
ncatted -h -a chansph_note,global,c,c,"annotated" "$work/extract.nc"
check $? "ncatted writes to extract's output"
exit $fail
