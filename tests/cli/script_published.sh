#!/bin/sh
# The published CPTest+ result end to end, offline: eleven runs of the published script
# pass on the correct bead dispenser, a broken link makes the twelfth Undecidable with
# m_ci = 1 (shown newest first by plcfi history); the buggy program fails with a healthy
# link, and after that change of its POU a broken link excuses nothing (m_ci = 0).
#   script_published.sh PLCFI SOURCE_DIR WORK_DIR
set -eu
plcfi=$1; src=$2; work=$3
dir=$src/st_programs/bead_dispenser
hist=$work/history.sqlite
rm -f "$hist" "$hist-wal" "$hist-shm"
run() { "$plcfi" script "$@" "$dir/tests/pass_one_ball.cpt" --plant bead_dispenser --history "$hist"; }
i=1
while [ $i -le 11 ]; do
  run "$dir/bead_dispenser.st" > "$work/run$i.txt"
  grep -q "Passed" "$work/run$i.txt" || { cat "$work/run$i.txt"; echo "run $i did not pass"; exit 1; }
  i=$((i + 1))
done
set +e
run "$dir/bead_dispenser.st" --link-fault 0ms:2s --junit "$work/junit12.xml" > "$work/run12.txt"; s12=$?
run "$dir/bead_dispenser_buggy.st" > "$work/run13.txt"; s13=$?
run "$dir/bead_dispenser_buggy.st" --link-fault 0ms:2s > "$work/run14.txt"; s14=$?
set -e
cat "$work/run12.txt" "$work/run13.txt" "$work/run14.txt"
[ $s12 -eq 0 ] || { echo "run 12: exit $s12, expected 0 (undecidable is no failure)"; exit 1; }
grep -q "Undecidable .*p_lst 10 of the latest 10" "$work/run12.txt"
grep -q "possible external problem, factor = 1$" "$work/run12.txt"
grep -q '<skipped message="undecidable: ' "$work/junit12.xml"
grep -q '<property name="m_ci" value="1"/>' "$work/junit12.xml"
grep -q '<testcase classname="[^"]*/tests/pass_one_ball.cpt" name="pass_one_ball" time="1.500000"' "$work/junit12.xml"
[ $s13 -eq 1 ] || { echo "run 13: exit $s13, expected 1"; exit 1; }
grep -q "Failed .*POUs DISPENSER; p_lst 0 of the latest 10" "$work/run13.txt"
grep -q "IS_BEAD_SEEN is FALSE (no communication error)" "$work/run13.txt"
[ $s14 -eq 1 ] || { echo "run 14: exit $s14, expected 1"; exit 1; }
grep -q "it never held; c = 101, m_ci = 0" "$work/run14.txt"
"$plcfi" history pass_one_ball --history "$hist" > "$work/history.txt"
cat "$work/history.txt"
# Newest first: the two failures of the buggy program, the undecidable run, eleven passes.
sed -n 2p "$work/history.txt" | grep -q "^pass_one_ball  Failed .* 0 .* 101 "
sed -n 3p "$work/history.txt" | grep -q "^pass_one_ball  Failed "
sed -n 4p "$work/history.txt" | grep -q "^pass_one_ball  Undecidable .* 1 .* 101  possible external problem, factor = 1$"
[ "$(grep -c "  Passed " "$work/history.txt")" -eq 11 ]
[ "$(wc -l < "$work/history.txt")" -eq 15 ]
echo "published result reproduced"
