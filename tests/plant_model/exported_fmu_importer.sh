#!/usr/bin/env bash
# The stamping plant as `plcfi plant export-fmu` packs it, loaded by an importer of our own
# (tests/plant_model/fmu/importer.c: dlopen, every one of the 34 FMI 2.0 co-simulation
# functions resolved, the standard's calling sequence): all functions are there, the slider
# moves when its valve opens, the FMU state restores a run exactly, and what the FMU does
# not offer (serialization, derivatives) it refuses with fmi2Error and a log message.
# usage: exported_fmu_importer.sh PLCFI IMPORTER
set -euo pipefail
plcfi=$1
importer=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_import_XXXXXX")
trap 'rm -rf "$work"' EXIT

"$plcfi" plant export-fmu -o "$work/stamping.fmu"
mkdir "$work/unpacked"
(cd "$work/unpacked" && cmake -E tar xf ../stamping.fmu)
md=$work/unpacked/modelDescription.xml
grep -q 'canGetAndSetFMUstate="true" canSerializeFMUstate="false"' "$md"
id=$(sed -n 's/.*modelIdentifier="\([^"]*\)".*/\1/p' "$md")
guid=$(sed -n 's/.*guid="\([^"]*\)".*/\1/p' "$md")
vr() { sed -n "s/.*ScalarVariable name=\"$1\" valueReference=\"\([0-9]*\)\".*/\1/p" "$md"; }
# The slider valve opens at step 50 (of 10 ms): PosCrane goes off, PosStamp comes on.
"$importer" "$work/unpacked" "$id" "$guid" 0.01 600 --state \
  --bool-in "$(vr SliderExtend)@50" --bool-out "$(vr PosCrane)" --bool-out "$(vr PosStamp)" > "$work/out.txt"
cat "$work/out.txt" | uniq -c
grep -qx "resolved all 34 functions" "$work/out.txt"
grep -qx "state restored: the second half ran the same" "$work/out.txt"
grep -qx "refused with a log message: serialization, derivatives, cancel" "$work/out.txt"
grep -qx ok "$work/out.txt"
# Retracted first, extended in the end: the FMU was driven, not merely loaded.
test "$(sed -n 2p "$work/out.txt")" = 10
test "$(grep -x '[01][01]' "$work/out.txt" | tail -n 1)" = 01
echo "exported FMU OK"
