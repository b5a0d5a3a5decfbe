#!/usr/bin/env bash
# Issue 13, points 7 and 8: chansph compare and extract refuse unusable inputs with a clear
# message naming the file (and line), exit status 1, and no Python traceback: empty,
# header-only, binary, short-column, NaN, Inf and reversed DNS tables, a missing file, a
# stats.nc that is not netCDF, a usage error; extract --window a:b. --help exits 0; compare
# runs CHANSPH_PYTHON when set (point 13).
# usage: compare_inputs.sh CHANSPH DNS_DIR RUNS
set -u
chansph=$1 dns=$2 runs=$3
status=0
fail() { echo "FAIL: $*"; status=1; }
w=$runs/compare_inputs
rm -rf "$w" && mkdir -p "$w" || exit 1
ours=$dns/mkm1999/chan180.means
good=$(grep -v '^#' "$ours" | grep -E '^ *[0-9]' | head -n 20)

# expect NAME REGEX command...: exit 1, a message matching REGEX, no traceback
expect() {
  local name=$1 regex=$2
  shift 2
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  echo "$name: exit $rc: $(echo "$out" | grep -m1 error)"
  [ $rc -eq 1 ] || fail "$name: exit status $rc, expected 1"
  echo "$out" | grep -Eq -- "$regex" || fail "$name: no message matching: $regex"
  echo "$out" | grep -q Traceback && fail "$name: a Python traceback"
}
table() { # table NAME: a directory NAME holding chan180.means from stdin
  mkdir -p "$w/$1" && cat > "$w/$1/chan180.means"
}
compare() { "$chansph" compare "$ours" --dns "$1" --out "$w/out" --no-plots; }

table empty < /dev/null
expect empty "empty/chan180.means: a mean profile .* holds 0 data row" compare "$w/empty/chan180.means"
printf '# comment\n  y/delta  y^+  U\n' | table header_only
expect header_only "holds 0 data row" compare "$w/header_only/chan180.means"
head -c 3000 /dev/urandom | table binary
printf '\0\0\0' >> "$w/binary/chan180.means"
expect binary "binary/chan180.means(:[0-9]+)?: binary data, not a text table" compare "$w/binary/chan180.means"
echo "$good" | awk '{print $1, $2}' | table short
expect short "short/chan180.means:[0-9]+: 2 column\(s\), a mean profile .* needs at least 3" compare "$w/short/chan180.means"
echo "$good" | awk 'NR == 6 { $2 = "nan" } 1' | table nan
expect nan "nan/chan180.means:6: non-finite value \(NaN or Inf\) in column 2" compare "$w/nan/chan180.means"
echo "$good" | awk 'NR == 20 { $2 = "inf" } 1' | table inf
expect inf "inf/chan180.means:20: non-finite value \(NaN or Inf\) in column 2" compare "$w/inf/chan180.means"
echo "$good" | tac | table reversed
expect reversed "reversed/chan180.means:2: y/delta = .* is not larger than the previous row's" compare "$w/reversed/chan180.means"
expect missing "/nonexistent/chan180.means: cannot open a mean profile .*: No such file" compare /nonexistent/chan180.means
expect missing_unknown "/nonexistent: no such file" compare /nonexistent
echo "not netCDF" > "$w/fake.nc"
expect stats_not_netcdf "fake.nc: cannot open as netCDF" "$chansph" compare "$w/fake.nc" --dns "$ours" --out "$w/out"
expect stats_missing "missing.nc: cannot open: No such file" "$chansph" compare "$w/missing.nc" --dns "$ours" --out "$w/out"
expect usage "the following arguments are required: --dns" "$chansph" compare "$ours"
expect extract_window "--window a:b: expected T0:T1" "$chansph" extract "$w/fake.nc" --window a:b
expect extract_window_order "--window 2:1: expected T0:T1" "$chansph" extract "$w/fake.nc" --window 2:1
expect extract_missing "missing.nc: No such file" "$chansph" extract "$w/missing.nc"
# the good rows are accepted (the checks refuse only what is wrong)
echo "$good" | table good
compare "$w/good/chan180.means" > /dev/null 2>&1 || fail "a valid 20-row table was refused"
for cmd in compare extract; do
  "$chansph" $cmd --help > /dev/null 2>&1 || fail "chansph $cmd --help: exit $?"
done
# compare runs the python3 named by CHANSPH_PYTHON (issue 13, point 13)
printf '#!/bin/sh\necho "fake python: $*"\n' > "$w/fakepy" && chmod +x "$w/fakepy"
CHANSPH_PYTHON=$w/fakepy "$chansph" compare "$ours" --dns "$ours" | grep -q "^fake python: .*compare.py" ||
  fail "CHANSPH_PYTHON is not used"
expect python_missing "cannot start /nonexistent/python3 for chansph compare .*CHANSPH_PYTHON" \
  env CHANSPH_PYTHON=/nonexistent/python3 "$chansph" compare "$ours" --dns "$ours"
[ $status -eq 0 ] && echo PASS
exit $status
