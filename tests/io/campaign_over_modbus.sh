#!/usr/bin/env bash
# The stamping campaign (three FMEA rows: StampLowered on two automatic paths, the
# pressure, the initialization run) over Modbus TCP against `plcfi plant-server` in real
# time gives the same verdicts as offline; without --arm it refuses to inject; SIGINT
# mid-campaign withdraws the fault, leaves the safe state on the coils and reports the
# campaign incomplete, and --resume finishes it with the same verdicts.
# usage: campaign_over_modbus.sh PLCFI SOURCE_DIR
set -euo pipefail
plcfi=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_cmb_XXXXXX")
server=
trap '[[ -n $server ]] && kill -9 $server 2>/dev/null; rm -rf "$work"' EXIT
cp "$src"/faults/campaigns/stamping/{tsd.yaml,fault_classes.yaml} "$work"/
head -4 "$src"/faults/campaigns/stamping/fmea.csv > "$work"/fmea.csv   # header, F1, F2, F3
sed -e "s#^  - \.\./\.\./\.\./st_programs#  - $src/st_programs#" -e 's/^search_window: .*/search_window: 10s/' \
  "$src"/faults/campaigns/stamping/campaign.yaml > "$work"/offline.yaml
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
sed "s/127.0.0.1:1502/127.0.0.1:$port/" "$src"/st_programs/stamping/io_plant_server.yaml > "$work"/io.yaml
{ cat "$work"/offline.yaml; echo "io: io.yaml"; } > "$work"/bench.yaml

verdicts() { sed -n 's/^\(TC[0-9]*\) *\([0-9-]*\) *\(PASS\|FAIL\|NOT REACHED\) .*/\1 \2 \3/p' "$1" | sort; }
# The bench gives the offline verdicts: every case tested, and each case's verdicts ones
# the offline run gave that case. Which control-flow paths a case is tested on depends on
# timing: on a loaded machine the second path of TC1 and TC2 (after six seconds) may fall
# outside the search window, or a retried exchange may shift a run onto a path the virtual
# plant never takes. That is coverage, reported, not a different verdict.
same_verdicts() {  # offline.v bench.v
  local wrong
  wrong=$(comm -13 <(cut -d' ' -f1,3- "$1" | sort -u) <(cut -d' ' -f1,3- "$2" | sort -u))
  [[ -z "$wrong" ]] || { echo "verdicts the offline run did not give: $wrong"; return 1; }
  diff <(cut -d' ' -f1 "$1" | sort -u) <(cut -d' ' -f1 "$2" | sort -u) || { echo "cases not tested on the bench"; return 1; }
  comm -3 "$1" "$2" | sed 's/^\t/  only on the bench: /; s/^\([^ ]\)/  only offline: \1/'
}

echo "== offline"
"$plcfi" campaign "$work"/offline.yaml --out "$work"/offline --quiet --no-vcd > "$work"/offline.txt || test $? -eq 1
verdicts "$work"/offline.txt | tee "$work"/offline.v
grep -q "TC3 1 FAIL" "$work"/offline.v
test "$(wc -l < "$work"/offline.v)" -ge 5

echo "== real I/O without --arm: refused"
status=0
"$plcfi" campaign "$work"/bench.yaml --out "$work"/refused --quiet > "$work"/refused.txt 2>&1 || status=$?
cat "$work"/refused.txt
test $status -eq 2
grep -q "refusing to inject faults on real I/O" "$work"/refused.txt

echo "== over Modbus TCP, in real time"
# The operator holds start for a second (operator_long_press.yaml): a 0.2 s press can fall
# unseen into a gap of a loaded machine (a late plant server, a reconnect).
"$plcfi" plant-server --listen 127.0.0.1:$port --plant-config "$src"/tests/io/operator_long_press.yaml \
  > "$work"/server.log 2>&1 &
server=$!
for _ in $(seq 1 200); do grep -q listening "$work"/server.log && break; sleep 0.05; done
"$plcfi" campaign "$work"/bench.yaml --arm --out "$work"/bench --quiet --no-vcd > "$work"/bench.txt || test $? -eq 1
cat "$work"/bench.txt
verdicts "$work"/bench.txt | tee "$work"/bench.v
same_verdicts "$work"/offline.v "$work"/bench.v
grep -q "wake latency   min" "$work"/bench.txt

echo "== SIGINT mid-campaign, then --resume"
"$plcfi" campaign "$work"/bench.yaml --arm --out "$work"/bench2 --quiet --no-vcd --junit "$work"/bench2.xml > "$work"/bench2.txt 2>&1 &
run=$!
sleep 7
kill -INT $run
status=0
wait $run || status=$?
cat "$work"/bench2.txt
test $status -eq 1
grep -q "campaign incomplete (interrupted by a signal); finish it with --resume" "$work"/bench2.txt
grep -q '<property name="incomplete" value="interrupted by a signal"/>' "$work"/bench2.xml
grep -q '<property name="wake_latency_p99_us"' "$work"/bench2.xml
coils=$(mbpoll -m tcp -a 1 -t 0 -r 1 -c 7 -1 -p "$port" 127.0.0.1 | sed -n 's/^\[\([0-9]*\)\]:[[:space:]]*\([01]\)$/\2/p' | tr -d '\n')
echo "coils after SIGINT: $coils"
test "$coils" = 1000000   # the io file's safe state: the slider valve on, all else off
"$plcfi" campaign "$work"/bench.yaml --arm --out "$work"/bench2 --resume --quiet --no-vcd > "$work"/bench3.txt || test $? -eq 1
cat "$work"/bench3.txt
verdicts "$work"/bench3.txt | tee "$work"/bench3.v
same_verdicts "$work"/offline.v "$work"/bench3.v

kill -INT $server
wait $server || true
server=
cat "$work"/server.log
grep -q "plant steps" "$work"/server.log
echo "same verdicts offline and over Modbus; interrupted and resumed"
