#!/usr/bin/env bash
# One negative-suite file against its snapshot: `plcfi check FILE.st` (run in the file's
# folder, so paths are stable), its complete output and exit status, must equal
# FILE.expected line for line: an extra or a cascading diagnostic fails the test as surely
# as a missing one. The file's own `// expect: STnnn @ LINE` comments must be in the
# snapshot too, so rewriting snapshots cannot quietly drop the error a file is about.
#   usage: check_snapshot.sh PLCFI FILE.st
#   PLCFI_UPDATE_SNAPSHOTS=1 rewrites FILE.expected (review the diff before committing).
set -u
plcfi=$1
file=$2
dir=$(dirname "$file")
name=$(basename "$file")
expected="${file%.st}.expected"
actual=$(cd "$dir" && "$plcfi" check "$name" 2>&1; echo "exit=$?")

status=0
while read -r code line; do
  if ! grep -q "^$name:$line:[0-9]*: error\[$code\]" <<<"$actual"; then
    echo "$name: its comment expects $code at line $line, which plcfi check does not report"
    status=1
  fi
done < <(grep -o 'expect: *ST[0-9]* *@ *[0-9]*' "$file" | sed 's|expect: *\(ST[0-9]*\) *@ *\([0-9]*\)|\1 \2|')
grep -q "^exit=1$" <<<"$actual" || { echo "$name: plcfi check must exit 1 on an invalid file"; status=1; }

if [[ "${PLCFI_UPDATE_SNAPSHOTS:-}" == 1 ]]; then
  printf '%s\n' "$actual" > "$expected"
  echo "wrote $expected"
  exit $status
fi
if [[ ! -f "$expected" ]]; then
  echo "$name: no snapshot $(basename "$expected"); run with PLCFI_UPDATE_SNAPSHOTS=1 and review it. Output:"
  printf '%s\n' "$actual"
  exit 1
fi
if ! diff -u "$expected" <(printf '%s\n' "$actual"); then
  echo "$name: output differs from $(basename "$expected") (- expected, + actual)"
  exit 1
fi
exit $status
