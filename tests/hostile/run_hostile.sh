#!/usr/bin/env bash
# Hostile-input suite (docs/reliability.md): malformed scenario files (scenario_cases.txt),
# broken network files, and hostile command lines (cli_cases.txt). Every case must end within
# its time limit with the documented exit code and exactly one line on stderr+stdout,
# "dualgrid: error: ...", containing the expected text; none may crash, hang or succeed.
# Usage: run_hostile.sh DUALGRID NETWORK_DIR
set -uo pipefail
dualgrid=$(realpath "$1")
network_dir=$2
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/dualgrid_hostile.XXXXXX")
trap 'rm -rf "$work"' EXIT
passed=0
failed=0

# check NAME EXPECTED_CODE EXPECTED_TEXT CMD...
check() {
  local name=$1 code=$2 text=$3
  shift 3
  local out rc
  out=$(cd "$work" && timeout 60 "$@" 2>&1)
  rc=$?
  local why=""
  if [ "$rc" -eq 124 ]; then why="hung (killed after 60 s)"
  elif [ "$rc" -ge 128 ]; then why="crashed (signal $((rc - 128)))"
  elif [ "$rc" -ne "$code" ]; then why="exit code $rc, expected $code"
  elif [ "$(printf '%s\n' "$out" | wc -l)" -ne 1 ]; then why="printed more than one line"
  elif [[ "$out" != "dualgrid: error: "* ]]; then why="not a 'dualgrid: error:' line"
  elif [ -n "$text" ] && [[ "$out" != *"$text"* ]]; then why="message lacks '$text'"
  fi
  if [ -n "$why" ]; then
    failed=$((failed + 1))
    printf 'FAIL %s: %s\n  command: %s\n  output: %s\n' "$name" "$why" "$*" "$out"
  else
    passed=$((passed + 1))
  fi
}

# 1. Malformed scenario files.
mkdir -p "$work/scenarios"
awk -v dir="$work/scenarios" '
  /^#/ && !started { next }
  /^=== / {
    started = 1
    split(substr($0, 5), f, " \\| ")
    name = f[1]; file = dir "/" name ".yaml"
    print name "|" f[2] "|" f[3] > (dir "/index.txt")
    printf "" > file
    next
  }
  started { print >> file }
' "$here/scenario_cases.txt"
while IFS='|' read -r name code text; do
  check "scenario:$name" "$code" "$text" \
    "$dualgrid" run "$work/scenarios/$name.yaml" --duration 0.1 --no-figures -q --out "$work/out_$name"
done <"$work/scenarios/index.txt"

# 2. Network files that are not SUMO networks.
mkdir -p "$work/nets"
scenario_for() {  # a valid scenario on network file $1
  sed "s#^network: .*#network: $1#" "$repo/scenarios/highway.yaml" >"$work/nets/on_$(basename "$1" .net.xml).yaml"
  echo "$work/nets/on_$(basename "$1" .net.xml).yaml"
}
printf 'hello, I am not XML\n' >"$work/nets/not_xml.net.xml"
: >"$work/nets/empty.net.xml"
size=$(stat -c %s "$network_dir/highway.net.xml")
head -c $((size / 2)) "$network_dir/highway.net.xml" >"$work/nets/truncated.net.xml"
printf '<?xml version="1.0"?>\n<routes>\n</routes>\n' >"$work/nets/routes_only.net.xml"
head -c 300 /dev/urandom >"$work/nets/binary.net.xml"
mkdir -p "$work/nets/folder.net.xml"
for net in not_xml empty truncated routes_only binary; do
  check "network:$net" 2 "$work/nets/$net.net.xml" \
    "$dualgrid" run "$(scenario_for "$work/nets/$net.net.xml")" --duration 0.1 --no-figures -q --out "$work/net_$net"
done
check "network:folder" 2 "folder.net.xml" \
  "$dualgrid" run "$(scenario_for "$work/nets/folder.net.xml")" --duration 0.1 --no-figures -q --out "$work/net_folder"

# 3. Hostile command lines.
mkdir -p "$work/existing/x.png"
n=0
while IFS= read -r line; do
  [[ -z "$line" || "$line" == \#* ]] && continue
  n=$((n + 1))
  code=$(echo "$line" | cut -d'|' -f1 | xargs)
  text=$(echo "$line" | cut -d'|' -f2 | sed 's/^ //; s/ $//')
  args=$(echo "$line" | cut -d'|' -f3- | sed 's/^ //')
  args=${args//@OUT/$work/cli_out_$n}
  args=${args//@S/$repo/scenarios/highway.yaml}
  args=${args//@T/$work/existing}
  eval "set -- $args"
  check "cli:$n: $args" "$code" "$text" "$dualgrid" "$@"
done <"$here/cli_cases.txt"

echo "hostile inputs: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
