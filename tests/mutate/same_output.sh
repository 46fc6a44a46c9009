#!/bin/sh
# plcfi mutate gives the same result however it is run: --jobs 2 writes the journal and
# the report of --jobs 1 byte for byte, and the shards 0/2 and 1/2 hold exactly the
# single run's mutant lines, each once, under headers that name their shard; plcfi merge
# combines them into the single run's journal.
# usage: same_output.sh PLCFI SOURCE_DIR WORK_DIR
set -eu
plcfi=$1
src=$2
work=$3/mutate-same
rm -rf "$work"
mkdir -p "$work"
run() {
  "$plcfi" mutate "$src/faults/campaigns/stamping/campaign.yaml" --program "$src/st_programs/stamping/stamping_fixed.st" "$@"
}
run --out "$work/one" > "$work/one.txt"
run --jobs 2 --out "$work/two" > "$work/two.txt"
run --shard 0/2 --out "$work/s0" > /dev/null
run --shard 1/2 --jobs 2 --out "$work/s1" > /dev/null
cmp "$work/one/mutants.jsonl" "$work/two/mutants.jsonl"
sed "s#$work/two#$work/one#" "$work/two.txt" | cmp - "$work/one.txt"
grep -q '"shard":"0/2"' "$work/s0/mutants.jsonl"
grep -q '"shard":"1/2"' "$work/s1/mutants.jsonl"
grep -q '"shard":null' "$work/one/mutants.jsonl"
# The shards' mutant lines, ordered by index, are the single run's.
awk 'FNR > 1' "$work/s0/mutants.jsonl" "$work/s1/mutants.jsonl" | sort -t: -k2,2n > "$work/shards.lines"
tail -n +2 "$work/one/mutants.jsonl" > "$work/one.lines"
cmp "$work/shards.lines" "$work/one.lines"
# plcfi merge combines the shard journals into the single run's, byte for byte.
"$plcfi" merge --out "$work/merged" "$work/s0/mutants.jsonl" "$work/s1/mutants.jsonl" > "$work/merge.txt"
cmp "$work/one/mutants.jsonl" "$work/merged/mutants.jsonl"
grep -q "score" "$work/merge.txt"
n=$(wc -l < "$work/one.lines")
test "$n" -gt 20
echo "same output: $n mutants"
