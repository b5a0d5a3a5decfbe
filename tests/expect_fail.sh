#!/usr/bin/env bash
# Expected failure: run a command, require its exit status and a message matching a regex.
# usage: expect_fail.sh STATUS REGEX command [args...]
set -u
want=$1 regex=$2
shift 2
out=$("$@" 2>&1)
rc=$?
echo "$out" | tail -n 5
[ "$rc" -eq "$want" ] || { echo "FAIL: exit status $rc, expected $want"; exit 1; }
echo "$out" | grep -Eq -- "$regex" || { echo "FAIL: no message matching: $regex"; exit 1; }
echo "PASS"
