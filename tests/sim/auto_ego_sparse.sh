#!/usr/bin/env bash
# The `auto` ego rule on a sparse grid network (docs/scenarios.md, "The auto ego"), built here
# from plain XML: 3 x 3 junctions 400 m apart. `lonely` drives the bottom row and up the east side
# for the whole run and never has another vehicle within its grid; `pair_a` and `pair_b` drive
# together along the top row and leave after about 30 s. The vehicle that stays longest is
# `lonely` (what the rule before this one chose); the rule must choose one of the pair, say why
# in summary.json, and the run must score the other. With `lonely` alone, the run must say in one
# line that no vehicle can see another (nothing can be scored), not end silently with zeros.
# Usage: auto_ego_sparse.sh DUALGRID NETCONVERT
set -uo pipefail
dualgrid=$(realpath "$1")
netconvert=$2
source "$(dirname "$0")/run_checks.sh" auto_sparse

{
  echo '<nodes>'
  for i in 0 1 2; do for j in 0 1 2; do
    echo "  <node id=\"n$i$j\" x=\"$((400 * i))\" y=\"$((400 * j))\" type=\"priority\"/>"
  done; done
  echo '</nodes>'
} >grid.nod.xml
{
  echo '<edges>'
  for i in 0 1 2; do for j in 0 1 2; do
    [ "$i" -lt 2 ] && echo "  <edge id=\"h$i${j}e\" from=\"n$i$j\" to=\"n$((i + 1))$j\" numLanes=\"1\" speed=\"13.9\"/>" &&
      echo "  <edge id=\"h$i${j}w\" from=\"n$((i + 1))$j\" to=\"n$i$j\" numLanes=\"1\" speed=\"13.9\"/>"
    [ "$j" -lt 2 ] && echo "  <edge id=\"v$i${j}n\" from=\"n$i$j\" to=\"n$i$((j + 1))\" numLanes=\"1\" speed=\"13.9\"/>" &&
      echo "  <edge id=\"v$i${j}s\" from=\"n$i$((j + 1))\" to=\"n$i$j\" numLanes=\"1\" speed=\"13.9\"/>"
  done; done
  echo '</edges>'
} >grid.edg.xml
"$netconvert" --node-files grid.nod.xml --edge-files grid.edg.xml --no-turnarounds true \
  --offset.disable-normalization true --output-file grid.net.xml >netconvert.log 2>&1 ||
  { cat netconvert.log; exit 1; }
cat >traffic.rou.xml <<'X'
<routes>
  <vType id="car" maxSpeed="13.9" sigma="0"/>
  <vehicle id="lonely" type="car" depart="0" departSpeed="max"><route edges="h00e h10e v20n v21n"/></vehicle>
  <vehicle id="pair_a" type="car" depart="0" departPos="60" departSpeed="max"><route edges="h02e"/></vehicle>
  <vehicle id="pair_b" type="car" depart="0" departPos="20" departSpeed="max"><route edges="h02e"/></vehicle>
</routes>
X
printf 'network: grid.net.xml\nduration: 60\nego: {from_routes: auto}\ntraffic: {route_files: [traffic.rou.xml]}\n' >sparse.yaml
timeout 300 "$dualgrid" run sparse.yaml --modes dual --no-figures --no-record --out run >run.log 2>&1 ||
  fail "run: $(tail -n 1 run.log)"
s=run/summary.json
ego=$(json $s "d['ego']")
case "$ego" in pair_a | pair_b) ;; *) fail "auto chose '$ego', expected pair_a or pair_b (lonely sees nobody)" ;; esac
[ "$(json $s "d['ego_choice']['candidates']")" = 3 ] || fail "candidates: $(json $s "d['ego_choice']")"
[ "$(json $s "d['ego_choice']['with_traffic']")" = 2 ] || fail "with_traffic: $(json $s "d['ego_choice']")"
python3 -c "import sys; sys.exit(0 if $(json $s "d['ego_choice']['seen_s']") > 20 else 1)" ||
  fail "the chosen ego saw traffic for $(json $s "d['ego_choice']['seen_s']") s only"
json $s "d['ego_choice']['reason']" | grep -q "with another vehicle in its grid longest" ||
  fail "no reason in summary.json"
scored=$(scored run)
python3 -c "import sys; sys.exit(0 if $scored >= 1 else 1)" || fail "objects scored: $scored"
# The rule can fail: lonely stays the whole 60 s (its route is 1.6 km at 13.9 m/s), so a rule by
# time in the run alone picks it; the pair leaves after about 25 s.
python3 -c "import sys; sys.exit(0 if $(json $s "d['ego_choice']['in_run_s']") < 40 else 1)" ||
  fail "the chosen ego stayed $(json $s "d['ego_choice']['in_run_s']") s: is it the longest-staying?"
# A scene of one vehicle: it runs (exit 0, complete), says in one warning line, also under -q,
# that nothing can be scored, and summary.json says why.
grep -v pair traffic.rou.xml >alone.rou.xml
printf 'network: grid.net.xml\nduration: 60\nego: {from_routes: auto}\ntraffic: {route_files: [alone.rou.xml]}\n' >alone.yaml
timeout 300 "$dualgrid" run alone.yaml --modes dual --no-figures --no-record -q --out alone >alone.log 2>&1
rc=$?
{ [ "$rc" -eq 0 ] && [ "$(grep -c . alone.log)" -eq 1 ] &&
  grep -q "^dualgrid: warning: ego: auto chose 'lonely', but no road vehicle of the route files ever had another vehicle in its grid (1 candidates): nothing can be scored" alone.log; } ||
  fail "one vehicle alone: exit $rc: $(cat alone.log)"
[ "$(json alone/summary.json "d['ego_choice']['with_traffic']")" = 0 ] || fail "alone: with_traffic"
[ "$(json alone/summary.json "d['complete']")" = True ] || fail "alone: not complete"
[ "$failed" -eq 0 ] && echo "auto ego on a sparse network: all checks passed (chose $ego)"
exit "$failed"
