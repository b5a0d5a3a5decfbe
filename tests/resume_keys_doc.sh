#!/usr/bin/env bash
# Issue 26, point 5: the keys docs/batch-jobs.md says a resume may change are the keys
# restart/resume.c accepts (the list `changeable`), no more, no fewer.
# usage: resume_keys_doc.sh SOURCE_DIR
set -u
src=$1
code=$(sed -n '/changeable\[\] = {/,/};/p' "$src/restart/resume.c" | grep -o '"[a-z_]*\.[a-z_0-9]*"' |
  tr -d '"' | sort -u)
doc=$(sed -n '/`--set` may change only these keys/,/(the list in `restart\/resume.c`/p' \
  "$src/docs/batch-jobs.md" | grep -o '`[a-z_]*\.[a-z_0-9]*`' | tr -d '`' | grep -v '^resume\.c$' |
  sort -u)
[ -n "$code" ] || { echo "FAIL: no key list found in restart/resume.c"; exit 1; }
missing=$(comm -23 <(echo "$code") <(echo "$doc"))
extra=$(comm -13 <(echo "$code") <(echo "$doc"))
[ -z "$missing" ] || echo "FAIL: accepted by resume but not in docs/batch-jobs.md:" $missing
[ -z "$extra" ] || echo "FAIL: in docs/batch-jobs.md but refused by resume:" $extra
[ -z "$missing$extra" ] || exit 1
echo "PASS: $(echo "$code" | wc -l) keys"
