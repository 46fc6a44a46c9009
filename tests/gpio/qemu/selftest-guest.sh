#!/bin/sh
# Runs INSIDE the gpio-sim guest (busybox sh), started by selftest.sh through
# run-in-gpio-sim.sh as the test binary. Uses the Debian gpiod tools (libgpiod 1.6)
# copied in through PLCFI_GPIO_QEMU_FILES.
#
#   selftest-guest.sh check          all checks; exit 0 when every one passes
#   selftest-guest.sh check-wrong    same, with one deliberately wrong expectation
#                                    (pull-up must read 0): must exit 1
#   selftest-guest.sh exit-code N ARGS...
#                                    exit N if ARGS arrived intact ("a b", "it's",
#                                    "", "$HOME"), 99 if not
set -u

failures=0
ok() { echo "selftest-guest: ok: $*"; }
bad() { echo "selftest-guest: FAIL: $*"; failures=$((failures + 1)); }
expect() {  # expect WHAT WANT GOT
  if [ "$2" = "$3" ]; then ok "$1 = '$3'"; else bad "$1: want '$2', got '$3'"; fi
}

mode=${1:-check}
if [ "$mode" = exit-code ]; then
  code=$2
  shift 2
  # shellcheck disable=SC2016  # a literal $HOME: the guest must not expand it
  if [ $# -eq 4 ] && [ "$1" = "a b" ] && [ "$2" = "it's" ] && [ -z "$3" ] && [ "$4" = '$HOME' ]; then
    echo "selftest-guest: arguments intact; exiting with $code"
    exit "$code"
  fi
  echo "selftest-guest: arguments damaged: $# [$*]"
  exit 99
fi

pullup_want=1
[ "$mode" = check-wrong ] && pullup_want=0   # deliberately wrong: must be caught

chip=${PLCFI_SIM_CHIP:?PLCFI_SIM_CHIP not set}
sysfs=${PLCFI_SIM_SYSFS:?PLCFI_SIM_SYSFS not set}
expect "PLCFI_SIM_LABEL" plcfi-sim "${PLCFI_SIM_LABEL:-}"
expect "/dev/$chip is a character device" yes "$([ -c "/dev/$chip" ] && echo yes || echo no)"

# The chip: label plcfi-sim, 8 lines, named in0..in3, out0..out3.
detect=$(gpiodetect)
echo "$detect"
expect "gpiodetect line of $chip" "$chip [plcfi-sim] (8 lines)" "$(echo "$detect" | grep "^$chip ")"
info=$(gpioinfo "$chip")
echo "$info"
expect "gpioinfo header" "$chip - 8 lines:" "$(echo "$info" | head -n1)"
i=0
for name in in0 in1 in2 in3 out0 out1 out2 out3; do
  got=$(echo "$info" | sed -n "s/^[[:space:]]*line[[:space:]]*$i:[[:space:]]*\"\([^\"]*\)\".*/\1/p")
  expect "name of line $i" "$name" "$got"
  i=$((i + 1))
done

# An output: gpioset on line 4 (out0) shows as 1 in sim_gpio4/value while held.
expect "sim_gpio4/value before gpioset" 0 "$(cat "$sysfs/sim_gpio4/value")"
gpioset --mode=signal "$chip" 4=1 &
setter=$!
n=0
while [ "$(cat "$sysfs/sim_gpio4/value")" != 1 ] && [ $n -lt 50 ]; do sleep 0.1; n=$((n + 1)); done
expect "sim_gpio4/value while gpioset holds 4=1" 1 "$(cat "$sysfs/sim_gpio4/value")"
kill "$setter"
wait "$setter" 2>/dev/null
# Released, the simulated line falls back to its pull (down).
expect "sim_gpio4/value after gpioset released it" 0 "$(cat "$sysfs/sim_gpio4/value")"

# An input: the pull written to sim_gpio0/pull is what gpioget reads on line 0 (in0).
echo pull-up > "$sysfs/sim_gpio0/pull"
expect "gpioget line 0 with pull-up" "$pullup_want" "$(gpioget "$chip" 0)"
echo pull-down > "$sysfs/sim_gpio0/pull"
expect "gpioget line 0 with pull-down" 0 "$(gpioget "$chip" 0)"

if [ "$failures" -eq 0 ]; then
  echo "selftest-guest: all checks passed"
  exit 0
fi
echo "selftest-guest: $failures check(s) failed"
exit 1
