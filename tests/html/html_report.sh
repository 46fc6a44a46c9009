#!/usr/bin/env bash
# End-to-end check of `plcfi campaign --html`: the stamping campaign writes its report, a
# real browser (headless Chromium) renders it to a screenshot without console messages,
# and the rendered DOM holds the verdict table, the waveforms and the TSD.
#   html_report.sh PLCFI CAMPAIGN.yaml OUTDIR
# Exit 0 pass, 1 fail, 77 skipped (no Chromium).
set -uo pipefail
plcfi=$1 campaign=$2 out=$3

chromium=$(command -v chromium || command -v chromium-browser || true)
if [[ -z $chromium ]]; then
  echo "SKIP: chromium is not installed (scripts/install-deps installs it)"
  exit 77
fi
fail() { echo "FAIL: $*"; exit 1; }

rm -rf "$out"
mkdir -p "$out"
# The stamping program as published fails some cases: exit 1 is the expected outcome.
"$plcfi" campaign "$campaign" --out "$out/campaign" --html "$out/report" --quiet >"$out/campaign.txt" 2>&1
status=$?
[[ $status -eq 1 ]] || { cat "$out/campaign.txt"; fail "plcfi campaign exited $status, expected 1"; }
# (A sanitizer report also exits 1: look for one.)
if grep -qE "Sanitizer|runtime error:|terminate called" "$out/campaign.txt"; then cat "$out/campaign.txt"; fail "plcfi crashed or a sanitizer reported"; fi
grep -qx "HTML report: $out/report/index.html" "$out/campaign.txt" || fail "the report's path was not printed"
page=$out/report/index.html
[[ -s $page ]] || fail "$page missing"
# Deterministic: the same campaign again gives the same page, byte for byte.
cp "$page" "$out/first.html"
rm -rf "$out/campaign" "$out/report"
"$plcfi" campaign "$campaign" --out "$out/campaign" --html "$out/report" --quiet >/dev/null 2>&1
cmp "$out/first.html" "$page" || fail "a second run of the campaign wrote another page"
# Self-contained: nothing loaded from elsewhere, no scripts.
if grep -Eq '<script|<link|<img|<iframe|src=|url\(|@import' "$page"; then fail "$page refers to external resources or scripts"; fi

# Chromium, bounded in time, with a profile of its own (parallel runs do not share one).
browse() {
  local profile
  profile=$(mktemp -d "$out/profile.XXXXXX")
  timeout -k 10 300 "$chromium" --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --no-first-run \
    --disable-extensions --user-data-dir="$profile" --enable-logging=stderr --v=0 "$@"
  local rc=$?
  rm -rf "$profile"
  return $rc
}
# Console output (errors, warnings, uncaught exceptions) is logged as ":CONSOLE" lines.
console_lines() { grep -E ':CONSOLE[:(]|Uncaught' "$1"; }

# The check of the console must be able to fail: a broken page has to show up in it.
cat >"$out/broken.html" <<'HTML'
<!DOCTYPE html><html><body><p>broken</p><script>console.error("plcfi-probe"); notDefined();</script></body></html>
HTML
browse --screenshot="$out/broken.png" --window-size=400,300 "file://$out/broken.html" >/dev/null 2>"$out/broken.log" ||
  fail "chromium did not render the probe page (see $out/broken.log)"
console_lines "$out/broken.log" | grep -q "plcfi-probe" ||
  fail "chromium's console log does not show a deliberate console error; cannot check the report (see $out/broken.log)"

# The report: a screenshot, and no console messages at all.
browse --screenshot="$out/report.png" --window-size=1400,2400 --hide-scrollbars "file://$page" >/dev/null 2>"$out/chromium.log" ||
  fail "chromium failed on the report (see $out/chromium.log)"
if console_lines "$out/chromium.log"; then fail "the report logged console messages (above)"; fi
[[ -f $out/report.png ]] || fail "no screenshot"
size=$(stat -c %s "$out/report.png")
(( size > 50000 )) || fail "screenshot $out/report.png is only $size bytes"
head -c 8 "$out/report.png" | od -An -tx1 | grep -q "89 50 4e 47 0d 0a 1a 0a" || fail "screenshot is not a PNG"

# The DOM as the browser parsed it: the table, one waveform per execution, the TSD.
browse --dump-dom "file://$page" >"$out/dom.html" 2>"$out/dom.log" || fail "chromium --dump-dom failed (see $out/dom.log)"
if console_lines "$out/dom.log"; then fail "the report logged console messages (above)"; fi
executions=$(grep -cE '^  \[run ' "$out/campaign.txt")
(( executions > 0 )) || fail "the campaign reported no executions"
grep -q '<table class="verdicts">' "$out/dom.html" || fail "no verdict table in the DOM"
waves=$(grep -o '<svg class="wave"' "$out/dom.html" | wc -l)
(( waves == executions )) || fail "$waves waveforms in the DOM for $executions executions"
tsds=$(grep -o '<svg class="tsd"' "$out/dom.html" | wc -l)
(( tsds == 2 )) || fail "$tsds TSD diagrams in the DOM, expected 2 (scenarios init and normal)"
grep -q 'class="badge fail">FAIL<' "$out/dom.html" || fail "no FAIL verdict in the DOM"
grep -q 'class="lane faulted"' "$out/dom.html" || fail "no faulted lane highlighted"
echo "PASS: $page rendered ($size-byte screenshot $out/report.png), $executions waveforms, no console messages"

# The explored campaign's page lists the FMEA suggestions; the mutation page lists every
# mutant, survivors first. Both render without console messages.
fixed=$(dirname "$campaign")/../../../st_programs/stamping/stamping_fixed.st
"$plcfi" campaign "$campaign" --program "$fixed" --explore --out "$out/explore" --html "$out/explore/report" --quiet \
  >"$out/explore.txt" 2>&1
[[ $? -le 1 ]] || { cat "$out/explore.txt"; fail "plcfi campaign --explore failed"; }
suggestions=$(($(wc -l < "$out/explore/fmea_suggestions.csv") - 1))
(( suggestions > 0 )) || fail "the explored campaign made no FMEA suggestion"
"$plcfi" mutate "$campaign" --program "$fixed" --html "$out/mutants" >"$out/mutate.txt" 2>&1 || { cat "$out/mutate.txt"; fail "plcfi mutate failed"; }
for name in explore/report mutants; do
  browse --dump-dom "file://$out/$name/index.html" >"$out/dom2.html" 2>"$out/dom2.log" || fail "chromium --dump-dom failed on $name"
  if console_lines "$out/dom2.log"; then fail "the $name page logged console messages (above)"; fi
  if [[ $name == mutants ]]; then
    grep -q '<h2 id="mutants">' "$out/dom2.html" || fail "no mutants section"
    n=$(grep -o 'class="badge survived"' "$out/dom2.html" | wc -l)
    (( n >= 1 )) || fail "no survivor on the mutation page"
    grep -q 'Verdicts by case and path' "$out/dom2.html" && fail "an empty verdict table on the mutation page"
  else
    grep -q '<h2 id="suggestions">' "$out/dom2.html" || fail "no FMEA suggestions section"
  fi
done
browse --screenshot="$out/mutants.png" --window-size=1400,2000 --hide-scrollbars "file://$out/mutants/index.html" >/dev/null \
  2>"$out/mutants.log" || fail "chromium failed on the mutation page"
if console_lines "$out/mutants.log"; then fail "the mutation page logged console messages (above)"; fi
echo "PASS: explored page with $suggestions FMEA suggestion(s), mutation page with its survivors ($out/mutants.png)"

