#!/usr/bin/env bash
# Every command that takes a plant takes a plant file too: a CPTest+ script on a plant file
# that names a built-in plant gives the verdicts it gives on the plant by name, and
# plant-server serves an ST plant over Modbus TCP (mbpoll, an independent master, reads
# the ST plant's sensors where the map puts them).
# usage: plant_file_commands.sh PLCFI SOURCE_DIR
set -euo pipefail
plcfi=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_plantcmd_XXXXXX")
server=
trap '[[ -n $server ]] && kill -9 $server 2>/dev/null; rm -rf "$work"' EXIT

echo "== script: a plant file naming the built-in bead dispenser"
printf 'builtin: bead_dispenser\n' > "$work/bead.yaml"
bead=$src/st_programs/bead_dispenser
"$plcfi" script "$bead/bead_dispenser.st" --plant bead_dispenser "$bead/tests/pass_one_ball.cpt" \
  --history "$work/h1.sqlite" > "$work/by_name.txt" || true
"$plcfi" script "$bead/bead_dispenser.st" --plant "$work/bead.yaml" "$bead/tests/pass_one_ball.cpt" \
  --history "$work/h2.sqlite" > "$work/by_file.txt" || true
cat "$work/by_file.txt"
grep -q "on plant bead_dispenser ($work/bead.yaml (built-in plant bead_dispenser))" "$work/by_file.txt"
grep -q "^1 passed, 0 failed, 0 undecidable" "$work/by_file.txt"
diff <(grep -o "\] [A-Z][a-z]* " "$work/by_name.txt") <(grep -o "\] [A-Z][a-z]* " "$work/by_file.txt")

echo "== plant-server: the ST stamping plant over Modbus TCP"
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
"$plcfi" plant-server --plant "$src/plant_model/stamping/st/stamping_st.yaml" --listen 127.0.0.1:$port --duration 60s \
  > "$work/server.log" 2>&1 &
server=$!
for _ in $(seq 1 200); do grep -q listening "$work/server.log" && break; sleep 0.05; done
cat "$work/server.log"
grep -q listening "$work/server.log"
# Discrete inputs 0..8: PosCrane, PosStamp, Filled, StampUp, StampLowered, ModeAuto, StartButton, AckButton, NextReady.
inputs=$(mbpoll -m tcp -a 1 -t 1 -r 1 -c 9 -1 -p "$port" 127.0.0.1 | sed -n 's/^\[\([0-9]*\)\]:[[:space:]]*\([01]\)$/\2/p' | tr -d '\n')
echo "discrete inputs: $inputs"
[[ ${inputs:0:1} == 1 && ${inputs:3:1} == 1 && ${inputs:5:1} == 1 && ${inputs:8:1} == 1 ]]  # at rest, automatic, next module ready
# Extend the slider (coil 0): after its 0.3 s stroke PosStamp is on and PosCrane off.
mbpoll -m tcp -a 1 -t 0 -r 1 -p "$port" 127.0.0.1 1 > /dev/null
moved=0
for _ in $(seq 1 50); do
  sleep 0.1
  inputs=$(mbpoll -m tcp -a 1 -t 1 -r 1 -c 2 -1 -p "$port" 127.0.0.1 | sed -n 's/^\[\([0-9]*\)\]:[[:space:]]*\([01]\)$/\2/p' | tr -d '\n')
  [[ $inputs == 01 ]] && { moved=1; break; }
done
echo "after SliderExtend: PosCrane PosStamp = $inputs"
(( moved ))
kill -INT $server
wait $server || true
server=
echo "plant files in script and plant-server OK"
