#!/usr/bin/env bash
# The ablation study of docs/results.md, one command per stage; resumable (an experiment whose
# summary.json says "complete": true is not rerun). Seeds run in parallel processes (one per core).
#
#   scripts/ablation.sh OUT switches    births x eq.-7 fall-back x likelihood, and the two presets,
#                                       10,000 particles, 4 scenarios, SEEDS seeds
#   scripts/ablation.sh OUT dualgrid    the dualgrid preset (the recommended setting), with figures
#   scripts/ablation.sh OUT particles   3,000 and 30,000 particles for the presets and the default
#   scripts/ablation.sh OUT paper       the paper preset on the highway, PAPER_SEEDS (10) seeds
#   scripts/ablation.sh OUT doppler     highway: Doppler accuracy 0.03-1 m/s, default and paper
#   scripts/ablation.sh OUT fit         the velocity fit to neighbouring Dopplers (issue 28): births,
#                                       likelihood, both, on the default preset; 4 scenarios
#   scripts/ablation.sh OUT table       Markdown tables of everything measured so far (stdout)
#   scripts/ablation.sh OUT all         all of the above
#
# Environment: DUALGRID (the binary, default build/tools/dualgrid), SEEDS (5), PAPER_SEEDS (10),
# JOBS (seed runs at a time, default: one per core).
set -euo pipefail
OUT=${1:?usage: scripts/ablation.sh OUT switches|particles|paper|doppler|table|all}
STAGE=${2:-all}
B=${DUALGRID:-build/tools/dualgrid}
SEEDS=${SEEDS:-5}
PAPER_SEEDS=${PAPER_SEEDS:-10}
JOBS_ARG=()
[[ -n "${JOBS:-}" ]] && JOBS_ARG=(--jobs "$JOBS")
[[ -x "$B" ]] || { echo "scripts/ablation.sh: $B not found; build first (scripts/bootstrap.sh)" >&2; exit 2; }

mkdir -p "$OUT/scenarios"
scenario_file() {
  case $1 in
    simple_road | highway) echo "scenarios/$1.yaml" ;;
    crossing | parallel) echo "$OUT/scenarios/$1.yaml" ;;
  esac
}
[[ -f "$OUT/scenarios/crossing.yaml" ]] ||
  "$B" tangential --kind crossing --count 4 --speed 15 --out "$OUT/scenarios/crossing.yaml" -q
[[ -f "$OUT/scenarios/parallel.yaml" ]] ||
  "$B" tangential --kind parallel --out "$OUT/scenarios/parallel.yaml" -q
SCENARIOS=(simple_road highway crossing parallel)

# experiment SCENARIO NAME SEEDS FIGURES(yes|no) [--set ...]
experiment() {
  local scen=$1 name=$2 seeds=$3 figures=$4
  shift 4
  local dir="$OUT/$scen/$name"
  if grep -q '"complete": *true' "$dir/summary.json" 2>/dev/null; then
    echo "ablation: $scen/$name done already"
    return 0
  fi
  local fig=()
  [[ $figures == no ]] && fig=(--no-figures)
  echo "ablation: $scen/$name ($seeds seeds) $*"
  # Exit 3 (some seeds failed) keeps the finished seeds; the study goes on and the table says so.
  "$B" experiment "$(scenario_file "$scen")" --seeds "$seeds" --out "$dir" --force -q "${fig[@]}" \
    "${JOBS_ARG[@]}" "$@" || echo "ablation: $scen/$name exited $?" >&2
}

# The 8 combinations of the three switches the paper is literal about (per-cell normalisation).
switch_args() {  # NAME -> --set arguments; names b{doppler,uniform}_z{keep,literal}_l{vector,radial}
  local b z l
  IFS=_ read -r b z l <<<"$1"
  echo "--set filter.birth_velocity=${b#b} --set filter.zero_likelihood=$([[ ${z#z} == keep ]] && echo keep_prediction || echo literal) --set filter.velocity_likelihood=${l#l}"
}
SWITCHES=()
for b in bdoppler buniform; do for z in zkeep zliteral; do for l in lvector lradial; do
  SWITCHES+=("${b}_${z}_${l}")
done; done; done

stage_switches() {
  for scen in "${SCENARIOS[@]}"; do
    experiment "$scen" preset_paper "$SEEDS" yes --set filter.preset=paper
    # The paper preset with one switch changed: which literal choice matters there.
    experiment "$scen" preset_paper_lradial "$SEEDS" no --set filter.preset=paper \
      --set filter.velocity_likelihood=radial
    experiment "$scen" preset_paper_bdoppler "$SEEDS" no --set filter.preset=paper \
      --set filter.birth_velocity=doppler
    for s in "${SWITCHES[@]}"; do
      # shellcheck disable=SC2046
      experiment "$scen" "$s" "$SEEDS" no $(switch_args "$s")
    done
  done
}
stage_dualgrid() {
  for scen in "${SCENARIOS[@]}"; do
    experiment "$scen" preset_dualgrid "$SEEDS" yes --set filter.preset=dualgrid
  done
}
# The fit of one velocity to the Doppler of neighbouring detections (docs/algorithm.md, "Births"
# and eq. 8), each use alone and both, against the preset without it (radial, Doppler births).
stage_fit() {
  for scen in "${SCENARIOS[@]}"; do
    local base=(--set filter.preset=dualgrid --set filter.birth_velocity=doppler
      --set filter.velocity_likelihood=radial)
    experiment "$scen" fit_none "$SEEDS" no "${base[@]}"
    experiment "$scen" fit_births "$SEEDS" no "${base[@]}" --set filter.birth_velocity=doppler_fit
    experiment "$scen" fit_likelihood "$SEEDS" no "${base[@]}" \
      --set filter.velocity_likelihood=radial_fit
    experiment "$scen" fit_both "$SEEDS" no "${base[@]}" --set filter.birth_velocity=doppler_fit \
      --set filter.velocity_likelihood=radial_fit
  done
}
stage_particles() {
  for scen in "${SCENARIOS[@]}"; do
    for n in 3000 30000; do
      experiment "$scen" "preset_paper_n$n" "$SEEDS" no --set filter.preset=paper \
        --set filter.num_particles=$n --set filter.num_birth=$((n / 10))
      experiment "$scen" "preset_dualgrid_n$n" "$SEEDS" no --set filter.preset=dualgrid \
        --set filter.num_particles=$n --set filter.num_birth=$((n / 10))
      experiment "$scen" "bdoppler_zkeep_lvector_n$n" "$SEEDS" no \
        $(switch_args bdoppler_zkeep_lvector) --set filter.num_particles=$n \
        --set filter.num_birth=$((n / 10))
    done
  done
}
stage_paper() {
  experiment highway "preset_paper_${PAPER_SEEDS}seeds" "$PAPER_SEEDS" yes --set filter.preset=paper
}
stage_doppler() {
  for rr in 0.03 0.1 0.3 1.0; do
    for preset in paper dualgrid; do
      experiment highway "doppler_${rr}_$preset" "$SEEDS" no --set filter.preset=$preset \
        --set sensors.overrides.all.range_rate_accuracy=$rr
    done
  done
  experiment highway clean_paper "$SEEDS" no --set filter.preset=paper --set sensors.accuracy=clean
  experiment highway clean_dualgrid "$SEEDS" no --set filter.preset=dualgrid \
    --set sensors.accuracy=clean
}

# Markdown: per scenario, one row per configuration, mean +- 95 % CI half-width per mode.
stage_table() {
  for scen in "${SCENARIOS[@]}"; do
    [[ -d "$OUT/$scen" ]] || continue
    for group in "D_v D" "delta_v delta_x t_d"; do
      echo
      echo "#### $scen: $group"
      echo
      header="| configuration |"
      rule="|---|"
      for m in $group; do
        for mode in position velocity dual; do
          header+=" $m ${mode:0:3} |"
          rule+="---:|"
        done
      done
      if [[ $group == "D_v D" ]]; then
        header+=" dual − best single (D_v) |"
        rule+="---:|"
      fi
      echo "$header"
      echo "$rule"
      for dir in "$OUT/$scen"/*/; do
        [[ -f "$dir/table.csv" ]] || continue
        name=$(basename "$dir")
        awk -F, -v name="$name" -v metrics="$group" '
          NR > 1 {
            v[$2 "," $4] = ($6 == "" ? "—" : sprintf("%.2f", $6)) ($7 == "" ? "" : sprintf(" ± %.2f", $7))
            if ($6 != "") mean[$2 "," $4] = $6
          }
          END {
            n = split(metrics, ms, " ")
            row = "| " name " |"
            for (i = 1; i <= n; ++i) {
              split("position velocity dual", modes, " ")
              for (k = 1; k <= 3; ++k) {
                key = ms[i] "," modes[k]
                row = row " " ((key in v) ? v[key] : "—") " |"
              }
            }
            if (metrics == "D_v D") {
              p = mean["D_v,position"]; q = mean["D_v,velocity"]; d = mean["D_v,dual"]
              row = row " " ((d == "" || p == "" || q == "") ? "—" : sprintf("%+.1f", d - (p > q ? p : q))) " |"
            }
            print row
          }' "$dir/table.csv"
      done
    done
  done
}

case $STAGE in
  switches) stage_switches ;;
  dualgrid) stage_dualgrid ;;
  particles) stage_particles ;;
  paper) stage_paper ;;
  doppler) stage_doppler ;;
  fit) stage_fit ;;
  table) stage_table ;;
  all) stage_switches; stage_dualgrid; stage_particles; stage_paper; stage_doppler; stage_table ;;
  *) echo "scripts/ablation.sh: unknown stage '$STAGE'" >&2; exit 2 ;;
esac
