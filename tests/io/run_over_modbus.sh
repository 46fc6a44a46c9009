#!/usr/bin/env bash
# The stamping program on `plcfi plant-server` over Modbus TCP in real time: workpieces
# get stamped; every way out (normal end, SIGINT, SIGTERM, a VM trap) leaves the configured
# safe state on the coils; a server killed and restarted mid-run is reconnected; a server
# gone for longer than lost_after is lost communication: a safe stop, without a hang.
# usage: run_over_modbus.sh PLCFI SOURCE_DIR
set -euo pipefail
plcfi=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_rom_XXXXXX")
pids=()
# On a failure the logs of every run and server are printed before they are removed.
cleanup() {
  local status=$?
  for p in "${pids[@]}"; do kill -9 $p 2>/dev/null || true; done
  if (( status != 0 )); then
    for f in "$work"/*.log "$work"/*.txt; do [[ -e $f ]] && { echo "---- $(basename "$f")"; cat "$f"; }; done
  fi
  rm -rf "$work"
}
trap cleanup EXIT
start_server() {  # -> port in $port, pid in $server
  port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  "$plcfi" plant-server --listen 127.0.0.1:$port --duration 120s \
    --plant-config "$src/tests/io/operator_long_press.yaml" > "$work/server_$port.log" 2>&1 &
  server=$!
  pids+=($server)
  for _ in $(seq 1 200); do grep -q listening "$work/server_$port.log" && break; sleep 0.05; done
  sed "s/127.0.0.1:1502/127.0.0.1:$port/" "$src"/st_programs/stamping/io_plant_server.yaml > "$work/io_$port.yaml"
}
program=$src/st_programs/stamping/stamping.st
coils() { mbpoll -m tcp -a 1 -t 0 -r 1 -c 7 -1 -p "$port" 127.0.0.1 | sed -n 's/^\[\([0-9]*\)\]:[[:space:]]*\([01]\)$/\2/p' | tr -d '\n'; }
safe=1000000   # SliderExtend kept on (safe_state), everything else off

echo "== 1. twelve seconds of production over Modbus TCP"
start_server
"$plcfi" run "$program" --io "$work/io_$port.yaml" --realtime --duration 12s \
  --print Main.pieceCount --print Main.step --print gSliderError --print gStampCylError | tee "$work/run1.txt"
grep -q "ended: done; outputs written to the safe state" "$work/run1.txt"
# What the product promises on a loaded machine is not zero timeouts (the device timeout is
# 4 ms) but that each failed exchange is counted and recovered from while production goes
# on: a few failures at most, the run to its end, no collision.
line=$(grep -o "device stamping: [0-9]* requests, [0-9]* failed, [0-9]* connect(s), [0-9]* disconnect(s)" "$work/run1.txt")
requests=$(sed 's/device stamping: \([0-9]*\) requests.*/\1/' <<<"$line")
failed=$(sed 's/.* requests, \([0-9]*\) failed.*/\1/' <<<"$line")
connects=$(sed 's/.* failed, \([0-9]*\) connect.*/\1/' <<<"$line")
(( requests >= 4000 ))            # 1200 scans, 4 requests each (a few scans may overrun)
(( failed * 20 <= requests ))     # at most 5 % lost
(( failed == 0 || connects >= 2 ))   # after a failed exchange the link came back
echo "coils after the end: $(coils)"
[[ "$(coils)" == "$safe" ]]
kill -INT $server; wait $server || true
cat "$work/server_$port.log"
# Production: a workpiece takes about 5 s, so 12 s stamp one or two. The program supervises
# every cylinder stroke with 0.5 s: a link down or a plant server starved for that long
# mid-stroke (seen on a 2-core machine under a parallel build) is a class-1 alarm, which is
# the program doing its job. That stop is accepted only with its cause on record (failed
# exchanges or late plant steps); a quiet run must have stamped.
pieces=$(sed -n 's/^Main.pieceCount = //p' "$work/run1.txt")
late=$(sed -n 's/.* plant steps (\([0-9]*\) late).*/\1/p' "$work/server_$port.log")
if (( pieces < 1 )); then
  grep -q "^Main.step = Alarm" "$work/run1.txt"
  grep -q "^gSliderError = TRUE\|^gStampCylError = TRUE" "$work/run1.txt"
  (( failed >= 1 || late >= 1 ))
  echo "no workpiece: a class-1 alarm after $failed failed exchange(s) and $late late plant step(s)"
else
  # No collision in production. (The program's class-1 stop switches every valve off, so
  # an alarm in the middle of a stroke may let the slider run back under the stamp.)
  grep -q "collisions 0" "$work/server_$port.log"
fi

for sig in TERM INT; do
  echo "== 2. SIG$sig: the safe state reaches the plant"
  start_server
  "$plcfi" run "$program" --io "$work/io_$port.yaml" --realtime --duration 60s > "$work/run2.txt" 2>&1 &
  run=$!
  pids+=($run)
  moving=0   # production: within a few seconds the coils leave the safe state
  for _ in $(seq 1 40); do sleep 0.2; [[ "$(coils)" != "$safe" ]] && { moving=1; break; }; done
  (( moving ))
  sleep 1
  kill -$sig $run
  wait $run
  cat "$work/run2.txt"
  grep -q "ended: SIG$sig; outputs written to the safe state (all off but 1)" "$work/run2.txt"
  echo "coils after SIG$sig: $(coils)"
  [[ "$(coils)" == "$safe" ]]
  kill -INT $server; wait $server || true
done

echo "== 2b. a VM trap: the safe state reaches the plant"
start_server
status=0
"$plcfi" run "$src/tests/io/trap_after_2s.st" --cycle-time 10ms --io "$work/io_$port.yaml" --realtime --duration 30s \
  > "$work/run2b.txt" 2>&1 || status=$?
cat "$work/run2b.txt"
(( status == 1 ))
grep -q "ended: trap: .*division by zero" "$work/run2b.txt"
echo "coils after the trap: $(coils)"
[[ "$(coils)" == "$safe" ]]
kill -INT $server; wait $server || true

echo "== 2c. the server killed and restarted mid-run: reconnected, the run goes on"
start_server
sed -i 's/lost_after: 1s/lost_after: 20s/' "$work/io_$port.yaml"
"$plcfi" run "$program" --io "$work/io_$port.yaml" --realtime --duration 8s > "$work/run2c.txt" 2>&1 &
run=$!
pids+=($run)
sleep 2
kill -9 $server; wait $server 2>/dev/null || true
sleep 2
"$plcfi" plant-server --listen 127.0.0.1:$port --duration 120s \
  --plant-config "$src/tests/io/operator_long_press.yaml" > "$work/server2_$port.log" 2>&1 &
server=$!
pids+=($server)
wait $run
cat "$work/run2c.txt"
grep -q "ended: done" "$work/run2c.txt"
# The outage is counted (failed requests, a disconnect) and recovered (a new connection);
# on a loaded machine a slow reply may add a timeout and a reconnect of its own.
grep -q "device stamping: [0-9]* requests, [1-9][0-9]* failed, [2-9][0-9]* connect(s), [1-9][0-9]* disconnect(s)" "$work/run2c.txt"
[[ "$(coils)" == "$safe" ]]
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
