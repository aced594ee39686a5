#!/usr/bin/env bash
# The performance table of docs/performance.md (issues 14, 25 and 37), measured side by side on this
# machine.
#
#   bench/perf_table.sh [BUILD_DIR [OLD_BUILD_DIR]]      (defaults: build, none)
#
# BUILD_DIR (and OLD_BUILD_DIR, e.g. a build of an earlier commit, for a before/after column) must
# hold Release builds of `dualgrid`, `bench_filter` and `bench_recorded`. Runs, alternating the
# builds within each repetition so that drifting machine load hits both alike, REPS times (default
# 3; medians shown):
#   - the highway run (60 s simulated, 3 modes, 2 threads) without figures, quiet and with one
#     competing CPU-bound process (a shell busy loop); the default run (recording and figures),
#     quiet; the replay video of that run (`dualgrid replay`);
#   - bench_filter at paper size (50 and 700 detections per cycle), quiet and under the same
#     load, and at Nuss scale (1.44e6 cells, 2e6 particles, 2e5 births), quiet;
#   - the highway run with the dual mode only, 2 threads and 1 thread, no figures;
#   - bench_recorded: a 20 s recorded sequence, three modes and the dual mode alone, the default
#     1 ms batch window;
#   - the floor (round 6, docs/performance.md): bench_filter's BM_Floor* (the prediction's Philox
#     noise and one pass over the state, no arithmetic) and bench_sim_step (SUMO and the radar
#     alone, no filters), beside the budgets they leave of the targets;
#   - issue 37's floor of the new design: bench_filter's BM_FloorCycle (a cycle's least work) and
#     bench_floor_e2e (the end-to-end rows' ceiling with every cycle at that floor).
# The benchmarks run with OMP_WAIT_POLICY=PASSIVE GOMP_SPINCOUNT=300, what `dualgrid` sets for
# itself. Prints a Markdown table: values, targets (issue 37's)
# and the loaded / quiet slowdown. Takes ~8 min (new build only) to ~16 min (both). Nothing else
# should run meanwhile: timings of a busy machine are noise (check `uptime` before).
set -euo pipefail

NEW=${1:-build}
OLD=${2:-}
REPS=${REPS:-3}
SCENARIO=${SCENARIO:-scenarios/highway.yaml}
SIMULATED=60
for b in "$NEW" $OLD; do
  for exe in tools/dualgrid bench/bench_filter bench/bench_recorded; do
    [[ -x "$b/$exe" ]] || { echo "perf_table.sh: $b/$exe missing: build it first (Release)" >&2; exit 2; }
  done
done
BUILDS=("$NEW")
[[ -n "$OLD" ]] && BUILDS+=("$OLD")
WORK=$(mktemp -d)
BUSY=""
cleanup() {
  [[ -n "$BUSY" ]] && kill "$BUSY" 2>/dev/null || true
  rm -rf "$WORK"
}
trap cleanup EXIT

busy_start() {
  sh -c 'while :; do :; done' &
  BUSY=$!
  sleep 0.5
}
busy_stop() {
  kill "$BUSY" 2>/dev/null || true
  wait "$BUSY" 2>/dev/null || true
  BUSY=""
}

# Wall seconds of one dualgrid command: timed BUILD WHAT ARGS... (WHAT names it in an error).
timed() {
  local build=$1 what=$2
  shift 2
  local t0 t1
  t0=$(date +%s.%N)
  if ! "$build/tools/dualgrid" "$@" >/dev/null 2>"$WORK/err"; then
    echo "perf_table.sh: $build/tools/dualgrid $what failed:" >&2
    cat "$WORK/err" >&2
    exit 1
  fi
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f\n", b - a }'
}

# Wall seconds of one highway run: e2e BUILD [extra args].
e2e() {
  local build=$1
  shift
  rm -rf "$WORK/run"
  timed "$build" run run "$SCENARIO" --out "$WORK/run" -q --threads 2 "$@"
}

# Wall seconds of the highway run with the dual mode only, no figures: single BUILD THREADS.
single() {
  rm -rf "$WORK/single"
  timed "$1" run run "$SCENARIO" --out "$WORK/single" -q --no-figures --modes dual --threads "$2"
}

# Wall seconds of the replay video of the last e2e run (its recording): video BUILD.
video() { timed "$1" replay replay "$WORK/run" -q; }

# x real time of the recorded-data loop, MODES modes (3, or 1: dual only), the default batch
# window, 2 threads (bench_recorded; issue 23's target): recorded BUILD MODES.
recorded() {
  OMP_WAIT_POLICY=PASSIVE GOMP_SPINCOUNT=300 OMP_NUM_THREADS=2 "$1/bench/bench_recorded" \
    --benchmark_filter="^BM_Recorded/$2/1/" 2>/dev/null | grep -o 'x_real_time=[0-9.]*' |
    cut -d= -f2
}

# ms per step of SUMO and the radar alone on the highway (no filters, 2 threads; bench_sim_step,
# multipath off as in the scenario): the part of a highway step no filter change touches.
sim_step() {
  [[ -x "$1/bench/bench_sim_step" ]] || return 0
  OMP_WAIT_POLICY=PASSIVE GOMP_SPINCOUNT=300 "$1/bench/bench_sim_step" \
    --benchmark_filter='^BM_SimStepMultipath/2/' 2>/dev/null | grep -o 'off_ms_per_step=[0-9.]*' |
    cut -d= -f2
}

# Median real time [ms] per cycle of one bench_filter case: bench BUILD NAME_PREFIX, with the wait
# policy `dualgrid` sets for itself; floor BUILD NAME_PREFIX with libgomp's default (spinning), the
# lower floor: with PASSIVE each region's wake-up is in it too (~0.05 ms here).
bench() { OMP_WAIT_POLICY=PASSIVE GOMP_SPINCOUNT=300 bench_any "$@"; }
floor() { (
  unset OMP_WAIT_POLICY GOMP_SPINCOUNT
  bench_any "$@"
); }
bench_any() {
  "$1/bench/bench_filter" --benchmark_filter="^$2" \
    --benchmark_format=csv --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
    2>/dev/null | awk -F, '/_median"?,/ {
      t = $3; u = $5; gsub(/"/, "", u)
      if (u == "us") t /= 1000; else if (u == "ns") t /= 1e6; else if (u == "s") t *= 1000
      printf "%.4f\n", t }'
}

# The end-to-end rows' ceilings (bench_floor_e2e: each step's source + the floor cycle for three
# modes, both cores busy): "HIGHWAY/RECORDED" x real time, or nothing when the build has no such
# benchmark (builds before issue 37).
floor_e2e() {
  [[ -x "$1/bench/bench_floor_e2e" ]] || return 0
  "$1/bench/bench_floor_e2e" 2>/dev/null | grep -o 'ceiling_x_real_time=[0-9.]*' | cut -d= -f2 |
    awk '{ v[NR] = $1 } END { if (NR == 2) printf "%.1fx/%.1fx\n", v[1], v[2] }'
}

median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

declare -A SAMPLES
add() { SAMPLES["$1"]+="$2 "; }

echo "perf_table.sh: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg), $REPS repetitions" >&2
for ((r = 1; r <= REPS; ++r)); do
  for b in "${BUILDS[@]}"; do
    echo "  repetition $r/$REPS, $b: highway run quiet, loaded, with figures" >&2
    add "e2e_quiet|$b" "$(e2e "$b" --no-figures)"
    busy_start
    add "e2e_loaded|$b" "$(e2e "$b" --no-figures)"
    busy_stop
    add "e2e_figures|$b" "$(e2e "$b")"
    add "video|$b" "$(video "$b")"
    add "single2|$b" "$(single "$b" 2)"
    add "single1|$b" "$(single "$b" 1)"
  done
done
for b in "${BUILDS[@]}"; do
  echo "  $b: bench_filter quiet and loaded" >&2
  add "paper50_quiet|$b" "$(bench "$b" BM_PaperConfig/10000/2/)"
  add "paper700_quiet|$b" "$(bench "$b" BM_PaperHighway/10000/2/)"
  add "paper50_one|$b" "$(OMP_NUM_THREADS=1 bench "$b" BM_PaperConfig/10000/1/)"
  # Issue 37's floor of the new design: a cycle's least work (bench/floor_cycle.hpp).
  add "fc50|$b" "$(bench "$b" BM_FloorCycle/0/2/)"
  add "fc700|$b" "$(bench "$b" BM_FloorCycle/1/2/)"
  add "fcnuss|$b" "$(bench "$b" BM_FloorCycle/2/2/)"
  add "fc50one|$b" "$(OMP_NUM_THREADS=1 bench "$b" BM_FloorCycle/0/1/)"
  add "e2efloor|$b" "$(floor_e2e "$b")"
  add "nuss_quiet|$b" "$(bench "$b" BM_Scale/2000000/2/)"
  # The floor (round 6): the Philox noise and one pass over the state, no arithmetic; libgomp's
  # default wait policy, the lower figure.
  add "floor_noise|$b" "$(floor "$b" BM_FloorNoise/10000/2/)"
  add "floor_pass|$b" "$(floor "$b" BM_FloorPass/10000/2/)"
  add "floor_nuss_noise|$b" "$(floor "$b" BM_FloorNoise/2000000/2/)"
  add "floor_nuss_pass|$b" "$(floor "$b" BM_FloorPass/2000000/2/)"
  add "sim_step|$b" "$(sim_step "$b")"
  for ((r = 1; r <= REPS; ++r)); do
    add "recorded_quiet|$b" "$(recorded "$b" 3)"
    add "recorded1|$b" "$(recorded "$b" 1)"
  done
  busy_start
  add "paper50_loaded|$b" "$(bench "$b" BM_PaperConfig/10000/2/)"
  add "paper700_loaded|$b" "$(bench "$b" BM_PaperHighway/10000/2/)"
  busy_stop
done

med() { tr ' ' '\n' <<<"${SAMPLES[$1|$2]:-}" | { grep -v '^$' || true; } | median; }
fmt() { awk -v v="$1" -v k="$2" 'BEGIN {
  if (v == "") { print "-"; exit }
  if (k == "xrt") printf "%.1fx (%.2f s)", 60 / v, v
  else if (k == "cps") printf "%.0f/s (%.3f ms)", 1000 / v, v
  else printf "%.1f ms", v }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (a == "" || b == "") print "-"; else printf "%.2fx", b / a }'; }

header="| quantity | target |"
rule="|---|---|"
for b in "${BUILDS[@]}"; do
  header+=" $b quiet | $b loaded | slowdown |"
  rule+="---:|---:|---:|"
done
echo "$header"
echo "$rule"
row() {  # key kind label target
  local line="| $3 | $4 |"
  for b in "${BUILDS[@]}"; do
    local q l
    q=$(med "$1_quiet" "$b")
    l=$(med "$1_loaded" "$b")
    line+=" $(fmt "$q" "$2") | $(fmt "$l" "$2") | $(ratio "$q" "$l") |"
  done
  echo "$line"
}
row e2e xrt "highway run, 3 modes, no figures: x real time" ">= 30x; loaded <= 2x slower"
line="| the default run (recording + figures, no video): x real time | >= 15x |"
for b in "${BUILDS[@]}"; do line+=" $(fmt "$(med e2e_figures "$b")" xrt) | - | - |"; done
echo "$line"
row paper50 cps "filter, paper size, 2 threads, 50 detections: cycles/s" ">= 5,000/s; loaded <= 2x"
row paper700 cps "filter, paper size, 2 threads, 700 detections: cycles/s" ">= 3,000/s; loaded <= 2x"
line="| filter, paper size, 1 thread, 50 detections: cycles/s | >= 2,500/s |"
for b in "${BUILDS[@]}"; do line+=" $(fmt "$(med paper50_one "$b")" cps) | - | - |"; done
echo "$line"
line="| filter, Nuss scale (1.44e6 cells, 2e6 + 2e5 particles), 2 threads: ms/cycle | <= 50 ms |"
for b in "${BUILDS[@]}"; do line+=" $(fmt "$(med nuss_quiet "$b")" ms) | - | - |"; done
echo "$line"
line="| replay video of the 60 s highway (\`dualgrid replay\`): s | <= 16 s |"
for b in "${BUILDS[@]}"; do line+=" $(med video "$b") s | - | - |"; done
echo "$line"
line="| recorded sequence, 3 modes, 1 ms window, 2 threads (bench_recorded): x real time | >= 20x |"
for b in "${BUILDS[@]}"; do line+=" $(med recorded_quiet "$b")x | - | - |"; done
echo "$line"
line="| recorded sequence, dual only, 1 ms window, 2 threads (bench_recorded): x real time | >= 10x (issue 23) |"
for b in "${BUILDS[@]}"; do line+=" $(med recorded1 "$b")x | - | - |"; done
echo "$line"
line="| highway run, dual only, no figures, 2 threads / 1 thread: x real time | 2 threads not slower |"
for b in "${BUILDS[@]}"; do
  line+=" $(fmt "$(med single2 "$b")" xrt) / $(fmt "$(med single1 "$b")" xrt) | - | - |"
done
echo "$line"
line="| floor, paper size, 2 threads: Philox noise + one pass over particles and cells (BM_Floor*, default wait policy): ms | 5,000/s = 0.200 ms per cycle |"
for b in "${BUILDS[@]}"; do line+=" $(med floor_noise "$b") + $(med floor_pass "$b") ms | - | - |"; done
echo "$line"
line="| floor, Nuss scale, 2 threads: Philox noise + one pass (BM_Floor*, default wait policy): ms | 50 ms per cycle |"
for b in "${BUILDS[@]}"; do line+=" $(med floor_nuss_noise "$b") + $(med floor_nuss_pass "$b") ms | - | - |"; done
echo "$line"
line="| SUMO + radar alone, highway, 2 threads, no filters (bench_sim_step): ms per step | 50x = 1.0 ms per step in all |"
for b in "${BUILDS[@]}"; do line+=" $(med sim_step "$b") ms | - | - |"; done
echo "$line"
line="| floor of the new design (BM_FloorCycle): paper 50 / 700 detections, Nuss, 2 threads; paper 50, 1 thread: ms | the four filter rows |"
for b in "${BUILDS[@]}"; do
  line+=" $(med fc50 "$b") / $(med fc700 "$b") / $(med fcnuss "$b") / $(med fc50one "$b") ms | - | - |"
done
echo "$line"
line="| ceiling of the end-to-end rows at the floor (bench_floor_e2e): highway / recorded, x real time | the highway and recorded rows |"
for b in "${BUILDS[@]}"; do line+=" $(med e2efloor "$b") | - | - |"; done
echo "$line"
echo "(targets: issue 37's, for a machine whose yardstick prints ~330 us: scale them by 330 / its time here)"
echo "(medians of $REPS runs for the highway, video and recorded rows, of 3 repetitions for bench_filter; $(date -u +%FT%TZ))"
