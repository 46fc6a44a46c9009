#!/usr/bin/env bash
# An FMU that cannot be used is a precise error and exit 2, never a crash or a hang: broken
# archives and descriptions, a missing binary or symbol, a wrong FMI version, and failures
# during the run (fmi2Error, a crash inside the FMU, exit() or abort() inside it, the end
# of its simulation, a stop time it needs), in sim and in a campaign. Plant-file mistakes point at their line and column.
# usage: fmu_errors.sh PLCFI SOURCE_DIR FMU_DIR
set -euo pipefail
plcfi=$1
src=$2
fmus=$3
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_fmuerr_XXXXXX")
trap 'rm -rf "$work"' EXIT
cat > "$work/prog.st" <<'ST'
PROGRAM Main
VAR
  en AT %QX0.0 : BOOL := TRUE;
  steps AT %IW2 : INT;
END_VAR
END_PROGRAM
ST
plant() {  # fmu-file [extra lines] -> $work/p.yaml
  { echo "fmu: $fmus/$1"; echo "step: 10ms"; [[ $# -gt 1 ]] && printf '%s\n' "$2"
    echo "map:"; echo "  - {image: \"%QX0.0\", plant: Enable}"; echo "  - {image: \"%IW2\", plant: Steps}"; } > "$work/p.yaml"
}
expect() {  # message-part command...
  local want=$1 status=0
  shift
  timeout 10 "$@" > "$work/out.txt" 2>&1 || status=$?
  echo "[exit $status] $(head -c 400 "$work/out.txt")"
  (( status == 2 )) || { echo "expected exit 2"; return 1; }
  grep -qF -- "$want" "$work/out.txt" || { echo "expected: $want"; return 1; }
}
sim() { expect "$1" "$plcfi" sim "$work/prog.st" --plant "$work/p.yaml" --duration 3s; }

plant probe_bad_xml.fmu;        sim "$work/p.yaml:1:6: fmu: $fmus/probe_bad_xml.fmu/modelDescription.xml:32:65: XML error"
plant probe_fmi1.fmu;           sim "fmiVersion '1.0': plcfi loads FMI 2.0 co-simulation FMUs"
plant probe_fmi3.fmu;           sim "fmiVersion '3.0': plcfi loads FMI 2.0 co-simulation FMUs (FMI 3.0 is not supported yet"
plant probe_no_binary.fmu;      sim "no binary for this platform: binaries/linux64/probe.so is missing"
plant probe_no_cosim.fmu;       sim "a Model Exchange FMU (no <CoSimulation> element)"
plant probe_missing_symbol.fmu; sim "binaries/linux64/probe_missing_symbol.so does not define fmi2DoStep"
plant not_a_zip.fmu;            sim "not_a_zip.fmu: not an FMU (an FMU is a zip archive)"
plant no_such.fmu;              sim "no_such.fmu: cannot open (No such file or directory)"

plant probe.fmu "parameters: {FailAt: 1.5}"
sim "fmi2DoStep(t = 1.5 s, h = 0.01 s) returned fmi2Error (the FMU logged: step failed at t = 1.5"
plant probe.fmu "parameters: {CrashAt: 0.5}"
sim "fmi2DoStep crashed inside the FMU (Segmentation fault, signal 11)"
plant probe.fmu $'call_timeout: 500ms\nparameters: {HangAt: 0.5}'
sim "fmi2DoStep did not return within 500ms (the FMU hangs; call_timeout in the plant file sets the limit)"
# An FMU that ends the process inside a call: named with the call, exit 2 (never the
# FMU's own status 0).
plant probe.fmu "parameters: {ExitAt: 0.5}"
sim "plcfi: FMU $fmus/probe.fmu: fmi2DoStep ended the process (exit() inside the FMU); an FMU must return a status"
plant probe.fmu "parameters: {AbortAt: 0.5}"
sim "fmi2DoStep crashed inside the FMU (Aborted, signal 6)"
plant probe.fmu "parameters: {EndAt: 2.5}"
sim "returned fmi2Discard: the FMU ended its simulation at t = 2.5 s (its DefaultExperiment stopTime is 10 s)"
plant probe.fmu "parameters: {NeedStopTime: true}"
sim "probe needs a stop time"
plant probe.fmu $'stop_time: 2s\nparameters: {NeedStopTime: true}'
sim "goes past the stop time 2"
plant probe.fmu "parameters: {Speed: 1}"
sim "$work/p.yaml:3:21: the FMU has no variable 'Speed' (its parameters: TogglePeriod, FailAt, CrashAt, EndAt, NeedStopTime, InternalStep, HangAt, ExitAt, AbortAt)"
plant probe.fmu "stop_time: soon"
sim "$work/p.yaml:3:12: stop_time: expected a duration, got 'soon'"

# An FMU named where a plant file belongs.
expect "$fmus/probe.fmu: an FMU plant is named by a plant file (YAML: fmu: $fmus/probe.fmu, its step and the map" \
  "$plcfi" sim "$work/prog.st" --plant "$fmus/probe.fmu" --duration 1s

# A campaign whose plant fails mid-run stops with the FMU's error.
sed -e "s|^plant: stamping|plant: $work/p.yaml|" -e "s|\.\./\.\./\.\./st_programs|$src/st_programs|" \
    -e "s|^tsd: |tsd: $src/faults/campaigns/stamping/|" -e "s|^fmea: |fmea: $src/faults/campaigns/stamping/|" \
    -e "s|^fault_classes: |fault_classes: $src/faults/campaigns/stamping/|" \
    "$src/faults/campaigns/stamping/campaign.yaml" > "$work/campaign.yaml"
plant probe.fmu "parameters: {FailAt: 0.2}"
expect "fmi2DoStep(t = 0.2 s, h = 0.01 s) returned fmi2Error" "$plcfi" campaign "$work/campaign.yaml" --out "$work/c" --quiet
plant probe.fmu "parameters: {ExitAt: 0.2}"
expect "fmi2DoStep ended the process (exit() inside the FMU)" "$plcfi" campaign "$work/campaign.yaml" --out "$work/c2" --quiet
plant probe.fmu "parameters: {ExitAt: 0.2}"
expect "fmi2DoStep ended the process (exit() inside the FMU)" "$plcfi" campaign "$work/campaign.yaml" --out "$work/c3" --quiet --jobs 2
echo "FMU errors OK"
