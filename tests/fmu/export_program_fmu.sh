#!/usr/bin/env bash
# `plcfi export-fmu`: the stamping program as an FMI 2.0 co-simulation FMU, driven by
# masters of our own (C, dlopen, the standard's calling sequence):
#  1. importer.c: all 34 functions there, the calling sequence, the FMU state saved
#     halfway and restored replays the second half, every other function called once
#     (what the FMU does not offer refused with fmi2Error and a log message), a reset
#     replays the run;
#  2. cosim.c: the program FMU coupled by name with the stamping plant FMU of `plcfi plant
#     export-fmu` gives, scan for scan, the signals of `plcfi sim` on the built-in plant;
#  3. the fault parameters reproduce the published failing case (F3: StampLowered stuck
#     during the reference stroke goes unnoticed by stamping.st; stamping_fixed.st raises
#     the alarm), and a bad fault parameter is refused at initialization;
#  4. programs FMI cannot carry are refused at export with the variable's file:line:col;
#  and every description passes fmi2_md_check.py (the standard's rules).
# usage: export_program_fmu.sh PLCFI IMPORTER COSIM SOURCE_DIR
set -euo pipefail
plcfi=$1
importer=$2
cosim=$3
src=$4
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_progfmu_XXXXXX")
trap 'rm -rf "$work"' EXIT
prog=$src/st_programs/stamping

unpack() {  # FMU DIR
  mkdir -p "$2"
  (cd "$2" && cmake -E tar xf "$1")
}
# "name vr causality type" per ScalarVariable of an unpacked FMU.
variables() {
  awk '/<ScalarVariable/ {
         match($0, /name="[^"]*"/); n = substr($0, RSTART + 6, RLENGTH - 7)
         match($0, /valueReference="[0-9]*"/); v = substr($0, RSTART + 16, RLENGTH - 17)
         match($0, /causality="[a-z]*"/); c = substr($0, RSTART + 11, RLENGTH - 12) }
       /<(Boolean|Integer|Real|String)/ { match($0, /<[A-Z][a-z]*/); print n, v, c, substr($0, RSTART + 1, RLENGTH - 1) }' \
    "$1/modelDescription.xml"
}
attr() { sed -n "s/.*$2=\"\([^\"]*\)\".*/\1/p" "$1/modelDescription.xml" | head -n 1; }

echo "--- export"
"$plcfi" export-fmu "$prog/stamping.st" -o "$work/program.fmu" | tee "$work/export.txt"
grep -q "wrote $work/program.fmu (FMI 2.0 co-simulation, model program, 12 inputs, 7 outputs, 39 fault parameters, base tick 10ms)" "$work/export.txt"
grep -Eq '^  input +%IX0.4 +BOOL +Boolean +StampLowered$' "$work/export.txt"
grep -Eq '^  output +%QW2 +INT +Integer +PressureSetpoint$' "$work/export.txt"
"$plcfi" plant export-fmu -o "$work/plant.fmu" > /dev/null
unpack "$work/program.fmu" "$work/program"
unpack "$work/plant.fmu" "$work/plant"
test -f "$work/program/resources/plcfi/src/000_stamping.st"
# Both descriptions keep the standard's rules (tests/fmu/fmi2_md_check.py, written from
# the FMI 2.0 text: attributes, causality/variability/initial, start values, structure).
/usr/bin/python3 "$src/tests/fmu/fmi2_md_check.py" "$work/program/modelDescription.xml" "$work/plant/modelDescription.xml"
grep -q 'canGetAndSetFMUstate="true" canSerializeFMUstate="false"' "$work/program/modelDescription.xml"
variables "$work/program" > "$work/program.vars"
variables "$work/plant" > "$work/plant.vars"
vr() { awk -v n="$2" '$1 == n { print $2 }' "$1"; }

echo "--- 1. importer"
"$importer" "$work/program" "$(attr "$work/program" modelIdentifier)" "$(attr "$work/program" guid)" 0.01 400 --state \
  --bool-in "$(vr "$work/program.vars" ModeAuto)@0" --bool-in "$(vr "$work/program.vars" PosCrane)@0" \
  --bool-in "$(vr "$work/program.vars" StampUp)@0" --bool-in "$(vr "$work/program.vars" StartButton)@5" \
  --bool-out "$(vr "$work/program.vars" StampDown)" --bool-out "$(vr "$work/program.vars" AlarmLamp)" > "$work/importer.txt"
uniq -c "$work/importer.txt"
grep -qx "resolved all 34 functions" "$work/importer.txt"
grep -qx "state restored: the second half ran the same" "$work/importer.txt"
grep -qx "refused with a log message: serialization, derivatives, cancel" "$work/importer.txt"
grep -qx ok "$work/importer.txt"
# The program was driven: started in automatic mode at home, its reference stroke lowers
# the stamp, which never arrives (no plant here); the unsupervised stroke of stamping.st
# raises no alarm.
test "$(sed -n 2p "$work/importer.txt")" = 00
test "$(grep -x '[01][01]' "$work/importer.txt" | tail -n 1)" = 10
# The state holds the fault overlays' state too: in manual mode the stamp valve follows
# the jog button (with the slider under the stamp), which a random intermittent fault drops in about half of its 20 ms
# intervals to its value at the injection (FALSE: the button is pressed one step later).
# The restored second half must draw the same random numbers.
"$importer" "$work/program" "$(attr "$work/program" modelIdentifier)" "$(attr "$work/program" guid)" 0.01 400 --state \
  --string "$(vr "$work/program.vars" fault.ManStamp)=intermittent(random, 0.5, 20ms)" \
  --bool-in "$(vr "$work/program.vars" PosStamp)@0" --bool-in "$(vr "$work/program.vars" ManStamp)@1" \
  --bool-out "$(vr "$work/program.vars" StampDown)" > "$work/random.txt" 2> /dev/null
grep -qx "state restored: the second half ran the same" "$work/random.txt"
on=$(sed -n '202,401p' "$work/random.txt" | grep -cx 1 || true)
echo "second half: the stamp valve open in $on of 200 steps"
(( on > 20 && on < 180 ))

# The co-simulation set-up: every program port linked by name to the plant's signal.
setup() {  # PROGRAM_DIR [param lines...]
  local dir=$1
  shift
  echo "fmu program $dir $(attr "$dir" modelIdentifier) $(attr "$dir" guid)"
  echo "fmu plant $work/plant $(attr "$work/plant" modelIdentifier) $(attr "$work/plant" guid)"
  while read -r name v causality type; do
    case $causality in
      input) echo "link $type plant $(vr "$work/plant.vars" "$name") program $v" ;;
      output) echo "link $type program $v plant $(vr "$work/plant.vars" "$name")" ;;
      *) continue ;;
    esac
    echo "watch program $type $v $name"
  done < "$work/program.vars"
  for p in "$@"; do echo "$p"; done
}

echo "--- 2. program FMU + plant FMU = plcfi sim"
setup "$work/program" > "$work/cosim.setup"
"$cosim" "$work/cosim.setup" 0.01 6000 > "$work/cosim.csv"
watch=$(head -n 1 "$work/cosim.csv" | cut -d, -f2-)
"$plcfi" sim "$prog/stamping.st" --duration 60s --watch "$watch" --csv "$work/sim.csv" > /dev/null
if ! cmp -s "$work/cosim.csv" "$work/sim.csv"; then
  echo "the co-simulation differs from plcfi sim:"
  diff "$work/sim.csv" "$work/cosim.csv" | head -n 20
  exit 1
fi
# The cell worked: the stamp went down more than once in the minute.
test "$(awk -F, -v c="$(head -n 1 "$work/cosim.csv" | tr ',' '\n' | grep -nx StampDown | cut -d: -f1)" \
  'NR > 1 && $c == 1 && prev != 1 { n++ } { prev = $c } END { print n + 0 }' "$work/cosim.csv")" -ge 2
echo "6000 steps identical to plcfi sim ($(head -n 1 "$work/cosim.csv" | tr ',' '\n' | wc -l) columns)"
# The same program as PLCopen XML: the archive keeps the file as it is, the binary
# imports it as plcfi does.
"$plcfi" export-fmu "$prog/stamping.xml" -o "$work/xml.fmu" > /dev/null
unpack "$work/xml.fmu" "$work/xml"
test -f "$work/xml/resources/plcfi/src/000_stamping.xml"
setup "$work/xml" > "$work/xml.setup"
"$cosim" "$work/xml.setup" 0.01 2000 > "$work/xml.csv"
cmp -s "$work/xml.csv" <(head -n 2001 "$work/sim.csv")
echo "the program as PLCopen XML: 2000 steps identical"

echo "--- 3. fault parameters: the published failing case F3"
col() { head -n 1 "$1" | tr ',' '\n' | grep -nx "$2" | cut -d: -f1; }
stuck="param program String $(vr "$work/program.vars" fault.StampLowered) stuck"
setup "$work/program" "$stuck" > "$work/f3.setup"
"$cosim" "$work/f3.setup" 0.01 3000 > "$work/f3.csv"
alarm=$(col "$work/f3.csv" AlarmLamp)
down=$(col "$work/f3.csv" StampDown)
# stamping.st: the stamp is lowered for the reference stroke and never seen arriving; no alarm.
awk -F, -v a="$alarm" 'NR > 1 && $a == 1 { exit 1 }' "$work/f3.csv"
test "$(tail -n 1 "$work/f3.csv" | cut -d, -f"$down")" = 1
echo "stamping.st with StampLowered stuck: no alarm in 30 s, the stamp valve still open (F3 FAIL)"
"$plcfi" export-fmu "$prog/stamping_fixed.st" -o "$work/fixed.fmu" > /dev/null
unpack "$work/fixed.fmu" "$work/fixed"
setup "$work/fixed" "$stuck" > "$work/f3_fixed.setup"
"$cosim" "$work/f3_fixed.setup" 0.01 3000 > "$work/f3_fixed.csv"
first=$(awk -F, -v a="$alarm" 'NR > 1 && $a == 1 { print $1; exit }' "$work/f3_fixed.csv")
test -n "$first"
test "$(tail -n 1 "$work/f3_fixed.csv" | cut -d, -f"$down")" = 0
echo "stamping_fixed.st with StampLowered stuck: AlarmLamp at t = $first s, the stamp valve closed (F3 PASS)"
# Later injection: the fault acts from fault_at on; before it, the run is the plain one.
setup "$work/program" "$stuck" "param program Real $(vr "$work/program.vars" fault_at.StampLowered) 20" > "$work/late.setup"
"$cosim" "$work/late.setup" 0.01 2000 > "$work/late.csv"
cmp -s <(head -n 2001 "$work/late.csv") <(head -n 2001 "$work/cosim.csv")
# An actuator fault on an output: the plant never receives the slider command.
setup "$work/program" "param program String $(vr "$work/program.vars" fault.SliderExtend) stuck_off" > "$work/act.setup"
"$cosim" "$work/act.setup" 0.01 3000 > "$work/act.csv"
awk -F, -v c="$(col "$work/act.csv" SliderExtend)" 'NR > 1 && $c == 1 { exit 1 }' "$work/act.csv"
echo "SliderExtend stuck_off: the plant never sees the slider command"

echo "--- bad fault parameters are refused at initialization"
for bad in "StampLowered stuk|fault.StampLowered = 'stuk'" "StampLowered stuck_on|fault.StampLowered" \
           "SliderExtend drift(1/s)|fault.SliderExtend"; do
  spec=${bad%%|*}
  want=${bad#*|}
  setup "$work/program" "param program String $(vr "$work/program.vars" "fault.${spec%% *}") ${spec#* }" > "$work/bad.setup"
  if "$cosim" "$work/bad.setup" 0.01 10 > /dev/null 2> "$work/bad.err"; then
    echo "fault '$spec' was accepted"
    exit 1
  fi
  cat "$work/bad.err"
  grep -qF "$want" "$work/bad.err"
  grep -q "fmi2ExitInitializationMode of program returned status 3" "$work/bad.err"
done

echo "--- analog ports, two instances in one process, a trap"
cat > "$work/analog.st" <<'ST'
PROGRAM Main
VAR
  level AT %ID0 : REAL;
  count AT %ID1 : UDINT;
  speed AT %IW4 : INT;
  divisor AT %IW5 : INT;
  valve AT %QD0 : REAL;
  total AT %QD1 : UDINT;
  back AT %QW4 : INT;
  ratio AT %QW5 : INT;
END_VAR
valve := level * 2.0;
total := count + 1;
back := -speed;
ratio := 100 / divisor;
END_PROGRAM
ST
"$plcfi" export-fmu "$work/analog.st" -o "$work/analog.fmu" --cycle-time 5ms | tee "$work/analog.txt"
grep -q "4 inputs, 4 outputs, 17 fault parameters, base tick 5ms" "$work/analog.txt"
unpack "$work/analog.fmu" "$work/analog"
/usr/bin/python3 "$src/tests/fmu/fmi2_md_check.py" "$work/analog/modelDescription.xml"
variables "$work/analog" > "$work/analog.vars"
a() { vr "$work/analog.vars" "Main.$1"; }
id=$(attr "$work/analog" modelIdentifier)
guid=$(attr "$work/analog" guid)
cat > "$work/analog.setup" <<SETUP
fmu one $work/analog $id $guid
fmu two $work/analog $id $guid
param one Real $(a level) 1.25
param one Real $(a count) 4294967294
param one Integer $(a speed) -300
param one Integer $(a divisor) 4
param two Real $(a level) -3
param two Real $(a count) 7
param two Integer $(a speed) 32767
param two Integer $(a divisor) 0
watch one Real $(a valve) valve1
watch one Real $(a total) total1
watch one Integer $(a back) back1
watch one Integer $(a ratio) ratio1
watch two Real $(a valve) valve2
watch two Real $(a total) total2
watch two Integer $(a back) back2
SETUP
# Steps of 12 ms against a 5 ms tick: 3, 2, 3 scans. Instance two divides by zero in its
# first scan: it stops with its outputs in the safe state (0), and says where.
"$cosim" "$work/analog.setup" 0.012 3 > "$work/analog.csv" 2> "$work/analog.err"
cat "$work/analog.csv" "$work/analog.err"
test "$(tail -n 1 "$work/analog.csv")" = "0.024,2.5,4294967295,300,25,0,0,0"
grep -q "\[two status 1\] t = 0.000000 s: the program stopped: .*000_analog.st:15:10: runtime error.*division by zero" "$work/analog.err"
grep -q "cosim: 1 step(s) ended with fmi2Warning" "$work/analog.err"
for bad in "Integer speed 40000|Main.speed: 40000 is not a value of INT (-32768..32767)" \
           "Real count 1.5|Main.count: 1.5 is not a value of UDINT" \
           "Real count -1|Main.count: -1 is not a value of UDINT" \
           "Boolean valve 1|fmi2SetBoolean: no Boolean input"; do
  set -- ${bad%%|*}
  printf 'fmu one %s %s %s\nparam one %s %s %s\n' "$work/analog" "$id" "$guid" "$1" "$(a "$2")" "$3" > "$work/bad.setup"
  if "$cosim" "$work/bad.setup" 0.01 1 > /dev/null 2> "$work/bad.err"; then
    echo "accepted: $bad"
    exit 1
  fi
  grep -qF "${bad#*|}" "$work/bad.err" || { cat "$work/bad.err"; exit 1; }
done
echo "analog values exact, out-of-range inputs refused, two instances apart, a trap stops one"

echo "--- 4. programs an FMU cannot carry"
expect_refused() {  # FILE WANT
  if "$plcfi" export-fmu "$1" -o "$work/bad.fmu" > /dev/null 2> "$work/export.err"; then
    echo "exported $1"
    exit 1
  else
    s=$?
  fi
  cat "$work/export.err"
  test $s -eq 2
  grep -qF "$2" "$work/export.err"
  test ! -e "$work/bad.fmu"
}
cat > "$work/lint.st" <<'ST'
PROGRAM Main
VAR
  count AT %QL1 : LINT;
  go AT %IX0.0 : BOOL;
END_VAR
IF go THEN count := count + 1; END_IF;
END_PROGRAM
ST
expect_refused "$work/lint.st" "lint.st:3:3: Main.count at %QL1 is LINT: FMI 2.0 has no type that holds every value of it exactly"
cat > "$work/noio.st" <<'ST'
PROGRAM Main
VAR x : INT; END_VAR
x := x + 1;
END_PROGRAM
ST
expect_refused "$work/noio.st" "the program declares no variable at a %I or %Q address"
cat > "$work/overlap.st" <<'ST'
PROGRAM Main
VAR
  status AT %IW0 : WORD;
  ready AT %IX0.3 : BOOL;
  lamp AT %QX0.0 : BOOL;
END_VAR
lamp := ready AND status > 0;
END_PROGRAM
ST
expect_refused "$work/overlap.st" "Main.status at %IW0 and Main.ready at %IX0.3 share bits of the input image"
echo "program FMU OK"
