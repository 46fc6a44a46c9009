#!/usr/bin/env bash
# The safety evidence section of `plcfi campaign --html` (issue 30) in headless Chromium:
# the page of campaign_safety.yaml on the published program renders without console
# messages, and the DOM as the browser parsed it holds the safety table (DC and band per
# safety function from OUT/safety.json, F3 undetected), the traceability matrix (one line
# per line of OUT/traceability.csv) and the fingerprint. The campaign without failure rates
# has no such section.
#   html_safety.sh PLCFI SOURCE_DIR OUTDIR
# Exit 0 pass, 1 fail, 77 skipped (no Chromium).
set -uo pipefail
plcfi=$1 src=$2 out=$3

chromium=$(command -v chromium || command -v chromium-browser || true)
if [[ -z $chromium ]]; then
  echo "SKIP: chromium is not installed (scripts/install-deps installs it)"
  exit 77
fi
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$out"
mkdir -p "$out"
spec=$src/faults/campaigns/stamping
"$plcfi" campaign "$spec/campaign_safety.yaml" --out "$out/campaign" --html "$out/report" --quiet >"$out/campaign.txt" 2>&1
[[ $? -eq 1 ]] || { cat "$out/campaign.txt"; fail "plcfi campaign: expected exit 1 (TC3 fails on the published program)"; }
page=$out/report/index.html
if grep -Eq '<script|<link|<img|<iframe|src=|url\(|@import' "$page"; then fail "$page refers to external resources or scripts"; fi

browse() {
  local profile
  profile=$(mktemp -d "$out/profile.XXXXXX")
  timeout -k 10 300 "$chromium" --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --no-first-run \
    --disable-extensions --user-data-dir="$profile" --enable-logging=stderr --v=0 "$@"
  local rc=$?
  rm -rf "$profile"
  return $rc
}
console_lines() { grep -E ':CONSOLE[:(]|Uncaught' "$1"; }

browse --dump-dom "file://$page" >"$out/dom.html" 2>"$out/dom.log" || fail "chromium --dump-dom failed (see $out/dom.log)"
if console_lines "$out/dom.log"; then fail "the report logged console messages (above)"; fi
browse --screenshot="$out/safety.png" --window-size=1400,3000 --hide-scrollbars "file://$page#safety" >/dev/null 2>"$out/shot.log" ||
  fail "chromium failed to take a screenshot"
if console_lines "$out/shot.log"; then fail "the report logged console messages (above)"; fi

grep -q '<h2 id="safety">Safety evidence</h2>' "$out/dom.html" || fail "no safety evidence section in the DOM"
# Each safety function's row carries DC and band as safety.json has them.
python3 - "$out/campaign/safety.json" "$out/dom.html" "$out/campaign/traceability.csv" <<'PY' || fail "the HTML section disagrees with safety.json"
import json, re, sys
s = json.load(open(sys.argv[1]))
dom = open(sys.argv[2]).read()
bad = []
for f in s["safety_functions"]:
    m = re.search(r'<tr class="[^"]*" data-function="%s">(.*?)</tr>' % re.escape(f["id"]), dom, re.S)
    if not m:
        bad.append(f"no row for {f['id']}"); continue
    row = m.group(1)
    dc = re.search(r'<td class="num dc">([^<]*)</td>', row).group(1)
    if dc != "%.1f %%" % (f["dc"] * 100): bad.append(f"{f['id']}: DC {dc} in the page, {f['dc']} in safety.json")
    band = re.search(r'<td class="band">([^<]*)</td>', row).group(1)
    if band != f["band"]: bad.append(f"{f['id']}: band {band}, safety.json {f['band']}")
    margin = re.search(r'<td class="num margin">([^<]*)</td>', row).group(1)
    if margin != "%s ms" % f["margin"]: bad.append(f"{f['id']}: margin {margin}, safety.json {f['margin']}")
    for u in f["undetected"]:
        if "<b>%s</b>" % u not in row: bad.append(f"{f['id']}: undetected {u} not shown")
table = re.search(r'<table class="trace">(.*?)</table>', dom, re.S)
csv_lines = [l for l in open(sys.argv[3]) if not l.startswith("#")][1:]
n = table.group(1).count("<tr") - 1 if table else -1
if n != len(csv_lines): bad.append(f"{n} traceability rows in the page, {len(csv_lines)} in traceability.csv")
for k in s["fingerprint"]:
    if "<dt>%s</dt>" % k not in dom: bad.append(f"fingerprint {k} not shown")
for b in bad: print("MISMATCH:", b)
sys.exit(1 if bad else 0)
PY
grep -q '<b>F3</b>: TC3 path 1 FAIL' "$out/dom.html" || fail "F3 is not shown undetected"

"$plcfi" campaign "$spec/campaign.yaml" --out "$out/plain" --no-vcd --html "$out/plain/report" --quiet >/dev/null 2>&1
grep -q 'id="safety"' "$out/plain/report/index.html" && fail "the campaign without failure rates has a safety section"
echo "PASS: safety evidence section rendered ($out/safety.png), DC, band, margin and traceability as in safety.json"
