#!/usr/bin/env bash
# kill -9 in the middle of a campaign, then --resume: the journal ends up identical to the
# one of an uninterrupted run (same verdicts, no case run twice, none missing).
# usage: resume_after_kill.sh PLCFI SOURCE_DIR
set -euo pipefail
plcfi=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_resume_XXXXXX")
trap 'rm -rf "$work"' EXIT

# A slow copy of the stamping campaign: the program burns CPU in every scan, so a
# campaign takes seconds and can be killed between two verdicts.
cp "$src"/faults/campaigns/stamping/{campaign.yaml,tsd.yaml,fmea.csv,fault_classes.yaml} "$work"/
sed -e 's/^  pressureFault : BOOL;.*$/&\n  busy : DINT;\n  busySum : LINT;/' \
    -e 's/^(\* ===== 1\. push-buttons.*$/FOR busy := 1 TO 40000 DO busySum := busySum + busy; END_FOR;\n&/' \
    "$src"/st_programs/stamping/stamping.st > "$work"/slow.st
grep -q 'FOR busy' "$work"/slow.st || { echo "could not make the slow program"; exit 1; }
sed -i -e "s#^  - \.\./\.\./\.\./st_programs/stamping/stamping\.st#  - $work/slow.st#" "$work"/campaign.yaml
grep -q "$work/slow.st" "$work"/campaign.yaml || { echo "could not point the campaign at the slow program"; exit 1; }

# Reference: the uninterrupted campaign.
"$plcfi" campaign "$work"/campaign.yaml --out "$work"/full --quiet --no-vcd > "$work"/full.txt || test $? -eq 1
verdicts=$(($(wc -l < "$work"/full/results.jsonl) - 1))
echo "uninterrupted: $verdicts verdicts"
test "$verdicts" -ge 5

# Killed after its third verdict.
"$plcfi" campaign "$work"/campaign.yaml --out "$work"/part --quiet --no-vcd > "$work"/part.txt 2>&1 &
pid=$!
for _ in $(seq 1 3000); do
  if [[ -f "$work"/part/results.jsonl ]] && (( $(wc -l < "$work"/part/results.jsonl) >= 4 )); then break; fi
  sleep 0.01
done
kill -9 "$pid"
wait "$pid" 2>/dev/null || true
before=$(($(wc -l < "$work"/part/results.jsonl) - 1))
echo "killed after $before verdicts"
if (( before >= verdicts )); then echo "the campaign finished before the kill; make the program slower"; exit 1; fi

# Resume: finishes the campaign without running a finished case again.
"$plcfi" campaign "$work"/campaign.yaml --out "$work"/part --resume --quiet --no-vcd > "$work"/resume.txt || test $? -eq 1
grep -q "resumed: $before verdict(s)" "$work"/resume.txt
cmp "$work"/full/results.jsonl "$work"/part/results.jsonl
# The summaries agree from the table on.
diff <(sed -n '/^case /,/NOT REACHED$/p' "$work"/full.txt) <(sed -n '/^case /,/NOT REACHED$/p' "$work"/resume.txt)
echo "resume OK: identical journal after kill -9 at $before of $verdicts verdicts"
