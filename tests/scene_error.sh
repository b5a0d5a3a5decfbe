#!/usr/bin/env bash
# Expected-failure test of a malformed scene: chansph must exit with status 1, print a message
# matching REGEX (file, line, key), and leave an existing output directory exactly as it was.
# usage: scene_error.sh CHANSPH SCENE REGEX [extra args...]
set -u
chansph=$1 scene=$2 regex=$3
shift 3
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "earlier results" > "$out/stats.nc"
echo "earlier log" > "$out/log.txt"
before=$(cd "$out" && ls -l --time-style=+%s.%N && cat stats.nc log.txt)
msg=$("$chansph" run "$scene" --out "$out" --overwrite "$@" 2>&1)
rc=$?
echo "$msg"
after=$(cd "$out" && ls -l --time-style=+%s.%N && cat stats.nc log.txt)
[ "$rc" -eq 1 ] || { echo "FAIL: exit status $rc, expected 1"; exit 1; }
echo "$msg" | grep -Eq -- "$regex" || { echo "FAIL: message does not match: $regex"; exit 1; }
[ "$before" = "$after" ] || { echo "FAIL: the output directory was modified"; exit 1; }
echo "PASS"
