# Shared by the shell tests of tests/sim (sourced): a work folder removed at exit, and checks on a
# run folder's JSON. Usage: source run_checks.sh NAME   (then $work is the current folder)
export SUMO_HOME=${SUMO_HOME:-/usr/share/sumo}
work=$(mktemp -d "${TMPDIR:-/tmp}/dualgrid_$1.XXXXXX")
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
failed=0
fail() { echo "FAIL: $*"; failed=1; }
# json FILE EXPRESSION: the Python expression over the file's JSON as `d`, printed.
json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }
# scored RUN_DIR [MODE]: objects scored in the run's table (mode dual by default).
scored() {
  python3 -c "import json,sys; t=json.load(open(sys.argv[1])); print([m for m in t['metrics'] if m['key']=='objects_scored'][0]['values'][sys.argv[2]]['mean'])" "$1/table.json" "${2:-dual}"
}
