# Hostile inputs of the newer surface (issue 26), sourced by run_hostile.sh (its check(), $work,
# $dualgrid, $repo, $network_dir): what dualgrid reads back (a sweep's plan.json, a run's
# table.json and summary.json, a replay recording), sweeps too large to validate, suites whose
# seeds overflow, a SUMO configuration's step length, an experiment that SUMO refuses.
# Every damaged file must give one "dualgrid: error:" line naming the file and the key, with the
# documented exit code; none may crash, hang, allocate without bound or be accepted.
rb=$work/read_back
mkdir -p "$rb"
S=$repo/scenarios/highway.yaml

# json FILE PYTHON-EXPRESSION: rewrites the JSON document `d` of FILE by the expression's
# statements (python3, as the viewer test uses).
json() {
  python3 -c "import json,sys; p=sys.argv[1]; d=json.load(open(p)); $2; json.dump(d, open(p,'w'))" "$1"
}

# --- 5. Sweeps: refused at once when too large (they validated every setting for minutes). ---
check "sweep:1e6_settings" 2 "more than 10000 settings" \
  "$dualgrid" sweep "$S" --set filter.sigma_v=1:1:1000 --set filter.sigma_f=1:1:1000 -q --emit list --out "$rb/big1"
check "sweep:1e9_settings" 2 "more than 10000 settings" \
  "$dualgrid" sweep "$S" --set filter.sigma_v=1:1:1000 --set filter.sigma_f=1:1:1000 \
  --set filter.static_speed=1:1:1000 -q --emit list --out "$rb/big2"
check "sweep:too_many_runs" 2 "expected at most 100000 runs" \
  "$dualgrid" sweep "$S" --set filter.sigma_v=1:1:1000 --seeds 101 -q --emit list --out "$rb/big3"
check "sweep:generator_1e6" 2 "more than 10000 settings" \
  "$dualgrid" sweep tangential --set tangential.angle=0:0.1:99.9 --set tangential.range=1:0.2:200 \
  -q --emit list --out "$rb/big4"

# The first SIGTERM stops a sweep while it validates its settings (it was ignored until every
# setting was checked): 10,000 settings take tens of seconds to check; the stop comes after 2 s
# and must end the sweep with 143 within 10 s, before anything ran or runs.txt was written.
start=$(date +%s)
(cd "$work" && exec "$dualgrid" sweep "$S" --set filter.sigma_v=1:1:100 --set filter.sigma_f=1:1:100 \
  -q --out "$rb/term") >"$rb/term.out" 2>&1 &
term_pid=$!
sleep 2
kill -TERM "$term_pid"
wait "$term_pid"
term_rc=$?
elapsed=$(($(date +%s) - start))
if [ "$term_rc" -eq 143 ] && [ "$elapsed" -le 10 ] && [ ! -e "$rb/term/runs.txt" ]; then
  passed=$((passed + 1))
else
  failed=$((failed + 1))
  printf 'FAIL sweep:sigterm_while_checking: exit %s after %s s (expected 143 within 10 s, no runs.txt): %s\n' \
    "$term_rc" "$elapsed" "$(cat "$rb/term.out")"
fi

# --- 6. A sweep folder whose plan.json is damaged: `sweep` (resuming) and `collect` both refuse
# it naming the file and the key. ---
"$dualgrid" sweep "$S" --set filter.sigma_v=0.5,1 --seeds 1 --duration 0.2 -q --emit list \
  --out "$rb/good" >/dev/null 2>&1 || echo "read_back: could not make the reference sweep"
plan=$rb/good/plan.json
damaged_plan() {  # NAME TEXT [python edit]: a copy of the good sweep with plan.json changed
  local dir=$rb/plan_$1
  rm -rf "$dir" && cp -r "$rb/good" "$dir"
  if [ -n "$3" ]; then json "$dir/plan.json" "$3"; else printf '%s' "$2" >"$dir/plan.json"; fi
  echo "$dir"
}
plan_case() {  # NAME TEXT-EXPECTED TEXT [python edit]
  local dir
  dir=$(damaged_plan "$1" "$3" "${4:-}")
  check "collect:plan_$1" 2 "$2" "$dualgrid" collect "$dir" -q
  check "sweep:plan_$1" 2 "$2" \
    "$dualgrid" sweep "$S" --set filter.sigma_v=0.5,1 --seeds 1 --duration 0.2 -q --emit list --out "$dir"
}
plan_case not_json "plan.json: not valid JSON" '{"scenario": '
plan_case truncated "not valid JSON (at byte" "$(head -c 200 "$plan")"
plan_case null "plan.json: the document" 'null'
plan_case list "plan.json: the document" '[1, 2]'
plan_case empty "not valid JSON" ''
plan_case nested "nested" "$(printf '%.0s[' $(seq 1 100000))"
plan_case axes_text "key 'axes': expected a list" '' 'd["axes"] = "filter.sigma_v"'
plan_case axes_empty "key 'axes': expected at least one axis" '' 'd["axes"] = []'
plan_case axis_key_number "key 'axes[0].key': expected a text" '' 'd["axes"][0]["key"] = 3'
plan_case seeds_text "key 'seeds'" '' 'd["seeds"] = "three"'
plan_case seeds_zero "key 'seeds': expected a whole number in [1, 10000]" '' 'd["seeds"] = 0'
plan_case first_seed_negative "key 'first_seed'" '' 'd["first_seed"] = -1'
plan_case first_seed_2_64 "key 'first_seed'" '' 'd["first_seed"] = 18446744073709551615'
plan_case first_seed_float "key 'first_seed'" '' 'd["first_seed"] = 1.5'
plan_case modes_unknown "key 'modes[0]': expected position, velocity or dual" '' 'd["modes"] = ["fancy"]'
plan_case duration_text "key 'duration'" '' 'd["duration"] = "long"'
plan_case settings_null "key 'settings': expected a list" '' 'd["settings"] = None'
plan_case setting_id_path "key 'settings[0].id'" '' 'd["settings"][0]["id"] = "../../etc"'
plan_case setting_id_twice "key 'settings[1].id'" '' 'd["settings"][1]["id"] = d["settings"][0]["id"]'
plan_case setting_values_short "key 'settings[0].values': expected a list of 1" '' 'd["settings"][0]["values"] = []'
plan_case run_unknown_setting "key 'runs[0].setting'" '' 'd["runs"][0]["setting"] = "s999"'
plan_case run_seed_text "key 'runs[0].seed'" '' 'd["runs"][0]["seed"] = "one"'
plan_case runs_missing "key 'runs': missing" '' 'del d["runs"]'
mkdir -p "$rb/plan_folder" && cp -r "$rb/good/." "$rb/plan_folder" && rm "$rb/plan_folder/plan.json" &&
  mkdir "$rb/plan_folder/plan.json"
check "collect:plan_is_folder" 2 "plan.json: sweep plan is a directory" "$dualgrid" collect "$rb/plan_folder" -q
mkdir -p "$rb/plan_fifo" && cp -r "$rb/good/." "$rb/plan_fifo" && rm "$rb/plan_fifo/plan.json" &&
  mkfifo "$rb/plan_fifo/plan.json"
check "collect:plan_is_fifo" 2 "plan.json: sweep plan is a FIFO" "$dualgrid" collect "$rb/plan_fifo" -q
mkdir -p "$rb/plan_zero" && cp -r "$rb/good/." "$rb/plan_zero" && ln -sf /dev/zero "$rb/plan_zero/plan.json"
check "collect:plan_is_dev_zero" 2 "sweep plan is a device" "$dualgrid" collect "$rb/plan_zero" -q
mkdir -p "$rb/plan_huge" && cp -r "$rb/good/." "$rb/plan_huge" &&
  head -c 70000000 /dev/zero | tr '\0' ' ' >"$rb/plan_huge/plan.json"
check "collect:plan_huge" 2 "sweep plan is larger than 64 MiB" "$dualgrid" collect "$rb/plan_huge" -q
check "collect:no_plan" 2 "no plan.json (not a sweep folder)" "$dualgrid" collect "$rb" -q

# --- 7. A run's results, read back by collect: a run counts only once its table is read. ---
table='{"scenario": "x", "modes": ["position", "velocity", "dual"], "notes": [], "status": "", "metrics": [{"key": "D", "label": "D", "unit": "%", "values": {"position": {"n": 1, "mean": 80.0, "ci95_half_width": null}, "velocity": {"n": 1, "mean": 81.0, "ci95_half_width": null}, "dual": {"n": 1, "mean": 82.0, "ci95_half_width": null}}}]}'
make_runs() {  # DIR: a copy of the good sweep with both runs finished (summary and table)
  rm -rf "$1" && cp -r "$rb/good" "$1"
  for s in s001 s002; do
    mkdir -p "$1/runs/$s/seed_1"
    printf '%s' '{"complete": true}' >"$1/runs/$s/seed_1/summary.json"
    printf '%s' "$table" >"$1/runs/$s/seed_1/table.json"
  done
}
run_case() {  # NAME EXPECTED-TEXT SUMMARY TABLE [COMMAND in the run folder]: collect exits 3
  local dir=$rb/run_$1
  make_runs "$dir"
  local run=$dir/runs/s002/seed_1
  [ "$3" = "-" ] || printf '%s' "$3" >"$run/summary.json"
  [ "$4" = "-" ] || printf '%s' "$4" >"$run/table.json"
  [ -z "${5:-}" ] || (cd "$run" && eval "$5")
  check "collect:run_$1" 3 "$2" "$dualgrid" collect "$dir" -q
}
run_case table_truncated "table.json: not valid JSON" - "${table:0:120}"
run_case table_nan "table.json: not valid JSON" - "${table/80.0/NaN}"
run_case table_empty "table.json: not valid JSON" - ""
run_case table_null_metrics "table.json: key 'metrics': expected a list" - '{"metrics": null}'
run_case table_no_metrics "key 'metrics': expected at least one metric" - '{"metrics": []}'
run_case table_mean_text "key 'metrics[0].values.dual.mean': expected a finite number or null" - \
  "${table/82.0/\"high\"}"
run_case table_mode_missing "has no value for mode 'dual'" - \
  '{"metrics": [{"key": "D", "unit": "%", "values": {"position": {"n": 1, "mean": 80.0}, "velocity": {"n": 1, "mean": 81.0}}}]}'
run_case table_key_number "key 'metrics[0].key': expected a text" - '{"metrics": [{"key": 4, "values": {}}]}'
run_case table_is_folder "table.json: result table is a directory" - - 'rm table.json && mkdir table.json'
run_case table_missing "table.json: result table not found" - - 'rm table.json'
run_case summary_not_json "summary.json: not valid JSON" '{"complete": tr' -
run_case summary_complete_text "key 'complete': expected true or false" '{"complete": "yes"}' -
run_case summary_incomplete "stopped by signal 15" '{"complete": false, "status": "stopped by signal 15"}' -
run_case summary_dev_zero "summary.json: run summary is a device" - - 'ln -sf /dev/zero summary.json'
# A copied sweep folder reads its own runs: the original is gone, the copy collects complete.
make_runs "$rb/original"
cp -r "$rb/original" "$rb/copied" && rm -rf "$rb/original"
if out=$("$dualgrid" collect "$rb/copied" -q 2>&1) && grep -q '"complete": true' "$rb/copied/sweep.json" &&
  head -1 "$rb/copied/tidy.csv" | grep -q ',seed,mode,metric,unit,value$' &&
  head -1 "$rb/copied/aggregate.csv" | grep -q ',mode,metric,unit,n,mean,ci95_half_width$'; then
  passed=$((passed + 1))
else
  failed=$((failed + 1))
  printf 'FAIL collect:copied_folder: a copied sweep folder did not collect its own runs: %s\n' "$out"
fi

# --- 8. Replay recordings, damaged: `replay --html` refuses what the video refuses. ---
# (--no-figures turns the recording off: a short run with figures in one format)
"$dualgrid" run "$S" --duration 0.5 --modes position,dual --record-interval 0.1 \
  --figure-formats png --snapshots 0.5 -q --out "$rb/rec" >/dev/null 2>&1 ||
  echo "read_back: could not record the reference run"
replay_case() {  # NAME EXPECTED-TEXT python-edit-of-index [frames.bin edit: shell command]
  local dir=$rb/replay_$1
  rm -rf "$dir" && mkdir -p "$dir" && cp -r "$rb/rec/replay" "$dir/replay"
  [ -z "$3" ] || json "$dir/replay/index.json" "$3"
  [ -z "${4:-}" ] || (cd "$dir/replay" && eval "$4")
  check "replay_html:$1" 2 "$2" "$dualgrid" replay "$dir" --html -q
}
replay_case format "key 'format': expected \"dualgrid-replay\"" 'd["format"] = "other"'
replay_case version_1 "key 'version': expected 2" 'd["version"] = 1'
replay_case version_text "key 'version': expected 2" 'd["version"] = "2"'
replay_case huge_grid "a frame of 20000 x 10000 cells" 'd["cells_x"] = 20000; d["cells_y"] = 10000'
replay_case zero_cells "key 'cells_x': expected a whole number in [1, 1000000]" 'd["cells_x"] = 0'
replay_case negative_cells "key 'cells_y': expected a whole number in [1, 1000000]" 'd["cells_y"] = -5'
replay_case cells_float "key 'cells_x'" 'd["cells_x"] = 1.5'
replay_case particles_2_31 "key 'max_particles': expected a whole number in [0, 1000000]" \
  'd["max_particles"] = 2**31 - 1; [m.__setitem__("np", 2**31 - 1) for f in d["frames"] for m in f["modes"]]'
replay_case np_above_max "key 'frames[0].modes[0].np'" 'd["frames"][0]["modes"][0]["np"] = d["max_particles"] + 1'
replay_case resolution_zero "key 'resolution'" 'd["resolution"] = 0'
replay_case interval_negative "key 'interval'" 'd["interval"] = -0.1'
replay_case modes_empty "key 'modes': expected at least one mode" 'd["modes"] = []'
replay_case modes_many "key 'modes': expected a list of at most 3" 'd["modes"] = ["a", "b", "c", "d"]'
replay_case sensors_text "key 'sensors': expected a list" 'd["sensors"] = "front"'
replay_case names_list "key 'names': expected an object" 'd["names"] = []'
replay_case complete_text "key 'complete': expected true or false" 'd["complete"] = "yes"'
replay_case parked_short "key 'parked[0]': expected a list of 8" 'd["parked"] = [[1, 2, 3]]'
replay_case rails_text "key 'rails[0]'" 'd["rails"] = ["x"]'
replay_case frames_empty "key 'frames': expected a non-empty list" 'd["frames"] = []'
replay_case frames_missing "key 'frames': missing" 'del d["frames"]'
replay_case frame_time_text "key 'frames[0].t'" 'd["frames"][0]["t"] = "now"'
replay_case frame_yaw_missing "key 'frames[1].yaw': missing" 'del d["frames"][1]["yaw"]'
replay_case blob_beyond "frames.bin: shorter than" 'd["frames"][2]["blob"][0] = 10**12'
replay_case blob_negative "key 'frames[0].blob[0]'" 'd["frames"][0]["blob"][0] = -1'
replay_case blob_three "key 'frames[0].blob': expected a list of 2" 'd["frames"][0]["blob"].append(0)'
replay_case frame_modes_short "key 'frames[0].modes': expected a list of 2" 'd["frames"][0]["modes"].pop()'
replay_case detection_short "key 'frames[1].det[0]': expected a detection" \
  'd["frames"][1]["det"] = [[0, 1, 2, 3, 4]]'
replay_case detection_sensor "key 'frames[1].det[0][0]'" 'd["frames"][1]["det"] = [[99, 1, 2, 3, 4, 0]]'
replay_case detection_text "key 'frames[1].det[0][1]': expected a finite number" \
  'd["frames"][1]["det"] = [[0, "x", 2, 3, 4, 0]]'
replay_case detection_path "key 'frames[1].det[0][6]'" 'd["frames"][1]["det"] = [[0, 1, 2, 3, 4, 0, 7]]'
replay_case cluster_short "key 'frames[2].modes[0].cl[0]': expected a list of 11" \
  'd["frames"][2]["modes"][0]["cl"] = [[1, 2, 3]]'
replay_case cluster_role "key 'frames[2].modes[0].cl[0][8]'" \
  'd["frames"][2]["modes"][0]["cl"] = [[1, 2, 3, 4, 5, 6, 7, 8, 9, -1, 0]]'
replay_case live_negative "key 'frames[0].modes[1].live[0]'" 'd["frames"][0]["modes"][1]["live"][0] = -3'
replay_case truth_box "key 'frames[3].truth[0][1]'" 'd["frames"][3]["truth"] = [[1, None, 0, 0, 4, 2, 0, 0]]'
replay_case ego_missing "key 'frames[0].ego': missing" 'del d["frames"][0]["ego"]'
replay_case origin_short "key 'frames[0].origin': expected a list of 2" 'd["frames"][0]["origin"] = [1]'
replay_case flipped_bytes "frames.bin: frame 2 (index.json's frames[2].blob) is damaged" '' \
  'python3 -c "b = bytearray(open(\"frames.bin\", \"rb\").read()); b[len(b) // 2] ^= 0xFF; b[len(b) // 2 + 7] ^= 0x5A; open(\"frames.bin\", \"wb\").write(b)"'
replay_case frames_truncated "frames.bin: shorter than" '' 'truncate -s 100 frames.bin'
replay_case frames_missing_file "frames.bin: shorter than" '' 'rm frames.bin'
replay_case frames_is_folder "frames.bin: the recording's frames are not a regular file (a directory)" '' \
  'rm frames.bin && mkdir frames.bin'
replay_case frames_dev_zero "frames.bin: the recording's frames are not a regular file (a device" '' \
  'ln -sf /dev/zero frames.bin'
replay_case index_not_json "index.json: not valid JSON" '' 'head -c 300 index.json > i && mv i index.json'
replay_case index_is_folder "index.json: replay index is a directory" '' 'rm index.json && mkdir index.json'
replay_case index_dev_zero "index.json: replay index is a device" '' 'ln -sf /dev/zero index.json'
replay_case index_fifo "index.json: replay index is a FIFO" '' 'rm index.json && mkfifo index.json'
# The video path reads through the same reader: the header cases fail before ffmpeg starts.
for name in huge_grid particles_2_31 version_1 frames_truncated; do
  check "replay_video:$name" 2 "" "$dualgrid" replay "$rb/replay_$name" -q --preview none
done

# --- 9. Regression suites whose seeds overflow (exit 3 with nothing said, under -q). ---
suite_case() {  # NAME EXPECTED-TEXT FIRST_SEED [SEEDS]
  printf 'cases:\n  - name: c\n    scenario: %s\n    seeds: %s\n    first_seed: %s\n    duration: 1\n' \
    "$S" "${4:-2}" "$3" >"$rb/suite_$1.yaml"
  check "regress:$1" 2 "$2" "$dualgrid" regress "$rb/suite_$1.yaml" --out "$rb/suite_out_$1" -q
}
suite_case first_seed_2_64 "cases[0].first_seed" 18446744073709551615
suite_case first_seed_2_60 "first_seed + seeds - 1 <= 9007199254740991" 1152921504606846976
suite_case first_seed_edge "first_seed + seeds - 1 <= 9007199254740991" 9007199254740991 2
suite_case first_seed_negative "cases[0].first_seed" -1
# A case that does not run (SUMO refuses its route) exits 3 and says why on stderr, also under -q
# (it used to exit 3 with nothing said); the report itself goes to stdout.
sed 's/east_2/no_such_edge/' "$S" >"$rb/bad_edge.yaml"
printf 'cases:\n  - name: c\n    scenario: %s\n    seeds: 1\n    duration: 0.5\n' "$rb/bad_edge.yaml" \
  >"$rb/suite_not_run.yaml"
(cd "$work" && timeout 60 "$dualgrid" regress "$rb/suite_not_run.yaml" --out "$rb/suite_out_not_run" -q \
  >/dev/null 2>"$rb/not_run.err")
not_run_rc=$?
if [ "$not_run_rc" -eq 3 ] && [ "$(wc -l <"$rb/not_run.err")" -eq 1 ] &&
  grep -q "^dualgrid: error: regress: case c did not run: .*no_such_edge" "$rb/not_run.err"; then
  passed=$((passed + 1))
else
  failed=$((failed + 1))
  printf 'FAIL regress:case_not_run_quiet: exit %s, stderr: %s\n' "$not_run_rc" "$(cat "$rb/not_run.err")"
fi
mkfifo "$rb/suite_fifo.yaml"
check "regress:suite_fifo" 2 "suite file is a FIFO" "$dualgrid" regress "$rb/suite_fifo.yaml" --out "$rb/sf" -q
check "regress:suite_dev_zero" 2 "suite file is a device" "$dualgrid" regress /dev/zero --out "$rb/sz" -q

# --- 10. A SUMO configuration's step length, and a scenario SUMO refuses under `experiment`. ---
for v in nan inf -0.1 fast 0; do
  printf '<configuration>\n  <input>\n    <net-file value="%s"/>\n    <route-files value="ok.rou.xml"/>\n  </input>\n  <time>\n    <step-length value="%s"/>\n  </time>\n</configuration>\n' \
    "$network_dir/highway.net.xml" "$v" >"$work/sumo/step_$v.sumocfg"
  printf 'sumo_config: step_%s.sumocfg\nego: {from_routes: v0}\n' "$v" >"$work/sumo/step_$v.yaml"
  check "sumo:step_length_$v" 2 "<step-length value=\"$v\"/>: expected a positive number" \
    "$dualgrid" run "$work/sumo/step_$v.yaml" --no-figures -q --out "$rb/step_$v"
done
check "experiment:bad_edge" 2 "The edge 'no_such_edge' within the route 'east' is not known" \
  "$dualgrid" experiment "$S" --set 'routes.east=[east_1, no_such_edge]' --seeds 2 --duration 0.5 \
  --no-figures -q --out "$rb/exp_bad_edge"
check "cli:frobnicate" 2 "unknown command 'frobnicate'" "$dualgrid" frobnicate --out x

# --- 11. Time of day and OpenDRIVE maps (docs/scenarios.md): a begin after the configuration's
# end, negative begins, an OpenDRIVE map netconvert rejects (named, with netconvert's first error
# line), one that is not XML, and one that does not exist. ---
printf '<configuration>\n  <input>\n    <net-file value="%s"/>\n    <route-files value="ok.rou.xml"/>\n  </input>\n  <time>\n    <begin value="500"/>\n    <end value="100"/>\n  </time>\n</configuration>\n' \
  "$network_dir/highway.net.xml" >"$work/sumo/late.sumocfg"
printf 'sumo_config: late.sumocfg\nego: {from_routes: v0}\n' >"$work/sumo/late.yaml"
check "time:begin_after_end" 2 "key 'sumo_config <begin>' expected < the configuration's end = 100 s (SUMO time)" \
  "$dualgrid" run "$work/sumo/late.yaml" --no-figures -q --out "$rb/late"
printf 'sumo_config: late.sumocfg\nbegin: -3\nego: {from_routes: v0}\n' >"$work/sumo/negative.yaml"
check "time:negative_begin" 2 "key 'begin' expected in [0, 31536000] s (SUMO time), got -3" \
  "$dualgrid" run "$work/sumo/negative.yaml" --no-figures -q --out "$rb/negative"
check "time:negative_begin_cli" 2 "--begin" \
  "$dualgrid" run "$S" --begin -3 --no-figures -q --out "$rb/negative_cli"
check "time:begin_not_a_time" 2 "key 'begin' expected a number" \
  "$dualgrid" run "$S" --set begin=noon --no-figures -q --out "$rb/noon"
export DUALGRID_CACHE_DIR=$work/cache
python3 "$repo/tests/sim/write_xodr.py" broken "$work/sumo/broken.xodr"
printf 'network: broken.xodr\nego: {from_routes: auto}\n' >"$work/sumo/broken_map.yaml"
check "opendrive:rejected" 2 "broken.xodr: netconvert cannot convert this OpenDRIVE map: Error: No nodes loaded." \
  "$dualgrid" run "$work/sumo/broken_map.yaml" --no-figures -q --out "$rb/broken_map"
head -c 3000 /dev/urandom >"$work/sumo/noise.xodr"
printf 'network: noise.xodr\nego: {from_routes: auto}\n' >"$work/sumo/noise_map.yaml"
check "opendrive:not_xml" 2 "noise.xodr: netconvert cannot convert this OpenDRIVE map: Error:" \
  "$dualgrid" run "$work/sumo/noise_map.yaml" --no-figures -q --out "$rb/noise_map"
printf 'network: nowhere.xodr\nego: {from_routes: auto}\n' >"$work/sumo/missing_map.yaml"
check "opendrive:missing" 2 "nowhere.xodr: OpenDRIVE map not found" \
  "$dualgrid" run "$work/sumo/missing_map.yaml" --no-figures -q --out "$rb/missing_map"
[ -e "$work/sumo/broken.net.xml" ] && { failed=$((failed + 1)); echo "FAIL opendrive: a network was written beside the map"; }
unset DUALGRID_CACHE_DIR
