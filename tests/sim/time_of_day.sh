#!/usr/bin/env bash
# A SUMO configuration that starts at a time of day (docs/scenarios.md, "Time of day"), built here
# from plain XML: a 2 km road, demand departing from 07:00 (25200 s), <begin value="25200"/>, and
# a <remote-port> that must make nothing wait for a TraCI client. Checks that dualgrid runs it
# with `ego: {from_routes: auto}` from the configuration's own begin, that `begin` and --begin
# override it, that the clocks are named, and the bad cases (a begin after the configuration's
# end, a negative begin, an explicit ego that departs before the begin) exit 2 with one line.
# Usage: time_of_day.sh DUALGRID NETCONVERT
set -uo pipefail
dualgrid=$(realpath "$1")
netconvert=$2
source "$(dirname "$0")/run_checks.sh" time_of_day

cat >road.nod.xml <<'X'
<nodes>
  <node id="w" x="0" y="0"/>
  <node id="e" x="2000" y="0"/>
</nodes>
X
cat >road.edg.xml <<'X'
<edges>
  <edge id="east" from="w" to="e" numLanes="2" speed="25"/>
  <edge id="west" from="e" to="w" numLanes="2" speed="25"/>
</edges>
X
"$netconvert" --node-files road.nod.xml --edge-files road.edg.xml --no-turnarounds true \
  --offset.disable-normalization true --output-file road.net.xml >netconvert.log 2>&1 ||
  { cat netconvert.log; exit 1; }
# Morning demand: a platoon eastbound from 07:00:05 and traffic westbound; one early vehicle
# that SUMO skips (it departs before the begin).
{
  echo '<routes>'
  echo '  <route id="e" edges="east"/>'
  echo '  <route id="w" edges="west"/>'
  echo '  <vehicle id="night" depart="25000" route="e"/>'
  for k in 0 1 2 3 4 5; do
    echo "  <vehicle id=\"car$k\" depart=\"$((25205 + 3 * k))\" route=\"e\" departLane=\"$((k % 2))\"/>"
  done
  echo '  <flow id="oncoming" begin="25200" end="25300" period="10" route="w"/>'
  echo '</routes>'
} >morning.rou.xml
# A detector whose output goes into the run folder (a relative --out, as users type it).
printf '<additional>\n  <inductionLoop id="loop" lane="east_0" pos="100" period="60" file="loop.xml"/>\n</additional>\n' \
  >detector.add.xml
port=$((20000 + $$ % 20000))
cat >morning.sumocfg <<X
<configuration>
  <input>
    <net-file value="road.net.xml"/>
    <route-files value="morning.rou.xml"/>
    <additional-files value="detector.add.xml"/>
  </input>
  <time>
    <begin value="25200"/>
    <end value="28800"/>
  </time>
  <traci_server>
    <remote-port value="$port"/>
  </traci_server>
</configuration>
X
printf 'sumo_config: morning.sumocfg\nduration: 40\nego: {from_routes: auto}\n' >morning.yaml

# 1. The configuration's own begin, an auto ego, the remote port never waited for (timeout).
timeout 300 "$dualgrid" run morning.yaml --modes dual --no-figures --no-record --out run1 \
  >run1.log 2>&1
rc=$?
[ "$rc" -eq 0 ] || fail "run from the configuration's begin: exit $rc: $(tail -n 2 run1.log)"
grep -q "remote-port value=\"$port\"/> (TraCI) is not opened" run1.log ||
  fail "no line about the configuration's <remote-port>: $(cat run1.log)"
s=run1/summary.json
[ "$(json $s "d['complete']")" = True ] || fail "run1 not complete"
[ "$(json $s "d['begin_s']")" = 25200.0 ] || fail "begin_s $(json $s "d['begin_s']"), expected 25200"
[ "$(json $s "d['begin_source']")" = sumo_config ] || fail "begin_source $(json $s "d['begin_source']")"
depart=$(json $s "d['ego_choice']['depart_sumo_s']")
python3 -c "import sys; sys.exit(0 if 25200 < $depart < 25240 else 1)" ||
  fail "the auto ego departs at SUMO time $depart, expected within the run (25200, 25240)"
ego=$(json $s "d['ego']")
case "$ego" in car* | oncoming.*) ;; *) fail "auto chose '$ego', expected one of the morning's vehicles" ;; esac
grep -q "auto chose '$ego' (the road vehicle of the route files with another vehicle in its grid longest" run1.log ||
  fail "the choice and its reason are not printed: $(grep auto run1.log)"
scored=$(scored run1)
python3 -c "import sys; sys.exit(0 if $scored >= 1 else 1)" || fail "objects scored: $scored, expected >= 1"
# Outputs are in run time: the ground truth's first time is within the 40 s, not 25200 s.
first=$(awk -F, 'NR == 2 {print $2; exit}' run1/ground_truth.csv)
python3 -c "import sys; sys.exit(0 if 0 <= $first <= 40 else 1)" ||
  fail "ground_truth.csv's first time $first is not run time"
# Nothing written beside the configuration's files.
[ "$(ls | grep -v -E '^(run1|run1.log|road\.(nod|edg|net)\.xml|netconvert\.log|morning\.(rou\.xml|sumocfg|yaml)|detector\.add\.xml)$')" = "" ] ||
  fail "files beside the configuration: $(ls)"

[ -s run1/sumo_outputs/loop.xml ] || fail "the detector's output is not in run1/sumo_outputs/"
# 2. `begin` in the scenario and --begin on the command line override the configuration's.
timeout 300 "$dualgrid" run morning.yaml --modes dual --no-figures --no-record --set begin=25210 \
  --duration 10 --out run2 -q >run2.log 2>&1 || fail "--set begin=25210: $(tail -n 1 run2.log)"
[ "$(json run2/summary.json "d['begin_source']")" = scenario ] || fail "begin key: source not 'scenario'"
[ "$(json run2/summary.json "d['begin_s']")" = 25210.0 ] || fail "begin key not used"
timeout 300 "$dualgrid" run morning.yaml --modes dual --no-figures --no-record --begin 25205 \
  --duration 20 --out run3 -q >run3.log 2>&1 || fail "--begin 25205: $(tail -n 1 run3.log)"
[ "$(json run3/summary.json "d['begin_source']")" = "command line" ] || fail "--begin: source"
[ "$(json run3/config.json "d['begin_s']")" = 25205.0 ] || fail "--begin not in config.json"

# 3. The scenario's own times count from the begin: a scenario of its own vehicles gives the same
# outputs, byte for byte, whatever its begin.
cat >own.yaml <<'X'
network: road.net.xml
duration: 6
routes: {e: [east]}
ego: {type: car, route: e, lane: 0, position: 100, speed: 20}
traffic:
  vehicles:
    - {id: lead, type: car, route: e, lane: 0, position: 140, speed: 20}
    - {id: late, type: car, route: e, depart: 2, lane: 1, position: 60, speed: 25}
X
for b in 0 25200; do
  timeout 300 "$dualgrid" run own.yaml --modes dual --no-figures --no-record --begin "$b" \
    --out "own_$b" -q >/dev/null 2>&1 || fail "own vehicles, begin $b"
done
for f in ground_truth.csv clusters.csv objects.csv grid.csv; do
  cmp -s "own_0/$f" "own_25200/$f" || fail "own vehicles: $f differs between begin 0 and 25200"
done

# 4. Bad input: one line, exit 2, naming the clock.
check() {  # NAME EXPECTED-TEXT ARGS...
  local name=$1 text=$2
  shift 2
  timeout 120 "$dualgrid" "$@" >"$name.log" 2>&1
  local rc=$?
  if [ "$rc" -ne 2 ] || [ "$(grep -vc '^dualgrid: warning' "$name.log")" -ne 1 ] ||
    ! grep -qF -- "$text" "$name.log"; then
    fail "$name: exit $rc, expected 2 and one line with '$text': $(cat "$name.log")"
  fi
}
check begin_after_end "< the configuration's end = 28800 s (SUMO time)" \
  run morning.yaml --no-figures --begin 30000 --out bad1
check negative_begin "key 'begin' expected in [0, 31536000] s (SUMO time), got -5" \
  run morning.yaml --no-figures --set begin=-5 --out bad2
printf 'sumo_config: morning.sumocfg\nduration: 40\nego: {from_routes: night}\n' >night.yaml
check ego_before_begin "departs at SUMO time 25000 s and SUMO skips vehicles that depart before the begin" \
  run night.yaml --no-figures --out bad3
printf 'sumo_config: morning.sumocfg\nduration: 40\nbegin: 0\nego: {from_routes: car5}\n' >car5.yaml
check ego_after_end "but it departs at SUMO time 25220 s: set begin (or --begin) or a longer duration" \
  run car5.yaml --no-figures --out bad4
printf 'sumo_config: morning.sumocfg\nduration: 40\nbegin: 0\nego: {from_routes: auto}\n' >early.yaml
check auto_nothing_departs "no road vehicle of the route files departed within SUMO time [0, 40] s (run time [0, 40] s)" \
  run early.yaml --no-figures --no-record --out bad5
[ -e bad1/summary.json ] && fail "a refused run left a summary.json"
[ "$failed" -eq 0 ] && echo "time of day: all checks passed"
exit "$failed"
