#!/usr/bin/env bash
# Every command the README and the manual show (`$ ...` lines in the code blocks of
# README.md and of every page in docs/mkdocs.yml's nav, in that order) runs as shown in a
# fresh copy of the repository: the files it names exist and it ends with status 0 or 1
# (a check or a test that fails on purpose), never 2 (bad usage or input) unless the page
# says so after the command (`# exits 2`), and never with a crash. And the manual builds:
# `mkdocs build --strict` (Debian's mkdocs, installed by scripts/install-deps).
#
# All pages run in one copy, each page's commands in order: a command may use what an
# earlier command of the same page wrote, never what another page wrote (a page repeats
# the commands it needs), and a server a page starts (`... &`) is ended on that page.
# usage: docs_examples.sh PLCFI SOURCE_DIR
set -uo pipefail
plcfi=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_docs_XXXXXX")
trap 'kill $(jobs -p) 2>/dev/null; rm -rf "$work"' EXIT
if git -C "$src" rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  # Tracked files and new ones git does not ignore (a page written, not committed yet). A
  # file deleted in the work tree but still tracked cannot be copied: cp says so, and
  # every other file is copied all the same.
  (cd "$src" && git ls-files -z --cached --others --exclude-standard | xargs -0 cp --parents -t "$work" 2> /dev/null)
else
  cp -r "$src"/. "$work"
fi
[[ -f "$work/README.md" && -f "$work/docs/mkdocs.yml" ]] || { echo "cannot copy the repository"; exit 1; }
# The bench examples serve on 127.0.0.1:1502 and :1503. In the copy they move to free
# ports, so that two runs of this test on one machine (two clones' CI) cannot collide.
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
p1=$(free_port)
p2=$(free_port)
while [[ $p2 == "$p1" ]]; do p2=$(free_port); done
grep -rlZ -e "127.0.0.1:1502" -e "127.0.0.1:1503" "$work" | xargs -0 -r sed -i "s/127\.0\.0\.1:1502/127.0.0.1:$p1/g; s/127\.0\.0\.1:1503/127.0.0.1:$p2/g"
mkdir -p "$work/.bin"
ln -s "$plcfi" "$work/.bin/plcfi"
export PATH="$work/.bin:$PATH"
cd "$work" || exit 1
failures=0

# The site: mkdocs build --strict fails on a broken link, a page missing from the nav's
# files, or anything else mkdocs warns about.
if command -v mkdocs > /dev/null 2>&1; then
  if mkdocs build --strict -f docs/mkdocs.yml -d "$work/.site" > .mkdocs.log 2>&1; then
    echo "mkdocs build --strict -f docs/mkdocs.yml: OK"
  else
    cat .mkdocs.log
    echo "  -> FAILED: mkdocs build --strict -f docs/mkdocs.yml"
    failures=$((failures + 1))
  fi
else
  echo "  -> FAILED: mkdocs is not installed; scripts/install-deps installs it (apt-get install mkdocs)"
  failures=$((failures + 1))
fi

# The pages: README.md, then the nav's pages in nav order. A page the nav leaves out would
# keep its commands from running: it is an error.
docs_dir=docs/$(sed -n 's/^docs_dir: *\([^ #]*\).*/\1/p' docs/mkdocs.yml)
pages=(README.md)
mapfile -t nav < <(sed -n '/^nav:/,$p' docs/mkdocs.yml | grep -oE '[A-Za-z0-9_./-]+\.md')
for p in "${nav[@]}"; do pages+=("$docs_dir/$p"); done
while IFS= read -r f; do
  if [[ " ${pages[*]} " != *" $f "* ]]; then
    echo "  -> FAILED: $f is not in the nav of docs/mkdocs.yml (its examples would not run)"
    failures=$((failures + 1))
  fi
done < <(find "$docs_dir" -name '*.md' | sort)

# The commands of one page, continuation lines joined, in page order.
page_commands() {
  awk '
    /^```/ { inblock = !inblock; next }
    inblock && /^\$ / { cmd = substr($0, 3); while (cmd ~ /\\$/ && (getline line) > 0) cmd = substr(cmd, 1, length(cmd) - 1) " " line; print cmd }
  ' "$1"
}

total=0
server=""
for page in "${pages[@]}"; do
  [[ -f "$page" ]] || { echo "  -> FAILED: $page does not exist"; failures=$((failures + 1)); continue; }
  mapfile -t commands < <(page_commands "$page")
  (( ${#commands[@]} > 0 )) || continue
  echo "=== $page: ${#commands[@]} command(s)"
  total=$((total + ${#commands[@]}))
  for cmd in "${commands[@]}"; do
    echo "\$ $cmd"
    if [[ "$cmd" == *"&" ]]; then            # a server for the next commands
      eval "${cmd% &*} > .bg.log 2>&1 &"
      server=$!
      for _ in $(seq 1 100); do grep -q listening .bg.log 2> /dev/null && break; sleep 0.05; done
      continue
    fi
    if [[ "$cmd" == kill* ]]; then           # ends that server
      # By its pid, not the job spec the page shows: a job table without job control has
      # been seen to leave `wait` waiting for ever (twice, beside another build).
      eval "${cmd//%1/$server}" || { echo "  -> FAILED"; failures=$((failures + 1)); }
      for _ in $(seq 1 400); do kill -0 "$server" 2> /dev/null || break; sleep 0.05; done
      if kill -0 "$server" 2> /dev/null; then
        echo "  -> FAILED: the server did not end within 20 s of the signal ($(grep -E 'SigPnd|SigCgt' /proc/$server/status | tr '\n' ' '))"
        kill -9 "$server"
        failures=$((failures + 1))
      fi
      wait "$server" 2> /dev/null
      server=""
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
    if [[ " $expected " != *" $status "* ]] || grep -qE "terminate called|Sanitizer|runtime error:" <<< "$out"; then
      echo "  -> FAILED: exit status $status (expected ${expected// / or })"
      failures=$((failures + 1))
    fi
  done
  if [[ -n "$server" ]]; then                # a page ends the servers it starts
    echo "  -> FAILED: $page leaves a server running (its \`kill -INT %1\` is missing)"
    kill -9 "$server" 2> /dev/null
    wait "$server" 2> /dev/null
    server=""
    failures=$((failures + 1))
  fi
done
(( total >= 50 )) || { echo "  -> FAILED: found only $total commands in README.md and the manual"; failures=$((failures + 1)); }
echo "$total command(s) in README.md and ${#nav[@]} page(s) of the manual, $failures failed"
(( failures == 0 ))
