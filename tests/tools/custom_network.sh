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
echo "custom network guide: 1 passed, 0 failed"
