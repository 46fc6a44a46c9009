#!/usr/bin/env bash
# The stamping program on `plcfi plant-server` over Modbus TCP in real time: workpieces
# get stamped; SIGTERM ends the run with the configured safe state on the coils; a server
# killed mid-run is detected as lost communication, without a hang.
# usage: run_over_modbus.sh PLCFI SOURCE_DIR
set -euo pipefail
plcfi=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_rom_XXXXXX")
pids=()
trap 'for p in "${pids[@]}"; do kill -9 $p 2>/dev/null || true; done; rm -rf "$work"' EXIT
start_server() {  # -> port in $port, pid in $server
  port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  "$plcfi" plant-server --listen 127.0.0.1:$port --duration 120s > "$work/server_$port.log" 2>&1 &
  server=$!
  pids+=($server)
  for _ in $(seq 1 200); do grep -q listening "$work/server_$port.log" && break; sleep 0.05; done
  sed "s/127.0.0.1:1502/127.0.0.1:$port/" "$src"/st_programs/stamping/io_plant_server.yaml > "$work/io_$port.yaml"
}
program=$src/st_programs/stamping/stamping.st

echo "== 1. twelve seconds of production over Modbus TCP"
start_server
"$plcfi" run "$program" --io "$work/io_$port.yaml" --realtime --duration 12s --print Main.pieceCount | tee "$work/run1.txt"
grep -q "ended: done; outputs written to the safe state" "$work/run1.txt"
grep -q "device stamping: [0-9]* requests, 0 failed, 1 connect(s)" "$work/run1.txt"
pieces=$(sed -n 's/^Main.pieceCount = //p' "$work/run1.txt")
(( pieces >= 1 ))
kill -INT $server; wait $server || true
cat "$work/server_$port.log"
grep -q "collisions 0" "$work/server_$port.log"

echo "== 2. SIGTERM: the safe state reaches the plant"
start_server
"$plcfi" run "$program" --io "$work/io_$port.yaml" --realtime --duration 60s > "$work/run2.txt" 2>&1 &
run=$!
pids+=($run)
sleep 4
kill -TERM $run
wait $run
cat "$work/run2.txt"
grep -q "ended: SIGTERM; outputs written to the safe state (all off but 1)" "$work/run2.txt"
coils=$(mbpoll -m tcp -a 1 -t 0 -r 1 -c 7 -1 -p "$port" 127.0.0.1 | sed -n 's/^\[\([0-9]*\)\]:[[:space:]]*\([01]\)$/\2/p' | tr -d '\n')
echo "coils after SIGTERM: $coils"
[[ "$coils" == "1000000" ]]   # SliderExtend kept on (safe_state), everything else off
kill -INT $server; wait $server || true

echo "== 3. the server dies mid-run: lost communication, safe stop, no hang"
start_server
"$plcfi" run "$program" --io "$work/io_$port.yaml" --realtime --duration 60s > "$work/run3.txt" 2>&1 &
run=$!
pids+=($run)
sleep 3
kill -9 $server
t0=$(date +%s)
status=0
wait $run || status=$?
t1=$(date +%s)
cat "$work/run3.txt"
(( status == 1 ))
(( t1 - t0 <= 10 ))
grep -q "ended: communication lost: stamping (127.0.0.1:$port) unit 1" "$work/run3.txt"
echo "run over Modbus OK"
