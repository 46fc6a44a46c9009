#!/usr/bin/env bash
# The stamping campaign with its program imported from st_programs/stamping/stamping.xml
# (plcfi campaign --program, the campaign file untouched) gives the verdicts of the run on
# stamping.st: the same executions, paths, verdicts, reasons and times, line for line.
#   usage: same_campaign_verdicts.sh PLCFI SOURCE_DIR OUT_DIR
set -u
plcfi=$1
src=$2
out=$3
campaign=$src/faults/campaigns/stamping/campaign.yaml
rm -rf "$out/st" "$out/xml"
mkdir -p "$out"
"$plcfi" campaign "$campaign" --out "$out/st" --quiet --no-vcd >"$out/st.log" 2>&1
st_status=$?
"$plcfi" campaign "$campaign" --program "$src/st_programs/stamping/stamping.xml" --out "$out/xml" --quiet --no-vcd \
  >"$out/xml.log" 2>&1
xml_status=$?
if [[ $st_status -ne $xml_status ]]; then
  echo "exit status differs: $st_status on stamping.st, $xml_status on stamping.xml"
  cat "$out/xml.log"
  exit 1
fi
# Everything but the branch names, which name the file and line they are in.
verdicts() {
  /usr/bin/python3 -c '
import json, sys
for line in open(sys.argv[1]):
    e = json.loads(line)
    if "verdict" not in e: continue
    print(e["case"], e["path"], e["path_hash"], e["verdict"], e["reason"], e["inject_ns"], e["start_ns"],
          e["reaction_ns"], e["end_ns"], e["latency_ns"], e["scans"], len(e["branches"]))
' "$1"
}
if ! diff <(verdicts "$out/st/results.jsonl") <(verdicts "$out/xml/results.jsonl"); then
  echo "verdicts differ (< stamping.st, > stamping.xml)"
  exit 1
fi
echo "same verdicts: $(verdicts "$out/xml/results.jsonl" | wc -l) execution(s), exit status $xml_status"
grep "execution(s) of" "$out/xml.log"
