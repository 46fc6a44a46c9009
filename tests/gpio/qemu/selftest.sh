#!/usr/bin/env bash
# Self-test of run-in-gpio-sim.sh: boots the gpio-sim guest three times and checks
#   1. the chip (label plcfi-sim, 8 named lines), an output seen in sim_gpio4/value
#      through gpioset, an input driven by sim_gpio0/pull through gpioget: exit 0;
#   2. the same checks with one deliberately wrong expectation: the failure must
#      come out on the host as a failure (exit 1), never as a pass;
#   3. a test exiting with 3 (after checking its arguments arrived intact) makes
#      the harness exit with 3.
# Exit 0 when all three behave, 1 otherwise, 77 when the harness skips.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
harness=$here/run-in-gpio-sim.sh
guest=$here/selftest-guest.sh

tools=()
for t in gpiodetect gpioinfo gpioset gpioget; do
  p=$(command -v "$t" 2>/dev/null) || { echo "SKIPPED: $t not found (Debian package gpiod)"; exit 77; }
  tools+=("$(readlink -f "$p")")
done
PLCFI_GPIO_QEMU_FILES=$(IFS=:; echo "${tools[*]}")
export PLCFI_GPIO_QEMU_FILES

passed=0
failed=0
log=$(mktemp "${TMPDIR:-/tmp}/plcfi-gpio-selftest.XXXXXX")
trap 'rm -f "$log"' EXIT

# run NAME WANT_RC [GREP_PATTERN] -- ARGS...: the harness must exit WANT_RC and, if a
# pattern is given, its output must contain it.
run() {
  local name=$1 want=$2 pattern=$3 rc start
  shift 4
  echo "=== selftest: $name (want exit $want)"
  start=$SECONDS
  set +e
  "$harness" "$@" 2>&1 | tee "$log"
  rc=${PIPESTATUS[0]}
  set -e
  if [[ $rc -eq 77 ]]; then
    echo "selftest: the harness skipped; nothing was tested"
    exit 77
  fi
  if [[ $rc -ne $want ]]; then
    echo "selftest: FAIL: $name: harness exited $rc, want $want ($((SECONDS - start)) s)"
    failed=$((failed + 1))
  elif [[ -n $pattern ]] && ! grep -q -- "$pattern" "$log"; then
    echo "selftest: FAIL: $name: output lacks '$pattern' ($((SECONDS - start)) s)"
    failed=$((failed + 1))
  else
    echo "selftest: ok: $name ($((SECONDS - start)) s)"
    passed=$((passed + 1))
  fi
}

run "gpio-sim chip, output and input through the gpiod tools" 0 \
  "selftest-guest: all checks passed" -- "$guest" check
run "a wrong expectation fails on the host" 1 \
  "FAIL: gpioget line 0 with pull-up: want '0', got '1'" -- "$guest" check-wrong
# shellcheck disable=SC2016  # a literal $HOME must arrive unexpanded
run "the test's exit code 3 comes out as 3" 3 \
  "arguments intact; exiting with 3" -- "$guest" exit-code 3 "a b" "it's" "" '$HOME'

echo "selftest: $passed passed, $failed failed"
[[ $failed -eq 0 ]]
