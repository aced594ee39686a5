#!/usr/bin/env bash
# The multipath study of docs/results.md ("Multipath ghosts", issue 27), one command per stage;
# resumable (an experiment whose summary.json says "complete": true is not rerun).
#
#   scripts/multipath_study.sh OUT experiments  highway, crossing, crossing_rails (the crossing
#                                               with guard rails along the ego's road) and
#                                               guardrail, multipath off and on (defaults
#                                               otherwise), SEEDS seeds, all 3 modes
#   scripts/multipath_study.sh OUT loss         guardrail, multipath on with rail losses of 0 and
#                                               12 dB (the default is 6)
#   scripts/multipath_study.sh OUT rates        dualgrid sim with multipath on, SEEDS seeds per
#                                               scenario: detections.csv.gz for the ghost rates
#   scripts/multipath_study.sh OUT table        the Markdown tables (stdout)
#   scripts/multipath_study.sh OUT all          all of the above
#
# Environment: DUALGRID (the binary, default build/tools/dualgrid), SEEDS (5), JOBS (seed runs at
# a time, default: one per core), EXTRA (more --set arguments for every run, e.g. a loss).
set -euo pipefail
OUT=${1:?usage: scripts/multipath_study.sh OUT experiments|loss|rates|table|all}
STAGE=${2:-all}
B=${DUALGRID:-build/tools/dualgrid}
SEEDS=${SEEDS:-5}
JOBS_ARG=()
[[ -n "${JOBS:-}" ]] && JOBS_ARG=(--jobs "$JOBS")
read -r -a EXTRA_ARGS <<<"${EXTRA:-}"
here=$(cd "$(dirname "$0")" && pwd)
[[ -x "$B" ]] || { echo "scripts/multipath_study.sh: $B not found; build first" >&2; exit 2; }

mkdir -p "$OUT/scenarios"
[[ -f "$OUT/scenarios/crossing.yaml" ]] ||
  "$B" tangential --kind crossing --count 4 --speed 15 --out "$OUT/scenarios/crossing.yaml" -q
[[ -f "$OUT/scenarios/guardrail.yaml" ]] ||
  "$B" tangential --kind guardrail --out "$OUT/scenarios/guardrail.yaml" -q
SCENARIOS=(highway crossing crossing_rails guardrail)
scenario_file() {
  case $1 in
    highway) echo "scenarios/highway.yaml" ;;
    crossing_rails) echo "$OUT/scenarios/crossing.yaml" ;;
    *) echo "$OUT/scenarios/$1.yaml" ;;
  esac
}
# The crossing has no rail (and no truck): no mirror. crossing_rails adds rails 4.5 m either side
# of the ego's road, open where the crossing road passes (x = 785 ... 815 m).
RAILS='[{id: rail_n1, points: [[0, 4.5], [785, 4.5]]}, {id: rail_n2, points: [[815, 4.5], [2000, 4.5]]}, {id: rail_s1, points: [[0, -4.5], [785, -4.5]]}, {id: rail_s2, points: [[815, -4.5], [2000, -4.5]]}]'
scenario_args() {  # SCENARIO -> extra arguments
  case $1 in
    crossing_rails) printf '%s\0' --set "obstacles.guard_rails=$RAILS" ;;
  esac
}

stage_experiments() {
  for scen in "${SCENARIOS[@]}"; do
    for mp in off on; do
      local dir="$OUT/$scen/multipath_$mp"
      if grep -q '"complete": *true' "$dir/summary.json" 2>/dev/null; then
        echo "multipath study: $scen/$mp done already"
        continue
      fi
      echo "multipath study: $scen, multipath $mp ($SEEDS seeds)"
      local args=()
      mapfile -d '' args < <(scenario_args "$scen")
      "$B" experiment "$(scenario_file "$scen")" --seeds "$SEEDS" --out "$dir" --force -q --no-figures \
        "${JOBS_ARG[@]}" "${args[@]}" --set sensors.multipath=$mp "${EXTRA_ARGS[@]}" ||
        echo "multipath study: $scen/$mp exited $?" >&2
    done
  done
}

stage_rates() {
  for scen in "${SCENARIOS[@]}"; do
    for ((seed = 1; seed <= SEEDS; ++seed)); do
      local dir="$OUT/rates/$scen/seed_$seed"
      if grep -q '"complete": *true' "$dir/summary.json" 2>/dev/null; then continue; fi
      echo "multipath study: ghost rates, $scen seed $seed"
      local args=()
      mapfile -d '' args < <(scenario_args "$scen")
      "$B" sim "$(scenario_file "$scen")" --seed "$seed" --detections csv.gz --out "$dir" --force -q \
        "${args[@]}" --set sensors.multipath=on "${EXTRA_ARGS[@]}"
    done
  done
}

stage_loss() {
  for loss in 0 12; do
    local dir="$OUT/guardrail/multipath_on_loss$loss"
    if grep -q '"complete": *true' "$dir/summary.json" 2>/dev/null; then continue; fi
    echo "multipath study: guardrail, rail loss $loss dB ($SEEDS seeds)"
    "$B" experiment "$(scenario_file guardrail)" --seeds "$SEEDS" --out "$dir" --force -q --no-figures \
      "${JOBS_ARG[@]}" --set "sensors.multipath={rail_loss_db: $loss}" ||
      echo "multipath study: guardrail/loss$loss exited $?" >&2
  done
}

stage_table() { python3 "$here/lib/multipath_table.py" "$OUT" "${SCENARIOS[@]}"; }

case $STAGE in
  experiments) stage_experiments ;;
  loss) stage_loss ;;
  rates) stage_rates ;;
  table) stage_table ;;
  all) stage_experiments; stage_loss; stage_rates; stage_table ;;
  *) echo "scripts/multipath_study.sh: unknown stage '$STAGE'" >&2; exit 2 ;;
esac
