#!/usr/bin/env bash
# The custom-network guide of docs/scenarios.md, step by step, as a user would run it: copy the
# example, build its network with netconvert, take a snapshot, run the filters for a short time.
# Usage: custom_network.sh DUALGRID NETCONVERT
set -euo pipefail
dualgrid=$(realpath "$1")
netconvert=$2
export SUMO_HOME=${SUMO_HOME:-/usr/share/sumo}
src="$(cd "$(dirname "$0")/../.." && pwd)/docs/examples/custom_network"
work=$(mktemp -d "${TMPDIR:-/tmp}/dualgrid_custom_network.XXXXXX")
trap 'rm -rf "$work"' EXIT
cp "$src"/village.nod.xml "$src"/village.edg.xml "$src"/village.yaml "$work"/
cd "$work"
"$netconvert" --node-files village.nod.xml --edge-files village.edg.xml \
  --no-turnarounds true --offset.disable-normalization true --output-file village.net.xml >/dev/null
# From another folder: the network path is read relative to the scenario file.
cd /
"$dualgrid" snapshot "$work/village.yaml" --time 5 -q --out "$work/village.png"
"$dualgrid" run "$work/village.yaml" --duration 6 --no-figures -q --out "$work/run"
grep -q '^village,D,%,dual,1,' "$work/run/table.csv"
grep -q '^dual,[0-9]*,lead,' "$work/run/objects.csv"
# The ego and its lead turn left into the side street (docs/scenarios.md, "An ego that turns"):
# the grid keeps its start heading and re-centres on the ego; the lead leaves it through its side
# after turning and comes back when the ego has turned too. Scoring goes on throughout.
"$dualgrid" run "$work/village.yaml" --no-figures -q --out "$work/turn" \
  --set 'routes.left=[main_in, side_out]' --set ego.route=left --set traffic.vehicles.0.route=left
awk -F, '$5 == 1 { yaw = $8 } END { if (yaw < 1.4 || yaw > 1.75) { print "ego did not turn: yaw " yaw; exit 1 } }' \
  "$work/turn/ground_truth.csv"
steps=$(awk -F, 'NR > 1 && $5 == 1' "$work/turn/ground_truth.csv" | wc -l)
awk -F, -v steps="$steps" '$1 == "dual" && $3 == "lead" {
  found = 1
  if (!($4 > 100 && $4 < steps)) { print "lead in the grid for " $4 " of " steps " frames"; exit 1 }
  if ($7 != 1 || $8 < 0.9) { print "lead not tracked while in the grid: " $0; exit 1 } }
  END { if (!found) { print "lead not scored"; exit 1 } }' "$work/turn/objects.csv"
echo "custom network guide: 2 passed, 0 failed"
