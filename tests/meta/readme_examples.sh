#!/usr/bin/env bash
# Every command README.md shows (`$ ...` lines in its code blocks) runs as shown in a fresh
# copy of the repository: the files it names exist and it ends with status 0 or 1 (a
# check or a test that fails on purpose), never 2 (bad usage or input) unless README says
# so after the command (`# exits 2`), and never with a crash.
# usage: readme_examples.sh PLCFI SOURCE_DIR
set -uo pipefail
plcfi=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_readme_XXXXXX")
trap 'kill $(jobs -p) 2>/dev/null; rm -rf "$work"' EXIT
(cd "$src" && git ls-files -z 2>/dev/null | xargs -0 cp --parents -t "$work" 2>/dev/null) || cp -r "$src"/. "$work"
[[ -f "$work/README.md" ]] || { echo "cannot copy the repository"; exit 1; }
# README's bench examples serve on 127.0.0.1:1502 and :1503. In the copy they move to free
# ports, so that two runs of this test on one machine (two clones' CI) cannot collide.
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
p1=$(free_port)
p2=$(free_port)
while [[ $p2 == "$p1" ]]; do p2=$(free_port); done
grep -rlZ -e "127.0.0.1:1502" -e "127.0.0.1:1503" "$work" | xargs -0 -r sed -i "s/127\.0\.0\.1:1502/127.0.0.1:$p1/g; s/127\.0\.0\.1:1503/127.0.0.1:$p2/g"
mkdir -p "$work/.bin"
ln -s "$plcfi" "$work/.bin/plcfi"
export PATH="$work/.bin:$PATH"

# The commands, continuation lines joined, in README order.
mapfile -t commands < <(awk '
  /^```/ { inblock = !inblock; next }
  inblock && /^\$ / { cmd = substr($0, 3); while (cmd ~ /\\$/ && (getline line) > 0) cmd = substr(cmd, 1, length(cmd) - 1) " " line; print cmd }
' "$work/README.md")
(( ${#commands[@]} >= 10 )) || { echo "found only ${#commands[@]} commands in README.md"; exit 1; }

cd "$work"
failures=0
for cmd in "${commands[@]}"; do
  echo "\$ $cmd"
  if [[ "$cmd" == *"&" ]]; then            # a server for the next commands
    eval "${cmd% &*} > .bg.log 2>&1 &"
    server=$!
    for _ in $(seq 1 100); do grep -q listening .bg.log 2>/dev/null && break; sleep 0.05; done
    continue
  fi
  if [[ "$cmd" == kill* ]]; then           # ends that server
    # By its pid, not the job spec README shows: a job table without job control has
    # been seen to leave `wait` waiting for ever (twice, beside another build).
    eval "${cmd//%1/$server}" || { echo "  -> FAILED"; failures=$((failures + 1)); }
    for _ in $(seq 1 400); do kill -0 "$server" 2>/dev/null || break; sleep 0.05; done
    if kill -0 "$server" 2>/dev/null; then
      echo "  -> FAILED: the server did not end within 20 s of the signal ($(grep -E 'SigPnd|SigCgt' /proc/$server/status | tr '\n' ' '))"
      kill -9 "$server"
      failures=$((failures + 1))
    fi
    wait "$server" 2>/dev/null
    continue
  fi
  # A command shown failing on purpose says so: `$ plcfi ... # exits 2`.
  expected="0 1"
  [[ "$cmd" =~ \#\ *exits\ ([0-9]+) ]] && expected=${BASH_REMATCH[1]}
  started=$SECONDS
  out=$(eval "$cmd" 2>&1)
  status=$?
  printf '%s\n' "$out" | tail -n 4
  echo "  ($((SECONDS - started)) s)"   # the real-time examples dominate; on a loaded machine too
  if [[ " $expected " != *" $status "* ]] || grep -qE "terminate called|Sanitizer|runtime error:" <<<"$out"; then
    echo "  -> FAILED: exit status $status (expected ${expected// / or })"
    failures=$((failures + 1))
  fi
done
echo "${#commands[@]} README command(s), $failures failed"
(( failures == 0 ))
