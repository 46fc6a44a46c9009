#!/usr/bin/env bash
# A campaign split between processes writes what one process writes: --jobs N, and
# --shard K/N run through GNU parallel and combined by `plcfi merge`, give the single
# run's journal byte for byte, and the same traces. Covered: the stamping campaign on both
# programs, campaigns ended by the time budget at several points (a share cannot know the
# budget, the merge must cut where the single run stops), a program that stops outside a
# test, a resumed journal, and the errors of bad shard sets.
# usage: parallel.sh PLCFI SOURCE_DIR
set -euo pipefail
plcfi=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_parallel_XXXXXX")
trap 'rm -rf "$work"' EXIT
command -v parallel >/dev/null || { echo "GNU parallel is not installed (scripts/install-deps installs it)"; exit 1; }

fail() { echo "FAIL: $*"; exit 1; }
same() {  # REF OTHER LABEL: journal and traces identical
  cmp "$1/results.jsonl" "$2/results.jsonl" || { diff "$1/results.jsonl" "$2/results.jsonl" | head -5; fail "$3: journals differ"; }
  diff <(cd "$1" && ls | grep '\.vcd$' || true) <(cd "$2" && ls | grep '\.vcd$' || true) || fail "$3: not the same traces"
  for f in "$1"/*.vcd; do
    [[ -e $f ]] || continue
    cmp -s "$f" "$2/$(basename "$f")" || fail "$3: $(basename "$f") differs"
  done
}
campaign() {  # exit 0 or 1 (a FAIL verdict) are results; 2 is not
  local s=0
  "$plcfi" campaign "$@" --quiet > "$work/last.txt" 2>&1 || s=$?
  [[ $s -le 1 ]] || { cat "$work/last.txt"; fail "plcfi campaign $* exited $s"; }
}
check() {  # LABEL CAMPAIGN [ARGS...]: single run vs --jobs 2, --jobs 3 and 3 shards + merge
  local label=$1
  shift
  local d="$work/$label"
  campaign "$@" --out "$d/single"
  campaign "$@" --out "$d/jobs2" --jobs 2
  same "$d/single" "$d/jobs2" "$label --jobs 2"
  campaign "$@" --out "$d/jobs3" --jobs 3
  same "$d/single" "$d/jobs3" "$label --jobs 3"
  # The shards as a job engine runs them: GNU parallel, each in its own folder.
  parallel --halt now,fail=1 "'$plcfi'" campaign "$@" --shard {}/3 --out "$d/shard{}" --quiet ::: 0 1 2 > "$d/parallel.txt" ||
    { cat "$d/parallel.txt"; fail "$label: a shard failed"; }
  local s=0
  "$plcfi" merge --out "$d/merged" "$d"/shard*/shard-*-of-3.jsonl > "$d/merge.txt" || s=$?
  [[ $s -le 1 ]] || { cat "$d/merge.txt"; fail "$label: merge exited $s"; }
  cmp "$d/single/results.jsonl" "$d/merged/results.jsonl" || fail "$label: merged journal differs"
  # The merge copies the campaign's traces from the shard folders: the merged folder is
  # the single run's.
  same "$d/single" "$d/merged" "$label shards"
  echo "ok: $label: $(($(wc -l < "$d/single/results.jsonl") - 1)) verdicts; $(tail -n 1 "$d/merge.txt" >/dev/null; grep -o 'ended: .*' "$d/merge.txt")"
}

stamping=$src/faults/campaigns/stamping
check stamping "$stamping/campaign.yaml"
check fixed "$stamping/campaign.yaml" --program "$src/st_programs/stamping/stamping_fixed.st"

# Copies of the campaign with another budget or program, in the work folder.
copy_campaign() {  # NAME BUDGET PROGRAM
  mkdir -p "$work/$1"
  cp "$stamping"/{tsd.yaml,fmea.csv,fault_classes.yaml} "$work/$1/"
  sed -e "s#^  - \.\./\.\./\.\./st_programs/stamping/stamping\.st#  - $3#" -e "s/^budget: .*/budget: $2/" \
    "$stamping/campaign.yaml" > "$work/$1/campaign.yaml"
  grep -q "^budget: $2" "$work/$1/campaign.yaml" || fail "could not set the budget"
}
for budget in 1s 2500ms 4s 7s 30s; do
  copy_campaign "budget_$budget" "$budget" "$src/st_programs/stamping/stamping.st"
  check "budget_$budget" "$work/budget_$budget/campaign.yaml"
  grep -q "time budget of" "$work/budget_$budget/merge.txt" || [[ $budget == 30s ]] ||
    fail "budget $budget: the campaign did not end on its budget"
done

# A program that traps 2.5 s after each restart: the campaign ends when a run's search
# meets the trap before any untested precondition.
sed -e 's/^  pressureFault : BOOL;.*$/&\n  trapScans : DINT;\n  trapZero : DINT;\n  trapX : DINT;/' \
    -e 's/^(\* ===== 1\. push-buttons.*$/trapScans := trapScans + 1; IF trapScans > 250 THEN trapX := 10 \/ trapZero; END_IF;\n&/' \
    "$src/st_programs/stamping/stamping.st" > "$work/trapping.st"
grep -q 'trapX := 10' "$work/trapping.st" || fail "could not make the trapping program"
copy_campaign trapping 1h "$work/trapping.st"
check trapping "$work/trapping/campaign.yaml"
grep -q "the program stopped outside a test" "$work/trapping/merge.txt" || fail "trapping: not ended by the trap"

# A resumed journal finished by two workers.
for keep in 2 5; do
  mkdir -p "$work/resume$keep"
  head -n "$keep" "$work/stamping/single/results.jsonl" > "$work/resume$keep/results.jsonl"
  campaign "$stamping/campaign.yaml" --out "$work/resume$keep" --resume --jobs 2
  cmp "$work/stamping/single/results.jsonl" "$work/resume$keep/results.jsonl" || fail "resume after $((keep - 1)) verdicts differs"
done
echo "ok: resumed journals finished by --jobs 2"

# Bad shard sets: precise errors, exit 2.
d=$work/stamping
expect_error() {  # REGEX ARGS...
  local re=$1 s=0
  shift
  "$plcfi" "$@" > "$work/err.txt" 2>&1 || s=$?
  [[ $s -eq 2 ]] || { cat "$work/err.txt"; fail "$*: exit $s, expected 2"; }
  grep -Eq -e "$re" "$work/err.txt" || { cat "$work/err.txt"; fail "$*: no '$re'"; }
}
expect_error "shard 2/3 is missing" merge --out "$work/m1" "$d"/shard0/shard-0-of-3.jsonl "$d"/shard1/shard-1-of-3.jsonl
expect_error "shard 0/3 given twice" merge --out "$work/m2" "$d"/shard0/shard-0-of-3.jsonl "$d"/shard0/shard-0-of-3.jsonl
expect_error "another campaign, program or share count" merge --out "$work/m3" "$d"/shard0/shard-0-of-3.jsonl \
  "$work"/fixed/shard1/shard-1-of-3.jsonl "$d"/shard2/shard-2-of-3.jsonl
head -n 3 "$d"/shard1/shard-1-of-3.jsonl > "$work/cut.jsonl"
expect_error "cut.jsonl: incomplete: no closing line" merge --out "$work/m4" "$d"/shard0/shard-0-of-3.jsonl "$work/cut.jsonl" \
  "$d"/shard2/shard-2-of-3.jsonl
expect_error "results.jsonl:1:1: not a plcfi campaign shard file" merge --out "$work/m5" "$d/single/results.jsonl"
# Hostile inputs: a folder, an endless file, a header with a zero tick and no cases.
expect_error "is a directory" merge --out "$work/m6" "$work"
expect_error "/dev/zero: is larger than" merge --out "$work/m7" /dev/zero
printf '%s\n%s\n' '{"journal":"plcfi campaign shard","shard":0,"shards":1,"header":"x","case_ids":[],"budget_ns":-5,"tick_ns":0}' \
  '{"complete":true}' > "$work/odd.jsonl"
expect_error "odd.jsonl:1:1: the shard header lacks the campaign's limits" merge --out "$work/m8" "$work/odd.jsonl"
expect_error "not K/N" campaign "$stamping/campaign.yaml" --shard -1/2
expect_error "K must be 0..2" campaign "$stamping/campaign.yaml" --shard 3/3
expect_error "not K/N" campaign "$stamping/campaign.yaml" --shard 1
sed 's/^restart: cold/restart: warm/' "$work/budget_1s/campaign.yaml" > "$work/budget_1s/campaign_warm.yaml"
expect_error "restart: warm carries each run" campaign "$work/budget_1s/campaign_warm.yaml" --jobs 2
expect_error "--shard runs one share" campaign "$stamping/campaign.yaml" --shard 0/2 --resume
echo "ok: bad shard sets and options"
