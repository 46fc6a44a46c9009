#!/usr/bin/env bash
# The three omissions of issue 15, each a variant of stamping_fixed.st with ONE gap in its
# error handling: the FMEA-only campaign passes on every one of them, the campaign with
# --explore fails, and its FMEA suggestions hold a row for the sensor (or valve) whose
# failure the omission hides, a row that stamping_fixed.st's own exploration does not have.
# usage: run.sh PLCFI SOURCE_DIR
set -euo pipefail
plcfi=$1
src=$2
here="$src/tests/campaign/omissions"
campaign="$src/faults/campaigns/stamping/campaign.yaml"
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_omissions_XXXXXX")
trap 'rm -rf "$work"' EXIT

fail() { echo "FAILED: $*"; exit 1; }

# run NAME PROGRAM [--explore]: the campaign's exit status in $status, its output in $work/NAME.txt
run() {
  local name=$1 program=$2
  shift 2
  status=0
  "$plcfi" campaign "$campaign" --program "$program" --out "$work/$name" --quiet --no-vcd "$@" > "$work/$name.txt" 2>&1 || status=$?
}

# The rows a program's exploration suggests, without the case id (ids are stable, but the
# comparison is about failures, not numbering).
rows() { tail -n +2 "$work/$1/fmea_suggestions.csv" | cut -d, -f2- | sort; }

# Baseline: stamping_fixed.st. Its exploration finds gaps of its own (see the manual,
# "Exploring beyond the FMEA"); the omissions must add rows to these.
run fixed "$src/st_programs/stamping/stamping_fixed.st" --explore
test "$status" -eq 1 || fail "stamping_fixed.st --explore: exit $status"
rows fixed > "$work/fixed.rows"
grep -q '"explore":true' "$work/fixed/results.jsonl" || fail "no explored case in the journal"

# check VARIANT EXPECTED-ROW-PREFIX: FMEA-only passes, --explore fails with a new row
# starting with EXPECTED (tsd_transition,failure_mode,S,effect...).
check() {
  local variant=$1 expected=$2
  run "$variant-fmea" "$here/$variant.st"
  test "$status" -eq 0 || { cat "$work/$variant-fmea.txt"; fail "$variant: FMEA-only campaign exit $status"; }
  grep -q " 0 FAIL, 0 NOT REACHED" "$work/$variant-fmea.txt" || fail "$variant: FMEA-only campaign not all PASS"
  if grep -q '"explore"' "$work/$variant-fmea/results.jsonl"; then fail "$variant: explored case in an FMEA-only journal"; fi
  test ! -e "$work/$variant-fmea/fmea_suggestions.csv" || fail "$variant: suggestions from an FMEA-only campaign"

  run "$variant-explore" "$here/$variant.st" --explore
  test "$status" -eq 1 || { cat "$work/$variant-explore.txt"; fail "$variant: --explore exit $status, expected 1"; }
  rows "$variant-explore" > "$work/$variant.rows"
  comm -13 "$work/fixed.rows" "$work/$variant.rows" > "$work/$variant.new"
  test -s "$work/$variant.new" || fail "$variant: --explore suggests nothing stamping_fixed.st does not"
  grep -q "^$expected" "$work/$variant.new" || { cat "$work/$variant.new"; fail "$variant: no new suggestion '$expected'"; }
  grep -q "FMEA suggestions: " "$work/$variant-explore.txt" || fail "$variant: no suggestions in the text output"
  echo "$variant: FMEA-only PASS, --explore FAIL; new suggestions:"
  sed 's/^/  /' "$work/$variant.new"
}

# (a) the stamp's end position not supervised in Hold: the stamp valve dropping out, or a
#     StampUp stuck on while the stamp is down, goes unnoticed while the WP is stamped.
check unsupervised_hold 'normal.hold.StampUp,StampUp stuck_at(1),,transition normal.hold.StampUp too early: after 0 ms of its min 1 s'
grep -q '^normal.hold.StampUp,StampDown stuck_off,,transition normal.hold.StampUp too early' "$work/unsupervised_hold.new" || fail "unsupervised_hold: no StampDown row"
# (b) the sensor pair's plausibility weakened: StampUp stuck on while the stamp goes down.
check weak_plausibility 'normal.stamp.StampLowered,StampUp stuck_at(1),,transition normal.hold.StampUp too early: after 0 ms of its min 1 s'
# (c) the slider not supervised on its way back: PosCrane stuck off hangs the module.
check unsupervised_return 'normal.retract.PosCrane,PosCrane stuck_at(0),,transition normal.retract.PosCrane not within 500 ms (to TRUE),found by plcfi campaign --explore,,none,,,1,,PosCrane: stuck_at(0)'
echo "all three omissions found"
