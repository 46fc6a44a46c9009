#!/bin/sh
# Coverage exports end to end (plcfi test/sim/campaign --lcov/--cobertura): genhtml renders
# the tracefile without a warning, the Cobertura file is well-formed XML with the same
# numbers, --native writes the same files, and the stamping campaign covers supervision
# branches that only faults reach (a fault-free sim leaves them untaken).
# Usage: coverage_export.sh PLCFI SOURCE_DIR WORK_DIR
set -eu
plcfi=$1
src=$2
work=$3
st=$src/st_programs/stamping
rm -rf "$work"
mkdir -p "$work"
cd "$work"
export SOURCE_DATE_EPOCH=1700000000
fail() { echo "FAIL: $*"; exit 1; }

# plcfi test: the unit tests of the stamping program.
"$plcfi" test "$st/stamping.st" "$st/tests/test_stamping.st" --lcov test.info --cobertura test.xml >test.out ||
  fail "plcfi test exited $?"
grep -q "^SF:$st/stamping.st\$" test.info || fail "no SF record for stamping.st"
grep -q "test_stamping" test.info test.xml && fail "the test file is reported as program"
genhtml --branch-coverage -q -o html test.info >genhtml.log 2>&1 || { cat genhtml.log; fail "genhtml exited $?"; }
[ -s genhtml.log ] && { cat genhtml.log; fail "genhtml wrote warnings"; }
# genhtml's top index lists the folder; its index lists the file, whose page shows the source.
grep -q "$(basename "$st")/index.html" html/index.html || fail "index.html does not list the folder of stamping.st"
grep -q "stamping.st.gcov.html" "html/$(basename "$st")/index.html" || fail "the folder's index does not name stamping.st"
grep -q "gStampCylError" "html/$(basename "$st")/stamping.st.gcov.html" || fail "the page of stamping.st shows no source"
xmllint --noout test.xml || fail "Cobertura file is not well-formed"
/usr/bin/python3 "$src/tests/cli/coverage_totals.py" test.info test.xml || fail "lcov and Cobertura disagree"

# The native tier records the same branches.
"$plcfi" test "$st/stamping.st" "$st/tests/test_stamping.st" --native --lcov native.info --cobertura native.xml >native.out ||
  fail "plcfi test --native exited $?"
cmp test.info native.info || fail "--native: another tracefile"
cmp test.xml native.xml || fail "--native: another Cobertura file"

# An output that cannot be written: exit 2 before anything runs.
set +e
"$plcfi" test "$st/stamping.st" "$st/tests/test_stamping.st" --lcov "$work/no-such-dir/x.info" >bad.out 2>&1
status=$?
set -e
[ $status -eq 2 ] || fail "unwritable --lcov: exit $status, not 2"
grep -q "plcfi test: --lcov $work/no-such-dir/x.info: cannot write" bad.out || { cat bad.out; fail "no message"; }

# The campaign against a fault-free simulation of the same program.
if_line=$(grep -n "IF stampCyl.Error OR pressureFault THEN" "$st/stamping.st" | cut -d: -f1)
[ -n "$if_line" ] || fail "stamping.st has no supervision IF"
set_line=$((if_line + 1))
sed -n "${set_line}p" "$st/stamping.st" | grep -q "gStampCylError := TRUE" || fail "unexpected line after the IF"
"$plcfi" sim "$st/stamping.st" --duration 2m --lcov sim.info >sim.out || fail "plcfi sim exited $?"
set +e
"$plcfi" campaign "$src/faults/campaigns/stamping/campaign.yaml" --out camp --quiet --no-vcd --lcov campaign.info \
  --cobertura campaign.xml >campaign.out 2>&1
status=$?
set -e
[ $status -le 1 ] || { cat campaign.out; fail "plcfi campaign exited $status"; }
genhtml --branch-coverage -q -o html-campaign campaign.info >genhtml2.log 2>&1 || { cat genhtml2.log; fail "genhtml (campaign)"; }
[ -s genhtml2.log ] && { cat genhtml2.log; fail "genhtml wrote warnings (campaign)"; }
/usr/bin/python3 "$src/tests/cli/coverage_totals.py" campaign.info campaign.xml || fail "campaign: lcov and Cobertura disagree"
grep -q "^BRDA:$if_line,0,0,[1-9]" campaign.info || fail "campaign did not take the IF at line $if_line"
grep -q "^DA:$set_line,[1-9]" campaign.info || fail "campaign did not run line $set_line"
grep -q "^BRDA:$if_line,0,0,0\$" sim.info || fail "fault-free sim took the IF at line $if_line"
grep -q "^DA:$set_line,0\$" sim.info || fail "fault-free sim ran line $set_line"
grep -q "<monitors\|<preconditions\|stdlib" campaign.info campaign.xml && fail "generated units or the library reported"

# Counting changes nothing the campaign records: the journal is the same without it.
set +e
"$plcfi" campaign "$src/faults/campaigns/stamping/campaign.yaml" --out camp-plain --quiet --no-vcd >campaign-plain.out 2>&1
set -e
cmp camp/results.jsonl camp-plain/results.jsonl || fail "the journal differs with coverage counting"
echo "coverage exports OK: $(tail -1 campaign.out)"
