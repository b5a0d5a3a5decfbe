#!/usr/bin/env bash
# Issue 26, point 16: the help of the commands. run, resume and bench --help describe --set,
# --fpe (run, resume), the default --out (run) and what --max-steps counts; compare --help
# prints one usage; `run DIR` with a directory says so; an unknown option prints the usage of
# its command only.
# usage: cli_help.sh CHANSPH RUNS
set -u
chansph=$1 runs=$2
status=0
fail() { echo "FAIL: $*"; status=1; }
for cmd in run resume; do
  h=$("$chansph" $cmd --help 2>&1) || fail "$cmd --help: exit status"
  for want in "--set SEC.KEY=V  override a scene key" "--fpe            trap floating-point" \
    "--max-steps N    stop after N steps of this process"; do
    echo "$h" | grep -qF -- "$want" || fail "$cmd --help does not describe: $want"
  done
done
"$chansph" run --help | grep -qF "default runs/<scene file name without .ini>" ||
  fail "run --help does not give the default --out"
"$chansph" bench --help | grep -qF -- "--set SEC.KEY=V overrides a scene key" ||
  fail "bench --help does not describe --set"
[ "$("$chansph" compare --help 2>&1 | grep -c "^usage:")" -eq 1 ] ||
  fail "compare --help does not print one usage"
mkdir -p "$runs/cli_help_dir"
out=$("$chansph" run "$runs/cli_help_dir" 2>&1)
[ $? -eq 1 ] || fail "run DIR: exit status not 1"
echo "$out" | head -n 2
echo "$out" | grep -q "is a directory, not a scene file" || fail "run DIR does not say it is a directory"
for cmd in run resume bench; do
  out=$("$chansph" $cmd --no-such-option 2>&1)
  echo "$out" | grep -q "^error: unexpected argument '--no-such-option'" || fail "$cmd: no error"
  echo "$out" | grep -q "^  chansph $cmd " || fail "$cmd: its usage is not printed"
  echo "$out" | grep -Eq "^  chansph (extract|compare|scene-doc)" &&
    fail "$cmd --no-such-option prints the usage of every command"
done
[ $status -eq 0 ] && echo PASS
exit $status
