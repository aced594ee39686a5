#!/usr/bin/env bash
# Tests of `dualgrid regress` itself (ctest regression_checks): the suite can fail, --record
# round-trips, and malformed suites are one-line errors with exit 2.
# usage: run_checks.sh DUALGRID WORK_DIR
set -uo pipefail
B=$1
WORK=$2
HERE=$(cd "$(dirname "$0")" && pwd)
rm -rf "$WORK" && mkdir -p "$WORK"
fail=0
check() {  # check NAME CONDITION-MESSAGE: records a failure
  echo "FAILED: $1" >&2
  fail=1
}

# 1. A degraded configuration (no births: nothing is ever tracked) fails with exit 1 and names the
#    broken checks.
"$B" regress "$HERE/mini.yaml" --out "$WORK/degraded" --set filter.num_birth=0 -q >"$WORK/degraded.md"
code=$?
[[ $code == 1 ]] || check "degraded suite exited $code, expected 1"
grep -q '| highway | dual.D | >= 50 | .* | \*\*FAIL\*\*' "$WORK/degraded.md" ||
  check "degraded report does not name the failing dual.D band"
grep -q 'failures="[1-9]' "$WORK/degraded/junit.xml" || check "junit.xml lists no failure"

# 2. --record, then the recorded suite passes, with the same digest.
"$B" regress "$HERE/mini.yaml" --out "$WORK/record" --record "$WORK/recorded.yaml" -q >/dev/null
code=$?
[[ $code == 0 ]] || check "record run exited $code, expected 0"
grep -q 'digest:' "$WORK/recorded.yaml" || check "recorded suite has no digest"
grep -q 'dual.D_v: {reference:' "$WORK/recorded.yaml" || check "recorded suite has no D_v band"
"$B" regress "$WORK/recorded.yaml" --out "$WORK/rerun" --require-digests -q >"$WORK/rerun.md"
code=$?
[[ $code == 0 ]] || check "recorded suite exited $code on a rerun, expected 0"
grep -q '| highway | ok .* | same ' "$WORK/rerun.md" || check "rerun digest is not 'same'"

# 3. Malformed suites: exit 2, one line naming the file and the key.
bad() {  # bad NAME EXPECTED-TEXT YAML
  printf '%s\n' "$3" >"$WORK/$1.yaml"
  local err
  err=$("$B" regress "$WORK/$1.yaml" --out "$WORK/out_$1" -q 2>&1 >/dev/null)
  local code=$?
  [[ $code == 2 ]] || check "$1: exit $code, expected 2 ($err)"
  [[ $(printf '%s' "$err" | wc -l) -le 1 ]] || check "$1: more than one line: $err"
  [[ $err == *"$1.yaml"* && $err == *"$2"* ]] || check "$1: error '$err' lacks '$2'"
}
SC="$HERE/../../scenarios/highway.yaml"
bad unknown_metric "unknown metric 'Dee'" "cases: [{name: a, scenario: $SC, bands: {dual.Dee: {min: 1}}}]"
bad unknown_mode "unknown mode 'both'" "cases: [{name: a, scenario: $SC, modes: [both]}]"
bad band_mode "does not run" "cases: [{name: a, scenario: $SC, modes: [dual], bands: {position.D: {min: 1}}}]"
bad inverted "inverted" "cases: [{name: a, scenario: $SC, bands: {dual.D: {min: 90, max: 10}}}]"
bad missing_scenario "not found" "cases: [{name: a, scenario: nowhere.yaml}]"
bad no_cases "cases" "name: empty"
bad bad_ordering "OP" "cases: [{name: a, scenario: $SC, orderings: [dual.D = dual.D_v]}]"
bad unknown_case "unknown case 'zz'" "cases: [{name: a, scenario: $SC}]
orderings: [zz:dual.D >= a:dual.D]"
bad bad_set "filter.sigma_v" "cases: [{name: a, scenario: $SC, set: [filter.sigma_v=-1]}]"
bad typo_key "seeeds" "cases: [{name: a, scenario: $SC, seeeds: 3}]"
bad duplicate_case "names two cases" "cases: [{name: a, scenario: $SC}, {name: a, scenario: $SC}]"
exit $fail
