#!/usr/bin/env bash
# mbpoll (an independent Modbus master) against `plcfi plant-server`: the stamping plant's
# sensors read as discrete inputs, a coil write moves the stamp in real time, SIGINT ends
# the server cleanly.   usage: plant_server_mbpoll.sh PLCFI
set -euo pipefail
plcfi=$1
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_ps_XXXXXX")
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
"$plcfi" plant-server --listen 127.0.0.1:$port --duration 60s > "$work"/server.log 2>&1 &
pid=$!
trap 'kill $pid 2>/dev/null || true; rm -rf "$work"' EXIT
for _ in $(seq 1 200); do grep -q listening "$work"/server.log && break; sleep 0.05; done
grep -q "listening on 127.0.0.1:$port" "$work"/server.log

# mbpoll -t 1: discrete inputs, -r 1: reference 1 = address 0. Initial state: slider at the
# crane position (PosCrane, DI 0), stamp up (StampUp, DI 3), mode automatic (ModeAuto, DI 5).
di() { mbpoll -m tcp -a 1 -t 1 -r 1 -c 11 -1 -p "$port" 127.0.0.1 | sed -n 's/^\[\([0-9]*\)\]:[[:space:]]*\([01]\)$/\1=\2/p' | tr '\n' ' '; }
before=$(di)
echo "before: $before"
[[ "$before" == "1=1 2=0 3=0 4=1 5=0 6=1 "* ]]
# Coil 1 (reference 2) is StampDown (%QX0.1): the stamp lowers in 0.2 s.
mbpoll -m tcp -a 1 -t 0 -r 2 -1 -p "$port" 127.0.0.1 1 > /dev/null
sleep 0.6
after=$(di)
echo "after StampDown: $after"
[[ "$after" == "1=1 2=0 3=0 4=0 5=1 6=1 "* ]]
# Holding register 2 (reference 3) is PressureSetpoint (%QW2); input register 2 the pressure.
mbpoll -m tcp -a 1 -t 4 -r 3 -1 -p "$port" 127.0.0.1 6000 > /dev/null
sleep 0.8
pressure=$(mbpoll -m tcp -a 1 -t 3 -r 3 -c 1 -1 -p "$port" 127.0.0.1 | sed -n 's/^\[3\]:[[:space:]]*\([0-9-]*\)$/\1/p')
echo "pressure: $pressure"
(( pressure > 5700 && pressure <= 6000 ))
kill -INT $pid
wait $pid
cat "$work"/server.log
grep -q "stamp_strokes 1" "$work"/server.log
echo "plant-server OK"
