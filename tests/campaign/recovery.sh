#!/usr/bin/env bash
# The fault classes' recovery (faults/campaigns/stamping/fault_classes.yaml): after the
# reaction the fault is withdrawn, the alarm must stay latched, the test presses
# AckButton and the module must clear. The fixed program recovers in every case; a
# program whose acknowledgement does not clear the stop, and one whose alarm does not
# latch, FAIL with the reason, though both react to every fault in time.
# usage: recovery.sh PLCFI SOURCE_DIR
set -euo pipefail
plcfi=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_recovery_XXXXXX")
trap 'rm -rf "$work"' EXIT
campaign=$src/faults/campaigns/stamping/campaign.yaml
fixed=$src/st_programs/stamping/stamping_fixed.st
fail() { echo "FAIL: $*"; exit 1; }
run() {  # NAME PROGRAM EXPECTED_STATUS
  local s=0
  "$plcfi" campaign "$campaign" --program "$2" --out "$work/$1" --quiet --no-vcd > "$work/$1.txt" 2>&1 || s=$?
  [[ $s -eq $3 ]] || { cat "$work/$1.txt"; fail "$1: exit $s, expected $3"; }
}

run fixed "$fixed" 0
n=$(grep -c 'recovered [0-9]* ms after pressing AckButton (%IX0.7)' "$work/fixed/results.jsonl")
[[ $n -eq 11 ]] || fail "fixed: $n of 11 PASS reasons say the module recovered"

# The acknowledgement clears the alarms but not the stop.
sed -e '/^  E_Step#Alarm:/,/^END_CASE/ s/^      gStampStop := FALSE;$/      (* gStampStop stays *)/' "$fixed" > "$work/no_clear.st"
grep -q 'gStampStop stays' "$work/no_clear.st" || fail "could not make no_clear.st"
run no_clear "$work/no_clear.st" 1
grep -q 'then not recovered: gStampStop still TRUE 1 s after pressing AckButton (%IX0.7)' "$work/no_clear.txt" ||
  { cat "$work/no_clear.txt"; fail "no_clear: no 'not recovered' reason"; }

# The cylinder alarm follows its cause instead of latching.
sed -e 's/^IF stampCyl.Error OR pressureFault THEN$/gStampCylError := stampCyl.Error OR pressureFault;\nIF FALSE THEN/' \
  -e 's/^  Error := TRUE;$/  Error := TRUE;\nELSIF NOT Supervise OR (Extend AND AtExtended) OR (NOT Extend AND AtRetracted) THEN\n  Error := FALSE;/' \
  "$fixed" > "$work/no_latch.st"
grep -q 'gStampCylError := stampCyl.Error OR pressureFault;' "$work/no_latch.st" || fail "could not make no_latch.st"
run no_latch "$work/no_latch.st" 1
grep -q 'then gStampCylError cleared without acknowledgement' "$work/no_latch.txt" ||
  { cat "$work/no_latch.txt"; fail "no_latch: no 'cleared without acknowledgement' reason"; }
echo "ok: the fixed program recovers in all 11 executions; a stop the acknowledgement does not clear and an alarm that does not latch FAIL"
