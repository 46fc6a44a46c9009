#!/usr/bin/env bash
# Self-test of fmi2_md_check.py: a small valid FMI 2.0 co-simulation modelDescription.xml
# must pass, and each broken variant of it (one sed edit) must fail with exit status 1 and
# name the broken rule; unreadable or non-XML input and a missing argument give status 2.
# usage: fmi2_md_check_selftest.sh [PYTHON]
set -euo pipefail
python=${1:-python3}
checker=$(cd "$(dirname "$0")" && pwd)/fmi2_md_check.py
work=$(mktemp -d "${TMPDIR:-/tmp}/fmi2_md_check_XXXXXX")
trap 'rm -rf "$work"' EXIT

# Variables (index): 1 time, 2 k, 3 u, 4 enable, 5 y, 6 count, 7 k2, 8 mode, 9 y_alias, 10 stop.
# y_alias is an alias of y (same Real valueReference); stop shares valueReference 5 with y,
# which is allowed because the base types differ.
cat > "$work/valid.xml" <<'EOF'
<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="demo" guid="{8c4e810f-3df3-4a00-8276-176fa3c9f000}" variableNamingConvention="flat" numberOfEventIndicators="0" generationDateAndTime="2024-01-02T03:04:05Z">
  <CoSimulation modelIdentifier="demo" canHandleVariableCommunicationStepSize="true" canGetAndSetFMUstate="true" canSerializeFMUstate="false" maxOutputDerivativeOrder="0"/>
  <UnitDefinitions>
    <Unit name="N"><BaseUnit kg="1" m="1" s="-2"/><DisplayUnit name="kN" factor="0.001"/></Unit>
  </UnitDefinitions>
  <TypeDefinitions>
    <SimpleType name="Force"><Real quantity="Force" unit="N" min="0" max="100"/></SimpleType>
    <SimpleType name="Mode"><Enumeration><Item name="off" value="1"/><Item name="on" value="2"/></Enumeration></SimpleType>
  </TypeDefinitions>
  <LogCategories>
    <Category name="logAll" description="everything"/>
  </LogCategories>
  <DefaultExperiment startTime="0" stopTime="10" stepSize="0.01"/>
  <ModelVariables>
    <ScalarVariable name="time" valueReference="0" causality="independent" variability="continuous"><Real/></ScalarVariable>
    <ScalarVariable name="k" valueReference="1" causality="parameter" variability="fixed"><Real declaredType="Force" displayUnit="kN" start="2"/></ScalarVariable>
    <ScalarVariable name="u" valueReference="2" causality="input"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="enable" valueReference="4" causality="input" variability="discrete"><Boolean start="false"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="5" causality="output" initial="calculated"><Real/></ScalarVariable>
    <ScalarVariable name="count" valueReference="6" causality="output" variability="discrete" initial="exact"><Integer start="0"/></ScalarVariable>
    <ScalarVariable name="k2" valueReference="7" causality="calculatedParameter" variability="fixed"><Real unit="N"/></ScalarVariable>
    <ScalarVariable name="mode" valueReference="8" variability="discrete" initial="exact"><Enumeration declaredType="Mode" start="1"/></ScalarVariable>
    <ScalarVariable name="y_alias" valueReference="5"><Real/></ScalarVariable>
    <ScalarVariable name="stop" valueReference="5" causality="input" variability="discrete"><Boolean start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs>
      <Unknown index="5" dependencies="1 3" dependenciesKind="dependent constant"/>
      <Unknown index="6" dependencies="4"/>
    </Outputs>
    <InitialUnknowns>
      <Unknown index="5" dependencies="2 3"/>
      <Unknown index="7" dependencies="2"/>
    </InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
EOF

"$python" "$checker" "$work/valid.xml" > "$work/valid.out" || { cat "$work/valid.out"; exit 1; }
grep -qx "$work/valid.xml: ok (10 variables)" "$work/valid.out"
echo "ok   valid description"

n=0
fails() {  # NAME EXPECTED-TEXT SED-SCRIPT: the edited description fails naming the rule
  local name=$1 expected=$2 status=0
  sed -e "$3" "$work/valid.xml" > "$work/$name.xml"
  cmp -s "$work/valid.xml" "$work/$name.xml" && { echo "FAIL $name: the edit changed nothing"; exit 1; }
  "$python" "$checker" "$work/$name.xml" > "$work/$name.out" || status=$?
  if [ "$status" -ne 1 ] || ! grep -qF -- "$expected" "$work/$name.out"; then
    echo "FAIL $name (status $status), expected: $expected"; cat "$work/$name.out"; exit 1
  fi
  echo "ok   $name: $(grep -F -m1 -- "$expected" "$work/$name.out" | sed "s|^$work/||")"
  n=$((n + 1))
}

# 2.2.1 fmiModelDescription: attributes and child elements
fails unknown_root_attribute 'fmiModelDescription: attribute foo is not allowed here' 's/<fmiModelDescription /&foo="bar" /'
fails fmi_version 'fmiVersion="1.0" must be "2.0"' 's/fmiVersion="2.0"/fmiVersion="1.0"/'
fails naming_convention 'variableNamingConvention="tree" must be one of flat, structured' 's/"flat"/"tree"/'
fails wrong_order 'element DefaultExperiment is out of order' '/<DefaultExperiment/d; /<\/ModelVariables>/a\  <DefaultExperiment startTime="0"/>'
fails unknown_element 'element Foo is not allowed here' 's|<LogCategories>|<Foo/>&|'
fails no_fmu_kind 'at least one of ModelExchange and CoSimulation must be present' '/<CoSimulation/d'
fails empty_list 'LogCategories: the list must have at least one Category element' '/<Category /d'
# 4.3.1 CoSimulation
fails no_model_identifier 'CoSimulation: required attribute modelIdentifier is missing' 's/ modelIdentifier="demo"//'
fails model_identifier_c 'attribute modelIdentifier="my-model" must be a C identifier' 's/modelIdentifier="demo"/modelIdentifier="my-model"/'
fails capability_flag 'attribute canHandleVariableCommunicationStepSize="yes" must be a boolean' 's/Size="true"/Size="yes"/'
fails unknown_capability 'CoSimulation: attribute canDoMagic is not allowed here' 's/<CoSimulation /&canDoMagic="true" /'
fails serialize_needs_state 'canSerializeFMUstate="true" requires canGetAndSetFMUstate="true"' 's/canGetAndSetFMUstate="true" canSerializeFMUstate="false"/canSerializeFMUstate="true"/'
# 2.2.2 - 2.2.5 units, types, log categories, default experiment
fails undefined_unit 'unit "kN" is not defined in UnitDefinitions' '/name="k2"/ s/unit="N"/unit="kN"/'
fails undefined_type 'declaredType "Torque" is not defined in TypeDefinitions' 's/declaredType="Force"/declaredType="Torque"/'
fails enum_items 'item value 1 is not unique' 's/value="2"/value="1"/'
fails category_name 'LogCategories/Category[1]: required attribute name is missing' 's/Category name="logAll"/Category/'
fails experiment_number 'attribute stopTime="ten" must be a finite number' 's/stopTime="10"/stopTime="ten"/'
# 2.2.7 ScalarVariable
fails input_without_start 'variable "u": a start value is required (causality="input")' '/name="u"/ s/ start="0"//'
fails calculated_with_start 'variable "y": a start value is not allowed with initial="calculated"' '/name="y"/ s|<Real/>|<Real start="1"/>|'
fails exact_without_start 'variable "count": a start value is required (initial="exact")' '/name="count"/ s/ start="0"//'
fails constant_without_start 'variable "count": a start value is required (initial="exact")' '/name="count"/ { s/"discrete" initial="exact"/"constant"/; s/ start="0"//; }'
fails independent_with_start 'variable "time": a start value is not allowed with causality="independent"' '/name="time"/ s|<Real/>|<Real start="0"/>|'
fails bogus_causality 'attribute causality="bogus" must be one of parameter, calculatedParameter' '/name="y"/ s/"output"/"bogus"/'
fails duplicate_name 'variable "y": the name is not unique (also variable 5)' '/name="count"/ s/name="count"/name="y"/'
fails no_value_reference 'variable "u": required attribute valueReference is missing' '/name="u"/ s/ valueReference="2"//'
fails two_types 'exactly one type element (Real, Integer, Boolean, String, Enumeration) is required' '/name="u"/ s|<Real start="0"/>|&<Integer start="0"/>|'
fails duplicate_boolean_vr 'valueReference 4 (Boolean): shared by "enable", "stop": aliases must not be set independently' '/name="stop"/ s/valueReference="5"/valueReference="4"/'
fails continuous_boolean 'variable "enable": variability="continuous" is only allowed for Real, not Boolean' '/name="enable"/ s/ variability="discrete"//'
fails continuous_parameter 'variable "k": causality="parameter" with variability="continuous" is not allowed' '/name="k"/ s/"fixed"/"continuous"/'
fails initial_on_input 'variable "u": initial is not allowed with causality="input"' '/name="u"/ s/causality="input"/& initial="exact"/'
fails parameter_approx 'initial="approx" is not allowed with causality="parameter" and variability="fixed" (allowed: exact)' '/name="k"/ s/variability="fixed"/& initial="approx"/'
fails integer_start 'attribute start="0.5" must be a 32-bit integer' '/name="count"/ s/start="0"/start="0.5"/'
fails boolean_start 'attribute start="yes" must be a boolean (true, false, 1, 0)' '/name="enable"/ s/"false"/"yes"/'
fails real_attribute 'variable "y_alias"/Real: attribute min2 is not allowed here' '/name="y_alias"/ s|<Real/>|<Real min2="0"/>|'
fails start_above_max 'variable "k": start=200 is outside min..max' '/name="k"/ s/start="2"/start="200"/'
# 2.2.8 ModelStructure
fails output_not_listed 'variable "count": an output must be listed in ModelStructure/Outputs' '/<Unknown index="6"/d'
fails index_out_of_range 'ModelStructure/Outputs/Unknown[2]: index 42 is out of range (1..10)' 's/<Unknown index="6"/<Unknown index="42"/'
fails not_an_output 'Unknown[2]: variable "mode" is not an output' 's/<Unknown index="6"/<Unknown index="8"/'
fails structure_order 'ModelStructure: element Outputs is out of order' '/<Outputs>/,/<\/Outputs>/d; /<\/InitialUnknowns>/a\    <Outputs><Unknown index="5"/><Unknown index="6"/></Outputs>'
fails initial_unknowns_missing 'variable "k2": must be listed in ModelStructure/InitialUnknowns' '/<Unknown index="7"/d'
fails initial_unknowns_extra 'InitialUnknowns/Unknown[3]: variable "count" does not belong in InitialUnknowns' 's|<Unknown index="7" dependencies="2"/>|&<Unknown index="6"/>|'
fails initial_unknowns_order 'InitialUnknowns must be in ascending index order' '/<InitialUnknowns>/a\      <Unknown index="7"/>'
fails dependency_range 'dependency 11 is out of range (1..10)' 's/dependencies="4"/dependencies="11"/'
fails dependency_known 'dependency 2 (variable "k") is not a known of Outputs' 's/dependencies="4"/dependencies="2"/'
fails dependencies_kind_length 'dependenciesKind needs dependencies with the same number of entries' 's/"dependent constant"/"dependent"/'
fails dependencies_kind_value 'attribute dependenciesKind="dependent linear" must be a list of' 's/"dependent constant"/"dependent linear"/'

# Usage errors and input that is not a readable XML file: status 2.
status=0; "$python" "$checker" > /dev/null 2>&1 || status=$?; [ "$status" -eq 2 ]
status=0; "$python" "$checker" "$work/absent.xml" > /dev/null 2>&1 || status=$?; [ "$status" -eq 2 ]
echo 'not <xml' > "$work/bad.xml"
status=0; "$python" "$checker" "$work/bad.xml" > /dev/null 2> "$work/bad.err" || status=$?
[ "$status" -eq 2 ] && grep -q 'not XML' "$work/bad.err"
echo "ok   usage error, missing file and non-XML input give status 2"
echo "fmi2_md_check selftest: valid description passes, $n broken variants fail as expected"
