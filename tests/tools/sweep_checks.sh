#!/usr/bin/env bash
# `dualgrid sweep` / `collect` end to end (ctest sweep_checks): a small aspect-angle sweep run
# with -j 2, rerun (a no-op), and the same run list through GNU parallel: identical tables; bad
# sweep specifications fail before anything runs (exit 2, one line).
# usage: sweep_checks.sh DUALGRID WORK_DIR
set -uo pipefail
B=$1
WORK=$2
rm -rf "$WORK" && mkdir -p "$WORK"
fail=0
check() { echo "FAILED: $1" >&2; fail=1; }
AXES=(--set tangential.sensor=front --set tangential.angle=0:90:90 --set tangential.count=1)

"$B" sweep tangential "${AXES[@]}" --seeds 2 --duration 8 -j 2 --out "$WORK/a" -q
code=$?
[[ $code == 0 ]] || check "sweep -j 2 exited $code"
for f in plan.json runs.txt tidy.csv aggregate.csv sweep.json; do
  [[ -s $WORK/a/$f ]] || check "sweep wrote no $f"
done
[[ $(ls "$WORK/a/figures" | wc -l) -ge 5 ]] || check "fewer than 5 figures"
grep -q '^s002,front,90,1,dual,D_v,%,2,' "$WORK/a/aggregate.csv" || check "aggregate row missing"
cp "$WORK/a/aggregate.csv" "$WORK/first.csv"

# A rerun skips every finished run and rewrites the same tables.
"$B" sweep tangential "${AXES[@]}" --seeds 2 --duration 8 -j 2 --out "$WORK/a" >"$WORK/rerun.log" 2>&1
grep -q '4 runs finished earlier, skipped' "$WORK/rerun.log" || check "rerun did not skip the runs"
cmp -s "$WORK/first.csv" "$WORK/a/aggregate.csv" || check "rerun changed aggregate.csv"

# The same plan as a run list, through GNU parallel (or plain bash without it), then collect.
"$B" sweep tangential "${AXES[@]}" --seeds 2 --duration 8 --out "$WORK/b" --emit list -q >/dev/null
if command -v parallel >/dev/null; then
  parallel -j 2 <"$WORK/b/runs.txt" || check "GNU parallel failed"
else
  echo "note: GNU parallel not installed (apt-get install parallel); running runs.txt with bash"
  bash "$WORK/b/runs.txt" || check "runs.txt failed"
fi
"$B" collect "$WORK/b" -q || check "collect exited $?"
cmp -s "$WORK/a/tidy.csv" "$WORK/b/tidy.csv" || check "tidy.csv differs between -j 2 and the run list"
cmp -s "$WORK/a/aggregate.csv" "$WORK/b/aggregate.csv" || check "aggregate.csv differs"

# collect names missing runs and exits 3, keeping the tables of the others.
rm -rf "$WORK/b/runs/s001/seed_1"
"$B" collect "$WORK/b" >"$WORK/missing.log" 2>&1
code=$?
[[ $code == 3 ]] || check "collect with a missing run exited $code, expected 3"
grep -q 'missing .*s001/seed_1' "$WORK/missing.log" || check "collect did not name the missing run"

# Bad specifications: exit 2, one line, nothing run.
bad() {  # bad NAME EXPECTED ARGS...
  local name=$1 expected=$2
  shift 2
  local err
  err=$("$B" sweep "$@" --out "$WORK/bad_$name" -q 2>&1)
  local code=$?
  [[ $code == 2 ]] || check "$name: exit $code, expected 2 ($err)"
  [[ $(printf '%s' "$err" | wc -l) -le 1 ]] || check "$name: more than one line: $err"
  [[ $err == *"$expected"* ]] || check "$name: '$err' lacks '$expected'"
  [[ ! -d $WORK/bad_$name/runs ]] || [[ -z $(ls "$WORK/bad_$name/runs") ]] || check "$name: ran something"
}
SC=scenarios/highway.yaml
bad unknown_key "sigma_vv" "$SC" --set filter.sigma_vv=1,2
bad empty_range "empty" "$SC" --set filter.sigma_v=2:0.5:1
bad zero_step "step > 0" "$SC" --set filter.sigma_v=1:0:2
bad rejected_value "sigma_v" "$SC" --set filter.sigma_v=1,-1
bad not_numeric "three numbers" "$SC" --set filter.sigma_v=a:1:3
bad unknown_generator_key "unknown generator option" tangential --set tangential.wobble=1,2
bad generator_value "tangential.angle" tangential --set tangential.angle=0,200
bad generator_key_on_file "generator keys" "$SC" --set tangential.angle=0,90
bad twice "given twice" "$SC" --set filter.sigma_v=1,1
bad no_scenario "not found" nowhere.yaml --set filter.sigma_v=1
exit $fail
