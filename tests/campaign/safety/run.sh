#!/usr/bin/env bash
# Safety evidence of the stamping campaign (issue 30), end to end:
#   1. campaign_safety.yaml on the published program, on stamping_fixed.st, and on the
#      fixed one with --explore: safety.json and traceability.csv agree with an independent
#      calculation from the FMEA, the class file and the journal (safety_check.py); the
#      published program's reference-stroke row F3 is undetected, the fixed one has none;
#   2. the summary's "safety evidence" section equals expected/<run>.txt (PLCFI_UPDATE_SNAPSHOTS=1
#      rewrites them);
#   3. JUnit carries the evidence as suite properties;
#   4. --baseline: the published program against the fixed one's run lists the lost PASS, the
#      lower DC and F3 and fails with --fail-on-regression; the fixed run against itself has
#      no change; a longer worst reaction than the baseline's fails only with the flag;
#   5. the checker itself fails on a safety.json with a wrong DC (so the test can fail);
#   6. the campaign without failure rates writes no safety.json and no traceability.csv.
# usage: run.sh PLCFI SOURCE_DIR
set -uo pipefail
plcfi=$1
src=$2
here="$src/tests/campaign/safety"
spec="$src/faults/campaigns/stamping"
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_safety_XXXXXX")
trap 'rm -rf "$work"' EXIT
fail() { echo "FAILED: $*"; exit 1; }
check() { python3 "$src/tests/campaign/safety_check.py" "$work/$1" "$spec/fmea_safety.csv" "$spec/fault_classes_safety.yaml" "${@:2}"; }

# run NAME EXPECTED_STATUS ARGS...: the campaign's output in $work/NAME.txt
run() {
  local name=$1 want=$2
  shift 2
  "$plcfi" campaign "$spec/campaign_safety.yaml" --out "$work/$name" --quiet "$@" >"$work/$name.txt" 2>&1
  local status=$?
  [[ $status -eq $want ]] || { cat "$work/$name.txt"; fail "$name: exit status $status, expected $want"; }
}
# The summary's section, with the output folder written as OUT.
section() { sed -n '/^safety evidence (/,$p' "$work/$1.txt" | sed "s#$work/$1#OUT#g"; }
snapshot() {
  local name=$1 expected="$here/expected/$1.txt"
  if [[ "${PLCFI_UPDATE_SNAPSHOTS:-}" == 1 ]]; then
    section "$name" >"$expected"
    echo "wrote $expected"
    return
  fi
  diff -u "$expected" <(section "$name") || fail "$name: the safety evidence section differs from expected/$name.txt"
}

run published 1 --junit "$work/published.xml"
check published --undetected F3 || fail "published: safety.json disagrees with the independent calculation"
snapshot published
run fixed 0 --program "$src/st_programs/stamping/stamping_fixed.st"
check fixed --undetected "" || fail "fixed: safety.json disagrees with the independent calculation"
snapshot fixed
run explore 1 --program "$src/st_programs/stamping/stamping_fixed.st" --explore --no-vcd
check explore --unassessed || fail "explore: safety.json disagrees with the independent calculation"
snapshot explore

grep -q '<property name="safety.SF_stamp.dc" value="0.8929"/>' "$work/published.xml" || fail "no DC property in JUnit"
grep -q '<property name="safety.SF_stamp.undetected" value="F3"/>' "$work/published.xml" || fail "no undetected property in JUnit"
grep -q '<property name="safety.SF_stamp.margin_ms" value="130"/>' "$work/published.xml" || fail "no margin property in JUnit"

# --baseline OLD_OUT [--fail-on-regression]
run regressed 1 --program "$src/st_programs/stamping/stamping.st" --no-vcd --baseline "$work/fixed" --fail-on-regression
grep -q '^3 change(s) since .*, 3 regression(s)$' "$work/regressed.txt" || { cat "$work/regressed.txt"; fail "regressed: not 3 regressions"; }
for l in 'REGRESSION TC3 path 1: PASS -> FAIL' 'REGRESSION SF_stamp: DC 100.0 % (high) -> 89.3 % (low)' \
         'REGRESSION SF_stamp: row F3 undetected now' 'failing (--fail-on-regression)'; do
  grep -qF "$l" "$work/regressed.txt" || { cat "$work/regressed.txt"; fail "regressed: no line '$l'"; }
done
run same 0 --program "$src/st_programs/stamping/stamping_fixed.st" --no-vcd --baseline "$work/fixed" --fail-on-regression
grep -q "^no change since $work/fixed (baseline)$" "$work/same.txt" || { cat "$work/same.txt"; fail "same: a change against itself"; }
mkdir -p "$work/faster"
python3 - "$work/fixed/safety.json" "$work/faster/safety.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
for f in s["safety_functions"]:
    if f["id"] == "SF_stamp": f["worst_reaction_ms"] = 1000
json.dump(s, open(sys.argv[2], "w"))
PY
run slower 0 --program "$src/st_programs/stamping/stamping_fixed.st" --no-vcd --baseline "$work/faster"
grep -qF 'REGRESSION SF_stamp: worst reaction 1000 ms -> 1870 ms' "$work/slower.txt" || { cat "$work/slower.txt"; fail "slower: no regression of the worst reaction"; }
run slower_fails 1 --program "$src/st_programs/stamping/stamping_fixed.st" --no-vcd --baseline "$work/faster" --fail-on-regression

# The checker must see a wrong number.
sed -i 's/"dc": 0.89[0-9]*/"dc": 0.9/' "$work/published/safety.json"
check published --undetected F3 >"$work/tampered.txt" && fail "safety_check.py accepted a safety.json with a wrong DC"
grep -q "MISMATCH: SF_stamp dc" "$work/tampered.txt" || { cat "$work/tampered.txt"; fail "the checker did not name the wrong DC"; }

"$plcfi" campaign "$spec/campaign.yaml" --out "$work/plain" --quiet --no-vcd >"$work/plain.txt" 2>&1
[[ -e "$work/plain/safety.json" || -e "$work/plain/traceability.csv" ]] && fail "a campaign without failure rates wrote safety evidence"
grep -q "safety evidence" "$work/plain.txt" && fail "a campaign without failure rates printed a safety section"
echo "PASS: safety evidence agrees with the independent calculation (published, fixed, explored)"
