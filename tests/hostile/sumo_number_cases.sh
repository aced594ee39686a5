#!/bin/bash
# Numbers and names in users' SUMO files (issue 42): a bad vType, vehicle or flow attribute in a
# route or additional file, or in the files a .sumocfg names, and a bad --set value, must end with
# exit 2 and one "dualgrid: error:" line naming the file (or key), the attribute and the range:
# never a SIGABRT inside libsumo, never a silent run.
# Usage: sumo_number_cases.sh DUALGRID NETWORK_DIR
set -u
exe=$1
net_dir=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/dualgrid_sumo_numbers.XXXXXX")
trap 'rm -rf "$work"' EXIT
cp "$net_dir/simple_road.net.xml" "$work/road.net.xml"
failures=0 cases=0

# check NAME EXPECTED_WORDS -- ARGS...: exit 2, one error line, holding EXPECTED_WORDS.
check() {
  local name=$1 expected=$2
  shift 3
  cases=$((cases + 1))
  local out rc
  out=$(cd "$work" && timeout 60 "$exe" "$@" --out "$work/out" -q 2>&1)
  rc=$?
  local lines
  lines=$(printf '%s\n' "$out" | grep -c '^dualgrid: error:')
  if [[ $rc -ne 2 || $lines -ne 1 || "$out" != *"$expected"* ]]; then
    echo "FAIL $name: rc=$rc, $lines error line(s), expected '$expected':"
    printf '%s\n' "$out" | head -5
    failures=$((failures + 1))
  fi
}

# A route file whose vType (or vehicle) carries ATTRIBUTE; the ego is one of its vehicles.
route_case() {
  local name=$1 element=$2 expected=$3 kind=${4:-route}
  cat > "$work/$name.xml" <<XML
<routes>
  $element
  <vehicle id="ego" type="t" depart="0"><route edges="east_1 east_2"/></vehicle>
</routes>
XML
  local key=route_files
  [[ $kind == additional ]] && key=additional_files
  printf 'name: n\nnetwork: road.net.xml\ntraffic: {%s: [%s.xml]}\nego: {from_routes: ego}\nduration: 1\n' \
    "$key" "$name" > "$work/$name.yaml"
  check "$name" "$expected" -- sim "$name.yaml"
}

for attr in length width height minGap maxSpeed accel decel emergencyDecel apparentDecel \
            speedFactor sigma tau actionStepLength; do
  for value in nan -inf 1e999 1e300 -1; do
    [[ $attr == minGap || $attr == sigma ]] && [[ $value == -1 ]] && value=-0.5
    route_case "vtype_${attr}_${value//[^a-z0-9]/_}" "<vType id=\"t\" $attr=\"$value\"/>" \
      "<vType id=\"t\"> $attr=\"$value\": expected"
  done
done
route_case vtype_in_additional '<vType id="t" length="nan"/>' 'length="nan": expected in (0, 30] m' additional
route_case car_following '<vType id="t"><carFollowing-Krauss accel="inf"/></vType>' \
  '<carFollowing-Krauss> accel="inf"'
route_case vclass '<vType id="t" vClass="spaceship"/>' 'expected a SUMO vehicle class, one of:'
route_case distribution '<vType id="t" speedFactor="norm(nan,0.1)"/>' 'arguments are finite'
route_case depart_speed '<vType id="t"/><vehicle id="v" type="t" depart="0" departSpeed="1e9"><route edges="east_1"/></vehicle>' \
  'departSpeed="1e9": expected in [0, 70] m/s'
route_case stop_duration '<vType id="t"/><vehicle id="s" type="t" depart="0"><route edges="east_1 east_2"/><stop lane="east_2_0" duration="nan"/></vehicle>' \
  '<stop> duration="nan": expected in [0,'
route_case flow_period '<vType id="t"/><flow id="f" type="t" begin="0" end="10" period="nan" from="east_1" to="east_2"/>' \
  'period="nan"'

# The files a .sumocfg names are checked the same way; two networks in one net-file refused.
cat > "$work/cfg.rou.xml" <<'XML'
<routes>
  <vType id="t" maxSpeed="inf"/>
  <vehicle id="ego" type="t" depart="0"><route edges="east_1 east_2"/></vehicle>
</routes>
XML
printf '<configuration><input><net-file value="road.net.xml"/><route-files value="cfg.rou.xml"/></input></configuration>\n' > "$work/a.sumocfg"
printf 'name: c\nsumo_config: a.sumocfg\nego: {from_routes: ego}\nduration: 1\n' > "$work/cfg.yaml"
check sumocfg_route 'maxSpeed="inf": expected in (0, 70] m/s' -- sim cfg.yaml
cp "$work/road.net.xml" "$work/other.net.xml"
printf '<configuration><input><net-file value="road.net.xml,other.net.xml"/></input></configuration>\n' > "$work/two.sumocfg"
printf 'name: c\nsumo_config: two.sumocfg\nego: {from_routes: auto}\nduration: 1\n' > "$work/two.yaml"
check two_nets 'expected one network file, got 2' -- sim two.yaml

# --set: the user's key, the user's units, the same ranges.
scenario="$(dirname "$0")/../../scenarios/simple_road.yaml"
scenario=$(cd "$(dirname "$scenario")" && pwd)/simple_road.yaml
check set_vclass "key 'vehicle_types.car.vclass' expected a SUMO vehicle class" -- \
  sim "$scenario" --duration 1 --set vehicle_types.car.vclass=spaceship
check set_seed "key 'seed' expected a whole number in [0, 9007199254740991]" -- \
  sim "$scenario" --duration 1 --set seed=9007199254740993
check set_gate "key 'evaluation.gate_box_margin' expected finite and >= 0" -- \
  sim "$scenario" --duration 1 --set evaluation.gate_box_margin=-1
check set_degrees "expected in (0, 360] deg" -- \
  sim "$scenario" --duration 1 --set sensors.overrides.front.fov_deg=400
check set_width "key 'filter.width_y' expected at most 200000000 cells" -- \
  sim "$scenario" --duration 1 --set filter.width_y=1e300
check set_resolution "at most 200000000 cells" -- \
  sim "$scenario" --duration 1 --set filter.resolution=1e-9
check set_length "key 'vehicle_types.car.length' expected in (0, 30] m" -- \
  sim "$scenario" --duration 1 --set vehicle_types.car.length=1e9

echo "$cases cases, $failures failed"
[[ $failures -eq 0 ]]
