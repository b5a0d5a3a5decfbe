#!/usr/bin/env bash
# Functions longer than a limit (default 80 lines, from the line of the name to the closing
# brace) in solver/, stats/ and restart/ (issue 14: a function fits on a screen). Brace
# matching on clang-format'ed sources: a function starts at a line that begins with a type or
# name at column 0 and ends at the line "}" at column 0.
# usage: tests/func_length.sh [LIMIT]   prints "LINES file:line name" per function over LIMIT;
#        exit 1 if there is any
set -eu
cd "$(dirname "$0")/.."
limit=${1:-80}
find solver stats restart -name '*.c' | sort | xargs awk -v limit="$limit" '
  FNR == 1 { start = 0 }
  /^[A-Za-z_][^;]*\(/ && !/^(typedef|struct [a-z_]+ \{|enum|#)/ && start == 0 {
    start = FNR; head = $0
  }
  start && /^}/ {
    n = FNR - start + 1
    if (n > limit) {
      name = head; sub(/\(.*/, "", name); sub(/.*[ *]/, "", name)
      printf "%5d %s:%d %s\n", n, FILENAME, start, name
    }
    start = 0
  }
  start && /^[A-Za-z_].*;$/ && FNR == start { start = 0 } # a prototype
' | sort -rn | tee /tmp/func_length.$$
status=0
[ -s /tmp/func_length.$$ ] && status=1
rm -f /tmp/func_length.$$
exit $status
