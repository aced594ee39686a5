#!/usr/bin/env bash
# The output guard end to end (docs/reliability.md, "Output folders"; issue 42's lost-data
# cases and more): an output that equals, contains or lies inside an input, however spelled
# (relative, `.`, `..`, trailing slashes, symbolic links), a name that would leave --out, a
# re-run into a folder without --force, --force on a folder that is not dualgrid's, an export of
# a run that did not finish. Every refusal must exit 2 with one "dualgrid: error:" line holding
# the expected words, within 60 s, and leave every input byte for byte as it was (a digest of the
# whole input tree before and after each case).
# Usage: output_guard_cases.sh DUALGRID PYTHON_WITH_H5PY
set -uo pipefail
dualgrid=$(realpath "$1")
py=${2:-python3}
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/dualgrid_guard.XXXXXX")
trap 'rm -rf "$work"' EXIT
in=$work/in  # every input lives under it; nothing under it may change in a refused case
mkdir -p "$in"
passed=0
failed=0

digest() { (cd "$in" && find . -print0 | LC_ALL=C sort -z | xargs -0 -I{} sh -c \
  'if [ -f "{}" ] && [ ! -L "{}" ]; then sha1sum "{}"; else echo "{} $(stat -c %F "{}")"; fi' | sha1sum); }

fail() {
  failed=$((failed + 1))
  printf 'FAIL %s\n' "$*"
}

# refused NAME TEXT CMD...: exit 2, one error line with TEXT, the inputs untouched.
refused() {
  local name=$1 text=$2
  shift 2
  local before out rc why=""
  before=$(digest)
  out=$(cd "$work" && timeout 60 "$@" 2>&1)
  rc=$?
  if [ "$rc" -eq 124 ]; then why="hung"
  elif [ "$rc" -ge 128 ]; then why="crashed (signal $((rc - 128)))"
  elif [ "$rc" -ne 2 ]; then why="exit code $rc, expected 2"
  elif [ "$(printf '%s\n' "$out" | wc -l)" -ne 1 ]; then why="printed more than one line"
  elif [[ "$out" != "dualgrid: error: "* ]]; then why="not a 'dualgrid: error:' line"
  elif [[ "$out" != *"$text"* ]]; then why="message lacks '$text'"
  elif [ "$(digest)" != "$before" ]; then why="an input changed"
  fi
  if [ -n "$why" ]; then fail "$name: $why; command: $*; output: $out"; else passed=$((passed + 1)); fi
}

# works NAME CMD...: exit 0.
works() {
  local name=$1
  shift
  local out
  if out=$(cd "$work" && timeout 120 "$@" 2>&1); then passed=$((passed + 1))
  else fail "$name: exit $?; command: $*; output: $out"; fi
}

S=$repo/scenarios/simple_road.yaml
R=$in/run
run_args=(--duration 1 --no-figures -q)
filter_args=(--no-figures -q)
"$dualgrid" run "$S" "${run_args[@]}" --detections exact --out "$R" || { echo "cannot make a run"; exit 1; }
"$py" "$repo/tests/recorded/make_radarscenes.py" --out "$in/rs" --duration 1 >/dev/null ||
  { echo "cannot make a RadarScenes dataset"; exit 1; }
mkdir -p "$in/scen" "$in/exp" "$in/sens"
cp "$in/rs/sensors.json" "$in/sens/sensors.json"
echo "(a foreign file)" >"$in/sens/readme.txt"
cp "$S" "$in/scen/s.yaml"
cp -r "$R" "$in/exp/input_run"           # an experiment-like folder that holds an input
ln -s "$R" "$in/run_link"                 # a link to the run
ln -s "$in" "$work/in_link"               # a link to the folder of every input
printf 'name: x\ncases:\n  - name: a\n    scenario: s.yaml\n    duration: 1\n    seeds: 1\n' >"$in/scen/suite.yaml"
echo "precious" >"$in/thesis.tex"

# --- The issue's lost-data cases, each spelled several ways. ---
refused export_into_itself "same place" "$dualgrid" export "$R" --out "$R"
refused export_into_itself_force "same place" "$dualgrid" export "$R" --out "$R" --force
refused export_dot_slash "same place" "$dualgrid" export "$R/." --out "$R//"
refused export_relative "same place" bash -c "cd '$R' && '$dualgrid' export . --out ../run/"
refused export_detour "same place" "$dualgrid" export "$R" --out "$in/scen/../run" --force
refused export_link "same place" "$dualgrid" export "$R" --out "$in/run_link" --force
refused export_inside "inside the input" "$dualgrid" export "$R" --out "$R/sub"
refused export_parent "contain the input" "$dualgrid" export "$R" --out "$in" --force
refused export_parent_link "contain the input" "$dualgrid" export "$R" --out "$work/in_link" --force
refused filter_into_itself "same place" "$dualgrid" filter "$R" --out "$R" "${filter_args[@]}"
refused filter_into_itself_force "same place" "$dualgrid" filter "$R" --out "$R" --force "${filter_args[@]}"
refused filter_link_inside "inside the input" "$dualgrid" filter "$in/run_link" --out "$R/x" "${filter_args[@]}"
refused filter_dataset_root "contain the input" \
  "$dualgrid" filter "$in/rs/data/sequence_1" --out "$in/rs" --force "${filter_args[@]}"
refused filter_sensors_file "sensors file" \
  "$dualgrid" filter "$in/rs/data/sequence_1" --sensors "$in/sens/sensors.json" --out "$in/sens" --force "${filter_args[@]}"
refused experiment_folder_with_input "contain the input" \
  "$dualgrid" export "$in/exp/input_run" --out "$in/exp" --force
refused run_into_scenario_folder "contain the input" \
  "$dualgrid" run "$in/scen/s.yaml" --out "$in/scen" --force "${run_args[@]}"
refused run_into_scenario_file "same place" \
  "$dualgrid" run "$in/scen/s.yaml" --out "$in/scen/s.yaml" --force "${run_args[@]}"
refused sim_into_scenario_folder "contain the input" \
  "$dualgrid" sim "$in/scen/s.yaml" --out "$in/scen" --force --duration 1 -q
refused experiment_into_scenario_folder "contain the input" \
  "$dualgrid" experiment "$in/scen/s.yaml" --seeds 1 --out "$in" --force --duration 1 -q --no-figures
refused sweep_into_scenario_folder "contain the input" \
  "$dualgrid" sweep "$in/scen/s.yaml" --set filter.sigma_v=1 --out "$in/scen" --emit list -q
refused regress_into_suite_folder "contain the input" \
  "$dualgrid" regress "$in/scen/suite.yaml" --out "$in/scen" --force -q

# --- Names from the user never leave --out. ---
refused sequence_up "--sequence: '../../X'" "$dualgrid" export "$R" --out "$work/e1" --sequence ../../X
refused sequence_absolute "--sequence: '/" "$dualgrid" export "$R" --out "$work/e2" --sequence "$work/abs"
refused sequence_dotdot "--sequence: '..'" "$dualgrid" export "$R" --out "$work/e3" --sequence ..
refused sequence_newline "control character" "$dualgrid" export "$R" --out "$work/e4" --sequence $'a\nb'
refused version_up "--version: '../v'" "$dualgrid" export "$R" --format nuscenes --out "$work/e5" --version ../v
refused scene_slash "--scene: 'a/b'" "$dualgrid" export "$R" --format nuscenes --out "$work/e6" --scene a/b
for d in X abs v; do [ -e "$work/$d" ] && fail "a name left --out: $work/$d exists"; done
[ -e "$work/e1" ] && fail "sequence_up: --out was created before the name was checked"

# --- A generator never overwrites a scenario or a network it did not write (without --force). ---
echo "<net/>" >"$in/scen/mine.net.xml"
refused tangential_over_scenario "exists; add --force" "$dualgrid" tangential --kind crossing --out "$in/scen/s.yaml" -q
refused tangential_over_network "mine.net.xml exists" "$dualgrid" tangential --kind aspect --out "$in/scen/mine.yaml" -q

# --- Folders: never emptied unless created by this command, or with --force of our own. ---
refused not_empty "is not empty" "$dualgrid" run "$S" --out "$in" "${run_args[@]}"
refused foreign_force "not a dualgrid output" "$dualgrid" run "$S" --out "$in/exp" --force "${run_args[@]}"
ln -s "$work/nowhere/x" "$work/dangling"
refused out_dangling_link "symbolic link to a missing folder" "$dualgrid" run "$S" --out "$work/dangling" "${run_args[@]}"
refused out_under_a_file "cannot create the folder" "$dualgrid" run "$S" --out "$in/thesis.tex/run" "${run_args[@]}"
refused out_is_a_file "not a folder" "$dualgrid" run "$S" --out "$in/thesis.tex" --force "${run_args[@]}"
out=$work/rerun
works first_run "$dualgrid" run "$S" "${run_args[@]}" --detections csv --out "$out"
echo mine >"$out/notes.txt"
before=$(sha1sum "$out/detections.csv")
refused rerun_without_force "add --force" "$dualgrid" run "$S" "${run_args[@]}" --out "$out"
[ "$(sha1sum "$out/detections.csv")" = "$before" ] || fail "rerun_without_force touched the folder"
works rerun_force "$dualgrid" run "$S" "${run_args[@]}" --out "$out" --force
[ -e "$out/detections.csv" ] && fail "rerun_force: the earlier run's detections.csv stayed"
[ "$(cat "$out/notes.txt" 2>/dev/null)" = mine ] || fail "rerun_force: the user's notes.txt was removed"
grep -q '"complete": true' "$out/summary.json" || fail "rerun_force: no complete summary.json"

exp=$work/exp
works experiment_first "$dualgrid" experiment "$S" --seeds 1 --duration 1 --no-figures -q --out "$exp"
echo mine >"$exp/notes.txt"
refused experiment_rerun "add --force" "$dualgrid" experiment "$S" --seeds 1 --duration 1 --no-figures -q --out "$exp"
works experiment_force "$dualgrid" experiment "$S" --seeds 1 --duration 1 --no-figures -q --out "$exp" --force
[ "$(cat "$exp/notes.txt" 2>/dev/null)" = mine ] || fail "experiment_force: the user's notes.txt was removed"
grep -q '"complete": true' "$exp/summary.json" || fail "experiment_force: no complete summary.json"

# --- Export of a run that did not finish. ---
cp -r "$R" "$in/killed"
rm "$in/killed/summary.json"
refused export_incomplete "not a finished run" "$dualgrid" export "$in/killed" --out "$work/x1"
cp -r "$R" "$in/stopped"
sed -i 's/"complete": true/"complete": false/' "$in/stopped/summary.json"
refused export_complete_false "not a finished run" "$dualgrid" export "$in/stopped" --out "$work/x2"
works export_allow_incomplete "$dualgrid" export "$in/killed" --out "$work/x3" --allow-incomplete -q
[ -f "$work/x3/INCOMPLETE.txt" ] || fail "export_allow_incomplete: no INCOMPLETE.txt"
msg=$(cd "$work" && "$dualgrid" filter "$work/x3/data/sequence_1" --out "$work/x4" "${filter_args[@]}" 2>&1)
[[ "$msg" == *"did not finish"* ]] || fail "filter of an incomplete export does not say so: $msg"
grep -q '"source_incomplete": true' "$work/x4/summary.json" || fail "x4: source_incomplete not recorded"

echo "output guard cases: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
