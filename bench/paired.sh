#!/usr/bin/env bash
# Alternating paired runs of one Google Benchmark in two builds: the way to see a change of a few
# per cent on a machine whose load drifts by more than that between runs (docs/performance.md).
#
#   bench/paired.sh PAIRS OLD_BUILD NEW_BUILD BENCHMARK FILTER
#   e.g. bench/paired.sh 8 /work/base/build build bench_recorded 'BM_Recorded/3/1/'
#
# Runs OLD then NEW, PAIRS times, each a single benchmark repetition; prints each pair's wall
# times [ms] and ratio, then the minimum and median of each column and the median of the pairs'
# ratios (the figure to quote). The environment passes through: set OMP_NUM_THREADS, and
# OMP_WAIT_POLICY=PASSIVE GOMP_SPINCOUNT=300 to measure what `dualgrid` itself sets.
# Exit codes: 0 done, 2 bad arguments or a benchmark that printed no time.
set -euo pipefail

if [[ $# -ne 5 ]]; then
  echo "usage: bench/paired.sh PAIRS OLD_BUILD NEW_BUILD BENCHMARK FILTER" >&2
  exit 2
fi
PAIRS=$1 OLD=$2 NEW=$3 BENCH=$4 FILTER=$5
[[ "$PAIRS" =~ ^[1-9][0-9]*$ ]] || { echo "paired.sh: PAIRS must be a positive integer, got '$PAIRS'" >&2; exit 2; }
for b in "$OLD" "$NEW"; do
  [[ -x "$b/bench/$BENCH" ]] || { echo "paired.sh: $b/bench/$BENCH missing: build it first (Release)" >&2; exit 2; }
done

# Wall time [ms] of one run (the benchmark's real_time column).
one() {
  local t
  t=$("$1/bench/$BENCH" --benchmark_filter="$FILTER" --benchmark_time_unit=ms 2>/dev/null |
      awk '$1 ~ /^BM_/ {print $2; exit}')
  [[ -n "$t" ]] || { echo "paired.sh: $1/bench/$BENCH printed no time for '$FILTER'" >&2; exit 2; }
  echo "$t"
}

for _ in $(seq "$PAIRS"); do
  a=$(one "$OLD")
  b=$(one "$NEW")
  echo "$a $b"
done | python3 -c '
import statistics as st, sys
rows = [tuple(map(float, l.split())) for l in sys.stdin if len(l.split()) == 2]
if not rows:
    sys.exit(2)  # the benchmark said why
print("old [ms]  new [ms]  new/old")
for a, b in rows:
    print(f"{a:8.0f}  {b:8.0f}  {100 * (b / a - 1):+6.1f} %")
a = [r[0] for r in rows]; b = [r[1] for r in rows]
print(f"min {min(a):.0f} {min(b):.0f}; median {st.median(a):.0f} {st.median(b):.0f}; "
      f"median of the ratios {100 * (st.median([y / x for x, y in rows]) - 1):+.1f} %")
'
