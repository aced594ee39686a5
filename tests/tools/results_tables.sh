#!/usr/bin/env bash
# scripts/results_tables.py (the tables of docs/results.md and the comparison of two ablation
# runs): what it prints is what the folders hold, and bad input ends with exit 2 and one line.
#
#   1. `tables`: an OUT folder made here (random values from a fixed seed) gives section 1's
#      simple-road table with those values at the page's precision, and an experiment whose
#      summary.json is not complete is left out with a note;
#   2. `compare`: two folders differing in one mean by more than its half-width list exactly that
#      value as moved (in each experiment that holds it), and its pair of modes as reordered;
#   3. hostile input (a FIFO, a directory, non-UTF-8, NUL bytes, short rows, NaN and infinite
#      numbers, a fractional seed count, a missing folder): exit 2, one line naming the file,
#      within 10 s (a FIFO must not block);
#   4. the page parser against 150 random edits of docs/results.md (fixed seed): exit 0 or 2,
#      never a Python traceback.
# Usage: results_tables.sh REPO
set -euo pipefail
REPO=${1:?usage: results_tables.sh REPO}
SCRIPT="$REPO/scripts/results_tables.py"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# An OUT folder: OUT/simple_road/{preset_paper,preset_dualgrid,unfinished}; means from seed SEED,
# with one value overridden by OVERRIDE ("metric,mode,mean" or empty). Prints nothing.
make_out() {
  local out=$1 seed=$2 override=$3
  python3 - "$out" "$seed" "$override" <<'EOF'
import json, os, random, sys
out, seed, override = sys.argv[1], int(sys.argv[2]), sys.argv[3]
rng = random.Random(seed)
metrics = ["delta_x", "delta_v", "t_d", "D", "D_v"]
for exp, complete in [("preset_paper", True), ("preset_dualgrid", True), ("unfinished", False)]:
    folder = os.path.join(out, "simple_road", exp)
    os.makedirs(folder)
    with open(os.path.join(folder, "summary.json"), "w") as f:
        json.dump({"complete": complete}, f)
    with open(os.path.join(folder, "table.csv"), "w") as f:
        f.write("scenario,metric,unit,mode,n,mean,ci95_half_width,ci95_low,ci95_high,paper\n")
        for m in metrics:
            for mode in ["position", "velocity", "dual"]:
                mean = rng.uniform(0.5, 9.5) if m[0] != "D" else rng.uniform(10, 90)
                if override and override.split(",")[:2] == [m, mode]:
                    mean = float(override.split(",")[2])
                ci = mean * 0.01
                f.write(f"simple_road,{m},-,{mode},5,{mean!r},{ci!r},,,1.5\n")
EOF
}

# --- 1. tables -------------------------------------------------------------------------------
make_out "$WORK/a" 11 ""
python3 "$SCRIPT" tables "$WORK/a" --section 1 >"$WORK/t1" 2>"$WORK/t1.err" || fail "tables exit $?"
grep -q "unfinished: not complete" "$WORK/t1.err" || fail "no note for the unfinished experiment"
# Every mean of preset_paper appears in the table at the page's decimals (2, or 1 for D and D_v).
python3 - "$WORK/a/simple_road/preset_paper/table.csv" "$WORK/t1" <<'EOF' || fail "tables: values"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
text = open(sys.argv[2]).read()
label = {"delta_x": "Δx [m]", "delta_v": "Δv [m/s]", "t_d": "t_d [s]", "D": "D [%]",
         "D_v": "D_v (velocity right) [%]"}
lines = {l.split("|")[1].strip(): l for l in text.splitlines() if l.startswith("| ")}
bad = 0
for r in rows:
    dec = 1 if r["metric"] in ("D", "D_v") else 2
    want = f"{float(r['mean']):.{dec}f} ± {float(r['ci95_half_width']):.{dec}f}"
    if want not in lines.get(label[r["metric"]], ""):
        print(f"missing {r['metric']} {r['mode']}: {want}")
        bad += 1
sys.exit(1 if bad else 0)
EOF

# --- 2. compare ------------------------------------------------------------------------------
# The same seed, and the dual mode's D far above the others: moved, and the pair reordered.
make_out "$WORK/b" 11 "D,dual,99.0"
make_out "$WORK/c" 11 "D,dual,1.0"
python3 "$SCRIPT" compare "$WORK/b" "$WORK/c" --moved >"$WORK/cmp" 2>/dev/null || fail "compare exit $?"
# Three rows: preset_paper, preset_dualgrid and fit_both (read from preset_dualgrid when missing).
moved=$(grep -c "| \*\*moved\*\* |" "$WORK/cmp" || true)
[[ $moved -eq 3 ]] || fail "compare: expected 3 moved rows (D dual), got $moved"
grep "| \*\*moved\*\* |" "$WORK/cmp" | grep -v "| D | dual |" && fail "compare: another row moved"
grep -q "flipped" "$WORK/cmp" || fail "compare: the D orderings with dual did not flip"

# --- 3. hostile input ------------------------------------------------------------------------
# Each case: a folder made from a good one with table.csv replaced; must exit 2 with one line
# naming table.csv (or the folder) within 10 s.
hostile() {  # name, then a command run in the case's experiment folder
  local name=$1
  shift
  local out="$WORK/h_$name"
  make_out "$out" 11 ""
  (cd "$out/simple_road/preset_paper" && eval "$*")
  local rc=0
  timeout 10 python3 "$SCRIPT" tables "$out" >/dev/null 2>"$WORK/err" || rc=$?
  local lines
  lines=$(grep -cv "not complete" "$WORK/err" || true)
  if [[ $rc -ne 2 ]]; then
    fail "hostile $name: exit $rc, expected 2"
  elif [[ $lines -ne 1 ]] || ! grep -v "not complete" "$WORK/err" | grep -q "preset_paper"; then
    fail "hostile $name: expected one line naming the file, got: $(cat "$WORK/err")"
  fi
}
hostile fifo 'rm table.csv && mkfifo table.csv'
hostile directory 'rm table.csv && mkdir table.csv'
hostile dangling 'rm table.csv && ln -s nowhere table.csv'
hostile latin1 "printf 'scenario,metric,mode,n,mean,ci95_half_width,paper\nx,\xe9,dual,5,1,1,\n' >table.csv"
hostile nul "printf 'scenario,metric,mode,n,mean,ci95_half_width,paper\nx,D,dual,5,1\0,1,\n' >table.csv"
hostile short_row "printf 'scenario,metric,mode,n,mean,ci95_half_width,paper\nx,D,dual,5\n' >table.csv"
hostile nan "sed -i '2s/,5,[^,]*,/,5,nan,/' table.csv"
hostile inf "sed -i '2s/,5,[^,]*,/,5,1e999,/' table.csv"
hostile fractional_n "sed -i '2s/,5,/,2.5,/' table.csv"
hostile empty ': >table.csv'
hostile header_only "head -1 table.csv >t && mv t table.csv"
rc=0
timeout 10 python3 "$SCRIPT" tables "$WORK/none" >/dev/null 2>"$WORK/err" || rc=$?
[[ $rc -eq 2 && $(wc -l <"$WORK/err") -eq 1 ]] || fail "missing folder: exit $rc, $(cat "$WORK/err")"
mkfifo "$WORK/page.md"
rc=0
timeout 10 python3 "$SCRIPT" compare "$WORK/page.md" "$REPO/docs/results.md" >/dev/null 2>"$WORK/err" || rc=$?
[[ $rc -eq 2 ]] || fail "compare with a FIFO page: exit $rc, expected 2"

# --- 4. edited pages -------------------------------------------------------------------------
python3 - "$SCRIPT" "$REPO/docs/results.md" "$WORK" <<'EOF' || fail "edited pages"
import os, random, subprocess, sys
script, page, work = sys.argv[1], sys.argv[2], sys.argv[3]
text = open(page, encoding="utf-8").read()
rng = random.Random(7)
bad = 0
for i in range(150):
    lines = text.split("\n")
    for _ in range(rng.randint(1, 20)):
        j = rng.randrange(len(lines))
        line, op = lines[j], rng.randrange(6)
        if op == 0 and line:
            k = rng.randrange(len(line))
            lines[j] = line[:k] + rng.choice("|±-.0123456789e*nanx ") + line[k + 1:]
        elif op == 1:
            lines[j] = line.replace("±", "")
        elif op == 2:
            lines[j] = line.replace("|", "", 1)
        elif op == 3:
            lines.insert(j, lines[rng.randrange(len(lines))])
        elif op == 4:
            del lines[j]
        else:
            lines[j] = line + " | 1e999 ± nan |"
    edited = os.path.join(work, "edited.md")
    with open(edited, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))
    r = subprocess.run([sys.executable, script, "compare", page, edited], capture_output=True,
                       text=True, timeout=60)
    if r.returncode not in (0, 2) or "Traceback" in r.stderr:
        print(f"edit {i}: exit {r.returncode}: {r.stderr[-400:]}")
        bad += 1
sys.exit(1 if bad else 0)
EOF

if [[ $fails -ne 0 ]]; then
  echo "results_tables.sh: $fails failure(s)"
  exit 1
fi
echo "results_tables.sh: all checks passed"
