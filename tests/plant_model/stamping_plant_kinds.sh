#!/usr/bin/env bash
# The stamping campaign on the three kinds of plant gives the same verdicts: the built-in
# model, the same model exported as an FMU (plcfi plant export-fmu) and the stamping plant
# written in ST (plant_model/stamping/st). stamping.st: the initialization-run case FAILS,
# all others PASS; stamping_fixed.st: all PASS. The journal and the JUnit report name the
# plant; a traced sim names it in the VCD header.
# usage: stamping_plant_kinds.sh PLCFI SOURCE_DIR
set -euo pipefail
plcfi=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi_kinds_XXXXXX")
trap 'rm -rf "$work"' EXIT

"$plcfi" plant export-fmu -o "$work/stamping.fmu" --plant-file "$work/stamping_fmu.yaml"
"$plcfi" plant info "$work/stamping_fmu.yaml" | tee "$work/info.txt"
grep -q "^plant stamping: $work/stamping_fmu.yaml (FMU stamping.fmu, FMI 2.0 co-simulation)" "$work/info.txt" ||
  grep -q "FMU $work/stamping.fmu, FMI 2.0 co-simulation" "$work/info.txt"
grep -q "%IX0.4   StampLowered" "$work/info.txt"

verdicts() { sed -n 's/^\(TC[0-9]*\) *\([0-9-]*\) *\(PASS\|FAIL\|NOT REACHED\) .*/\1 \2 \3/p' "$1" | sort; }
camp=$src/faults/campaigns/stamping
for prog in stamping stamping_fixed; do
  for kind in builtin fmu st; do
    case $kind in
      builtin) plant=stamping ;;
      fmu) plant=$work/stamping_fmu.yaml ;;
      st) plant=$src/plant_model/stamping/st/stamping_st.yaml ;;
    esac
    sed -e "s|^plant: stamping|plant: $plant|" -e "s|\.\./\.\./\.\./st_programs/stamping/stamping.st|$src/st_programs/stamping/$prog.st|" \
        -e "s|^tsd: tsd.yaml|tsd: $camp/tsd.yaml|" -e "s|^fmea: fmea.csv|fmea: $camp/fmea.csv|" \
        -e "s|^fault_classes: fault_classes.yaml|fault_classes: $camp/fault_classes.yaml|" \
        "$camp/campaign.yaml" > "$work/$prog.$kind.yaml"
    status=0
    "$plcfi" campaign "$work/$prog.$kind.yaml" --out "$work/out.$prog.$kind" --quiet --no-vcd --junit "$work/$prog.$kind.xml" \
      > "$work/$prog.$kind.txt" || status=$?
    echo "== $prog on the $kind plant: exit $status"
    tail -n 3 "$work/$prog.$kind.txt"
    verdicts "$work/$prog.$kind.txt" > "$work/$prog.$kind.v"
    grep -q "\"plant\":\"$plant\"" "$work/out.$prog.$kind/results.jsonl"
    grep -q "<property name=\"plant\" value=\"$plant\"/>" "$work/$prog.$kind.xml"
    if [[ $prog == stamping ]]; then
      (( status == 1 ))
      grep -q "^TC3 1 FAIL$" "$work/$prog.$kind.v"        # the initialization run: no supervision
      (( $(grep -c " FAIL$" "$work/$prog.$kind.v") == 1 ))
    else
      (( status == 0 ))
      ! grep -q " FAIL$" "$work/$prog.$kind.v"
    fi
    (( $(wc -l < "$work/$prog.$kind.v") >= 8 ))
  done
  # The exported FMU is the built-in model: the very same executions, path by path.
  diff "$work/$prog.builtin.v" "$work/$prog.fmu.v"
  # The ST plant is a simpler twin (no random variation): the same verdict per case.
  diff <(cut -d' ' -f1,3 "$work/$prog.builtin.v" | sort -u) <(cut -d' ' -f1,3 "$work/$prog.st.v" | sort -u)
done

"$plcfi" sim "$src/st_programs/stamping/stamping_fixed.st" --plant "$src/plant_model/stamping/st/stamping_st.yaml" \
  --duration 60s --vcd "$work/st.vcd" | tee "$work/sim.txt"
grep -q "plant file      $src/plant_model/stamping/st/stamping_st.yaml (ST plant StampingPlant" "$work/sim.txt"
grep -q "stamped 1[0-9], defective 0, collisions 0" "$work/sim.txt"
grep -q "^\$comment plcfi sim on plant StampingPlant: $src/plant_model/stamping/st/stamping_st.yaml" "$work/st.vcd"
echo "same verdicts on the built-in, FMU and ST stamping plants"
