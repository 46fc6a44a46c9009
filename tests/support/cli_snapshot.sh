#!/usr/bin/env bash
# One CLI case: `plcfi ARGS...` run in folder DIR (so the paths in messages are stable),
# its complete output and exit status must equal DIR/expected/NAME.txt line for line.
#   usage: cli_snapshot.sh PLCFI DIR NAME ARGS...
#   PLCFI_UPDATE_SNAPSHOTS=1 rewrites expected/NAME.txt (review the diff before committing).
set -u
plcfi=$1
dir=$(cd "$2" && pwd)
name=$3
shift 3
expected=$dir/expected/$name.txt
# Wall-clock figures are the only thing that changes from run to run.
actual=$(cd "$dir" && "$plcfi" "$@" 2>&1 | sed -E 's/[0-9]+(\.[0-9]+)? ?(ms|s) wall/<time> wall/g'; echo "exit=${PIPESTATUS[0]}")
if [[ "${PLCFI_UPDATE_SNAPSHOTS:-}" == 1 ]]; then
  mkdir -p "$dir/expected"
  printf '%s\n' "$actual" > "$expected"
  echo "wrote $expected"
  exit 0
fi
if [[ ! -f "$expected" ]]; then
  echo "no snapshot expected/$name.txt; run with PLCFI_UPDATE_SNAPSHOTS=1 and review it. Output:"
  printf '%s\n' "$actual"
  exit 1
fi
if ! diff -u "$expected" <(printf '%s\n' "$actual"); then
  echo "$name: output differs from expected/$name.txt (- expected, + actual)"
  exit 1
fi
echo "$name: as expected"
