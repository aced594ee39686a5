#!/usr/bin/env bash
# SUMO's own example configurations (Debian's sumo-tools: tools/game/*.sumocfg and the RealWorld
# scenarios of sumolib), run as they are (docs/scenarios.md, "SUMO's own examples"): every one
# that `sumo -c` itself runs for 30 s must also run in dualgrid for 30 s with
# `ego: {from_routes: auto}` from the configuration's own begin, exit 0 with a complete
# summary.json, score objects where two vehicles share the road (or say that nothing can be
# scored), and write nothing beside the configuration's files. The examples are copied first: SUMO's own run writes its outputs
# (tripinfos.xml, ...) beside them.
# Usage: sumo_examples.sh DUALGRID [--table]   (--table: print D and D_v per mode as Markdown)
# A configuration whose files define no vehicle at all (persons only: tools/game/hiking) has
# nothing to be the ego: dualgrid refuses it with its one-line error (exit 2), which is checked.
# Exit 0: all passed; 1: one failed; 77: sumo-tools is not installed (ctest's SKIP_RETURN_CODE).
set -uo pipefail
dualgrid=$(realpath "$1")
table=${2:-}
export SUMO_HOME=${SUMO_HOME:-/usr/share/sumo}
game=$SUMO_HOME/tools/game
realworld=$SUMO_HOME/tools/sumolib/scenario/scenarios/RealWorld
if [ ! -d "$game" ] || ! command -v sumo >/dev/null; then
  echo "SKIP: sumo-tools (SUMO's example configurations in $game) or sumo is not installed"
  exit 77
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/dualgrid_sumo_examples.XXXXXX")
trap 'rm -rf "$work"' EXIT
cp -r "$game" "$work/game"
cp -r "$realworld" "$work/RealWorld"
passed=0 failed=0 refused=0 no_vehicle=0
rows=()
listing() { find "$1" -type f -printf '%P %s %T@\n' | sort; }
while IFS= read -r cfg; do
  name=${cfg#"$work/"}
  dir=$(dirname "$cfg")
  if ! (cd "$dir" && timeout 300 sumo -c "$cfg" --end 30 --no-step-log true \
        --duration-log.disable true --no-warnings true >"$work/sumo.log" 2>&1); then
    refused=$((refused + 1))
    echo "refused by sumo -c itself (not run): $name: $(grep -m1 -i error "$work/sumo.log")"
    continue
  fi
  scenario="$work/$(echo "$name" | tr '/' '_').yaml"
  printf 'sumo_config: %s\nduration: 30\nego: {from_routes: auto}\n' "$cfg" >"$scenario"
  before=$(listing "$dir")
  out="$work/out_$(basename "$scenario" .yaml)"
  timeout 600 "$dualgrid" run "$scenario" --out "$out" --no-figures -q >"$work/run.log" 2>&1
  rc=$?
  if [ "$rc" -eq 2 ] && [ "$(grep -c . "$work/run.log")" -eq 1 ] &&
     grep -q "define no vehicle, trip or flow to choose from" "$work/run.log"; then
    no_vehicle=$((no_vehicle + 1))
    echo "no vehicle to be the ego (refused, one line, exit 2): $name"
    continue
  fi
  if [ "$rc" -ne 0 ] || ! grep -q '"complete": true' "$out/summary.json"; then
    failed=$((failed + 1))
    echo "FAIL $name: $(grep -v warning "$work/run.log" | tail -n 1)"
    continue
  fi
  if [ "$before" != "$(listing "$dir")" ]; then
    failed=$((failed + 1))
    echo "FAIL $name: dualgrid wrote beside the configuration's files:"
    diff <(echo "$before") <(listing "$dir") | head -n 5
    continue
  fi
  # Where two vehicles share the road (the auto ego had another in its grid for 5 s or more),
  # objects are scored; a scene with no traffic near any vehicle says so in a warning.
  share=$(python3 -c "import json,sys; c=json.load(open(sys.argv[1]))['ego_choice']; print(1 if c['seen_s'] >= 5 else 0)" "$out/summary.json")
  scored=$(python3 -c "import json,sys; t=json.load(open(sys.argv[1])); print(int([m for m in t['metrics'] if m['key']=='objects_scored'][0]['values']['dual']['mean']))" "$out/table.json")
  if [ "$share" -eq 1 ] && [ "$scored" -eq 0 ]; then
    failed=$((failed + 1))
    echo "FAIL $name: vehicles share the road, but nothing was scored"
    continue
  fi
  if [ "$share" -eq 0 ] && [ "$scored" -eq 0 ] && ! grep -q "nothing can be scored" "$work/run.log"; then
    failed=$((failed + 1))
    echo "FAIL $name: nothing scored and nothing said"
    continue
  fi
  passed=$((passed + 1))
  echo "ok $name: ego $(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['ego'])" "$out/summary.json")"
  [ -n "$table" ] && rows+=("$(python3 - "$out" "$name" <<'PY'
import json, sys
out, name = sys.argv[1], sys.argv[2]
s = json.load(open(out + "/summary.json"))
t = json.load(open(out + "/table.json"))
vals = {m["key"]: m["values"] for m in t["metrics"]}
def cell(key):
    return " / ".join("-" if vals[key][m]["mean"] is None else f'{vals[key][m]["mean"]:.0f}'
                      for m in ("position", "velocity", "dual"))
scored = vals["objects_scored"]["dual"]["mean"]
c = s["ego_choice"]
print(f'| `{name}` | {s["begin_s"]:.0f} | `{s["ego"]}` | {s["ego_departed_s"]:.1f} | {c["seen_s"]:.1f} | {scored:.0f} | {cell("D")} | {cell("D_v")} |')
PY
)")
done < <(find "$work/game" "$work/RealWorld" \( -name '*.sumocfg' -o -name '*.sumo.cfg' \) | sort)
if [ -n "$table" ]; then
  echo "| configuration | begin [s] | ego (auto) | departs [s] | traffic in its grid [s] | objects scored | D [%] (position / velocity / dual) | D_v [%] |"
  echo "|---|---:|---|---:|---:|---:|---|---|"
  printf '%s\n' "${rows[@]}"
fi
echo "SUMO examples: $passed ran, $failed failed, $no_vehicle without a vehicle, $refused refused by sumo itself"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
