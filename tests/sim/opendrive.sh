#!/usr/bin/env bash
# OpenDRIVE maps as a scenario's network (docs/scenarios.md, "OpenDRIVE maps"), on .xodr files
# written by tests/sim/write_xodr.py from the ASAM OpenDRIVE structure (not netconvert's output of
# our own networks): a straight road, a road of lines, arcs and clothoids, and a T junction with
# its connecting roads. Each runs end to end: converted once into the cache (keyed by the file's
# digest, never beside the map), traffic from randomTrips.py seeded by the scenario's seed, an
# auto ego, objects scored; on the junction, with the user's routes through it, the grid turns
# with the road, the figures are drawn and the replay viewer is written.
# Usage: opendrive.sh DUALGRID
set -uo pipefail
dualgrid=$(realpath "$1")
here=$(cd "$(dirname "$0")" && pwd)
export SUMO_HOME=${SUMO_HOME:-/usr/share/sumo}
if [ ! -f "$SUMO_HOME/tools/randomTrips.py" ]; then
  echo "SKIP: sumo-tools (randomTrips.py) is not installed"
  exit 77
fi
source "$here/run_checks.sh" opendrive
export DUALGRID_CACHE_DIR=$work/cache
mkdir -p "$work/maps" && cd "$work/maps" || exit 1
for kind in straight curves junction; do python3 "$here/write_xodr.py" "$kind" "$kind.xodr"; done
listing() { find "$work/maps" -type f -printf '%P %s %T@\n' | sort; }

# 1. Each map with nothing but the network and an auto ego: random traffic.
for kind in straight curves junction; do
  printf 'network: %s.xodr\nduration: 40\nseed: 3\nego: {from_routes: auto}\n' "$kind" >"$kind.yaml"
  before=$(listing)
  timeout 600 "$dualgrid" run "$kind.yaml" --modes dual --no-figures --no-record \
    --out "$work/run_$kind" -q >"$work/$kind.log" 2>&1 || { fail "$kind: $(tail -n 1 "$work/$kind.log")"; continue; }
  [ "$before" = "$(listing)" ] || fail "$kind: files written beside the map"
  s=$work/run_$kind/summary.json
  [ "$(json "$s" "d['complete']")" = True ] || fail "$kind: not complete"
  [ "$(json "$s" "d['network_source']")" = "$work/maps/$kind.xodr" ] || fail "$kind: network_source"
  python3 -c "import sys; sys.exit(0 if $(scored "$work/run_$kind") >= 1 else 1)" ||
    fail "$kind: no object scored"
  grep -q '<vehicle id="rt' "$work/run_$kind/random_trips.rou.xml" || fail "$kind: no random trips"
done
nets=$(find "$work/cache/networks" -name '*.net.xml' | wc -l)
[ "$nets" -eq 3 ] || fail "expected 3 converted networks in the cache, found $nets"
# The same seed gives the same trips; the map is converted once (the cached file is reused).
net=$(find "$work/cache/networks" -name 'straight-*.net.xml')
stamp=$(stat -c %Y.%s "$net")
timeout 600 "$dualgrid" run straight.yaml --modes dual --no-figures --no-record --out "$work/again" -q ||
  fail "straight, second run"
[ "$stamp" = "$(stat -c %Y.%s "$net")" ] || fail "the cached network was rewritten"
cmp -s <(grep '<vehicle' "$work/run_straight/random_trips.rou.xml") \
  <(grep '<vehicle' "$work/again/random_trips.rou.xml") || fail "same seed, different random trips"
# A changed map is a new cache entry (keyed by the file's digest, not its name).
echo '<!-- edited -->' >>straight.xodr
timeout 600 "$dualgrid" run straight.yaml --modes dual --no-figures --no-record --duration 5 \
  --out "$work/edited" -q >/dev/null 2>&1 || true
[ "$(find "$work/cache/networks" -name 'straight-*.net.xml' | wc -l)" -eq 2 ] ||
  fail "an edited map did not get a cache entry of its own"

# 2. The junction with the user's routes through it (edge ids of the converted map: road 1's
# right lane is edge -1 towards the junction, road 3's is -3 away from it): a platoon turning
# right from the west arm into the south arm, and a car turning left from the south arm.
cat >turns.rou.xml <<'X'
<routes>
  <vType id="car" sigma="0"/>
  <vehicle id="turn_lead" type="car" depart="0" departPos="60"><route edges="-1 -3"/></vehicle>
  <vehicle id="turn_mid" type="car" depart="0" departPos="30"><route edges="-1 -3"/></vehicle>
  <vehicle id="turn_last" type="car" depart="0" departPos="0"><route edges="-1 -3"/></vehicle>
  <vehicle id="left_in" type="car" depart="12"><route edges="3 1"/></vehicle>
</routes>
X
printf 'network: junction.xodr\nduration: 40\nego: {from_routes: auto}\ntraffic: {route_files: [turns.rou.xml]}\n' >turns.yaml
timeout 600 "$dualgrid" run turns.yaml --modes dual --out "$work/turns" -q >"$work/turns.log" 2>&1 ||
  fail "junction with routes: $(tail -n 1 "$work/turns.log")"
s=$work/turns/summary.json
[ "$(json "$s" "d['grid_frame']['realignments']")" -ge 1 ] 2>/dev/null || fail "the grid never turned"
turned=$(python3 - "$work/turns/grid.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
d = abs((float(rows[-1]["yaw_deg"]) - float(rows[0]["yaw_deg"]) + 180) % 360 - 180)
print(int(d))
PY
)
[ "$turned" -ge 60 ] || fail "the grid turned by $turned deg over a 90 deg turn"
ls "$work"/turns/figures/*.png >/dev/null 2>&1 || fail "no figures"
timeout 600 "$dualgrid" replay "$work/turns" --html -q || fail "replay --html"
[ -s "$work/turns/replay.html" ] || fail "no replay.html"
[ "$failed" -eq 0 ] && echo "OpenDRIVE: all checks passed"
exit "$failed"
