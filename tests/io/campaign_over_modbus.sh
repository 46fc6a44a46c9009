#!/usr/bin/env bash
# The stamping campaign (three FMEA rows: StampLowered on two automatic paths, the
# pressure, the initialization run) over Modbus TCP against `plcfi plant-server` in real
# time gives the same verdicts as offline; without --arm it refuses to inject.
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
"$plcfi" plant-server --listen 127.0.0.1:$port > "$work"/server.log 2>&1 &
server=$!
for _ in $(seq 1 200); do grep -q listening "$work"/server.log && break; sleep 0.05; done
"$plcfi" campaign "$work"/bench.yaml --arm --out "$work"/bench --quiet --no-vcd > "$work"/bench.txt || test $? -eq 1
cat "$work"/bench.txt
verdicts "$work"/bench.txt | tee "$work"/bench.v
diff "$work"/offline.v "$work"/bench.v
kill -INT $server
wait $server || true
server=
cat "$work"/server.log
grep -q "plant steps" "$work"/server.log
echo "same verdicts offline and over Modbus"
