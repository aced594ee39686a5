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

# 4. SUMO files that could block, never end, take quadratic time or loop (docs/scenarios.md,
# "Bring your own SUMO scenario": every file is read once, streaming, bounded).
sumo=$work/sumo
net_abs=$(realpath "$network_dir")
mkdir -p "$sumo/folder.rou.xml"
mkfifo "$sumo/fifo.sumocfg" "$sumo/fifo.rou.xml"
routes() {  # a valid route file on the highway network, with $1 inserted
  printf '<routes>\n%s\n<vehicle id="v0" depart="0" departLane="1" departPos="300">\n' "$1"
  printf '  <route edges="east_1 east_2"/>\n</vehicle>\n</routes>\n'
}
routes "" >"$sumo/ok.rou.xml"
# A 3 MB comment (the text scan it replaces took over a minute).
routes "<!-- $(head -c 3000000 /dev/zero | tr '\0' 'x') -->" >"$sumo/comment.rou.xml"
routes "" | gzip -c | head -c 60 >"$sumo/damaged.rou.xml.gz"
printf '<additional>\n  <include href="loop.add.xml"/>\n</additional>\n' >"$sumo/loop.add.xml"
printf '<configuration>\n  <input>\n    <net-file value="net.bin"/>\n    <route-files value="ok.rou.xml"/>\n  </input>\n</configuration>\n' \
  >"$sumo/binary_net.sumocfg"
head -c 4000 /dev/urandom >"$sumo/net.bin"
sumo_case() {  # NAME SCENARIO-LINES: a scenario on the highway network with ego v0 of the files
  printf 'name: %s\nnetwork: %s\n%s\n' "$1" "$net_abs/highway.net.xml" "$2" \
    >"$sumo/$1.yaml"
  echo "$sumo/$1.yaml"
}
check "sumo:fifo_config" 2 "is a FIFO (named pipe), expected a regular file" \
  "$dualgrid" run "$(printf 'sumo_config: fifo.sumocfg\nego: {from_routes: v0}\n' >"$sumo/c1.yaml"; echo "$sumo/c1.yaml")" --no-figures -q --out "$work/s1"
check "sumo:fifo_routes" 2 "fifo.rou.xml: SUMO route file is a FIFO" \
  "$dualgrid" run "$(sumo_case fifo_routes 'traffic: {route_files: [fifo.rou.xml]}
ego: {from_routes: v0}')" --no-figures -q --out "$work/s2"
check "sumo:urandom_config" 2 "/dev/urandom: SUMO configuration is a device" \
  "$dualgrid" run "$(printf 'sumo_config: /dev/urandom\nego: {from_routes: v0}\n' >"$sumo/c3.yaml"; echo "$sumo/c3.yaml")" --no-figures -q --out "$work/s3"
check "sumo:zero_additional" 2 "/dev/zero: SUMO additional file is a device" \
  "$dualgrid" run "$(sumo_case zero_additional 'traffic: {route_files: [ok.rou.xml], additional_files: [/dev/zero]}
ego: {from_routes: v0}')" --no-figures -q --out "$work/s4"
check "sumo:folder_routes" 2 "SUMO route file is a directory" \
  "$dualgrid" run "$(sumo_case folder_routes 'traffic: {route_files: [folder.rou.xml]}
ego: {from_routes: v0}')" --no-figures -q --out "$work/s5"
check "sumo:damaged_gzip" 2 "damaged.rou.xml.gz" \
  "$dualgrid" run "$(sumo_case damaged_gzip 'traffic: {route_files: [damaged.rou.xml.gz]}
ego: {from_routes: v0}')" --no-figures -q --out "$work/s6"
check "sumo:include_loop" 2 "<include href> nested more than 8 levels deep" \
  "$dualgrid" run "$(sumo_case include_loop 'traffic: {route_files: [ok.rou.xml], additional_files: [loop.add.xml]}
ego: {from_routes: v0}')" --no-figures -q --out "$work/s7"
check "sumo:binary_net" 2 "net.bin" \
  "$dualgrid" run "$(printf 'sumo_config: binary_net.sumocfg\nego: {from_routes: v0}\n' >"$sumo/c8.yaml"; echo "$sumo/c8.yaml")" --no-figures -q --out "$work/s8"
# A radar cross-section that overflows 10^(rcs / 10) (1e300 dBsm gave NaN weights), for a vType
# of the route files.
routes '<vType id="lorry" length="12" vClass="truck"/>' >"$sumo/typed.rou.xml"
check "sumo:traffic_rcs_huge" 2 "traffic.rcs_dbsm.lorry" \
  "$dualgrid" run "$(sumo_case traffic_rcs_huge 'traffic: {route_files: [typed.rou.xml], rcs_dbsm: {lorry: 1e300}}
ego: {from_routes: v0}')" --no-figures -q --out "$work/s10"
check "sumo:traffic_rcs_tiny" 2 "traffic.rcs_dbsm.lorry" \
  "$dualgrid" run "$(sumo_case traffic_rcs_tiny 'traffic: {route_files: [typed.rou.xml], rcs_dbsm: {lorry: -1e300}}
ego: {from_routes: v0}')" --no-figures -q --out "$work/s11"
# The 3 MB comment is read in linear time: the run itself succeeds well within the time limit.
if out=$(cd "$work" && timeout 60 "$dualgrid" run "$(sumo_case comment 'duration: 1
traffic: {route_files: [comment.rou.xml]}
ego: {from_routes: v0}')" --modes dual --no-figures -q --out "$work/s9" 2>&1); then
  passed=$((passed + 1))
else
  failed=$((failed + 1))
  printf 'FAIL sumo:comment: a valid route file with a 3 MB comment did not run: %s\n' "$out"
fi

# 5.-10. What dualgrid reads back, sweeps, suites, step lengths, experiments (issue 26).
source "$here/read_back_cases.sh"

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
  text=${text//@S/$repo/scenarios/highway.yaml}
  eval "set -- $args"
  check "cli:$n: $args" "$code" "$text" "$dualgrid" "$@"
done <"$here/cli_cases.txt"

# 4. Recorded data (issue 23): RadarScenes files written by h5py from the public schema
# (tests/recorded/make_radarscenes.py --mutate KIND), and broken run folders. Each is one error
# line naming the file and the field, except NaN detections: a documented skip with a count.
py=${DUALGRID_PYTHON:-/usr/bin/python3}  # Debian's python3-h5py is for /usr/bin/python3
rec_case() {  # rec_case KIND CODE TEXT
  "$py" "$repo/tests/recorded/make_radarscenes.py" --out "$work/rs_$1" --duration 1 --mutate "$1" >/dev/null
  check "recorded:$1" "$2" "$3" "$dualgrid" filter "$work/rs_$1/data/sequence_1" --no-figures -q --out "$work/rso_$1"
}
rec_case missing_dataset 2 "radar_data.h5: dataset 'odometry' is missing"
rec_case missing_field 2 "dataset 'radar_data', field 'x_seq': missing"
rec_case wrong_type 2 "field 'vr_compensated': expected a float or integer, got string"
rec_case index_out_of_range 2 "scenes.json: key 'scenes.1600000000000000.radar_indices'"
rec_case index_overlap 2 "overlaps the previous scene's rows"
rec_case odometry_not_increasing 2 "dataset 'odometry', field 'timestamp': not increasing at row 5"
rec_case nan_odometry 2 "dataset 'odometry', field 'x_seq': not finite at row"
rec_case empty_sequence 2 "scenes.json: key 'scenes': no scenes (an empty sequence)"
rec_case truncated 2 "radar_data.h5"
rec_case bad_sensor 2 "sensor_id': 7 has no radar_7 in sensors.json"
rec_case not_json 2 "scenes.json: not valid JSON"
rec_case sensors_not_number 2 "sensors.json: key 'radar_2.x': expected a finite number, got \"front\""
rec_case missing_h5 2 "sequence_1/radar_data.h5: RadarScenes radar data not found"
rec_case label_out_of_range 2 "field 'label_id': 12 at row"
rec_case row_timestamp 2 "field 'timestamp': 1600000000000001 at row 0"
rec_case float_timestamp 2 "field 'timestamp': expected an integer, got a float"
# NaN positions and velocities (the last detections of some published sequences): skipped and
# counted in summary.json's input.skipped_detections, the run goes on.
"$py" "$repo/tests/recorded/make_radarscenes.py" --out "$work/rs_nan" --duration 1 --mutate nan_detections >/dev/null
if out=$(cd "$work" && timeout 60 "$dualgrid" filter "$work/rs_nan/data/sequence_1" --no-figures -q --out "$work/rso_nan" 2>&1) &&
   grep -q '"skipped_detections": 3' "$work/rso_nan/summary.json"; then
  passed=$((passed + 1))
else
  failed=$((failed + 1))
  printf 'FAIL recorded:nan_detections: not a run with 3 skipped detections: %s\n' "$out"
fi
# Run folders: without scans.csv (not recorded with --detections exact), and a damaged number.
mkdir -p "$work/runfolder"
echo '{}' >"$work/runfolder/summary.json"
check "recorded:run_without_scans" 2 "scans.csv: missing" \
  "$dualgrid" filter "$work/runfolder" --no-figures -q --out "$work/rso_run1"
check "recorded:export_without_scans" 2 "scans.csv: missing" \
  "$dualgrid" export "$work/runfolder" --out "$work/rso_run2"
printf 'step,time,sensor,sensor_name,ego_x,ego_y,ego_yaw,ego_vx,ego_vy,ego_yaw_rate,ego_length,ego_width,lane_yaw,mount_x,mount_y,mount_yaw,fov,min_range,max_range\n0,0.05,0,front,0,0,0,10,0,0,4.5,1.8,0,2.25,0,0,1,0.5,80\n' >"$work/runfolder/scans.csv"
printf 'step,time,sensor,sensor_name,range,azimuth,range_rate,snr_db,x_ego,y_ego,x,y,radial_speed,vrx,vry,sensor_x,sensor_y,source,is_clutter,vclass\n0,0.05,0,front,10,0,0,10,12,0,nan,0,0,0,0,2.25,0,clutter,1,\n' >"$work/runfolder/detections.csv"
check "recorded:run_nan_number" 2 "detections.csv: row 2, column 'x': expected a finite number, got 'nan'" \
  "$dualgrid" filter "$work/runfolder" --no-figures -q --out "$work/rso_run3"

# nuScenes (issue 40): a scene written by numpy + json (tests/recorded/make_nuscenes.py --mutate
# KIND), each broken one way: one error line naming the file and the field, exit 2.
ns_case() {  # ns_case KIND CODE TEXT
  "$py" "$repo/tests/recorded/make_nuscenes.py" --out "$work/ns_$1" --duration 1 --mutate "$1" >/dev/null
  check "nuscenes:$1" "$2" "$3" "$dualgrid" filter "$work/ns_$1" --scene scene-test --no-figures -q --out "$work/nso_$1"
}
ns_case missing_table 2 "v1.0-mini/ego_pose.json: missing: table 'ego_pose' is needed"
ns_case dangling_token 2 "sample_data.json: record 'sd-RADAR_FRONT-3', field 'ego_pose_token': token 'nowhere' points nowhere"
ns_case pcd_header 2 ".pcd: header keys 'TYPE'/'SIZE': field 'y' has type X"
ns_case pcd_short 2 "bytes after the header, fewer than its POINTS x row size"
ns_case nan_field 2 ".pcd: field 'vx_comp': not finite at point 1"
ns_case unknown_channel 2 "sensor.json: record 'sensor-RADAR_FRONT_LEFT', field 'channel': unknown radar channel 'RADAR_TOP'"
"$py" "$repo/tests/recorded/make_nuscenes.py" --out "$work/ns_ok" --duration 1 >/dev/null
check "nuscenes:unknown_scene" 2 "scene.json: field 'name': no scene named (or with token) 'scene-none'" \
  "$dualgrid" filter "$work/ns_ok" --scene scene-none --no-figures -q --out "$work/nso_scene"
check "nuscenes:unknown_version" 2 "v1.0-trainval: missing: no version folder" \
  "$dualgrid" filter "$work/ns_ok" --scene scene-test --version v1.0-trainval --no-figures -q --out "$work/nso_version"
check "nuscenes:version_without_scene" 2 "only with --scene" \
  "$dualgrid" filter "$work/ns_ok" --version v1.0-trainval --no-figures -q --out "$work/nso_noscene"
check "nuscenes:root_without_scene" 2 "a nuScenes root (v1.0-mini/scene.json): give --scene" \
  "$dualgrid" filter "$work/ns_ok" --no-figures -q --out "$work/nso_noscene2"
# A run with one radar cannot be the five channels.
mkdir -p "$work/onerun"
printf 'step,time,sensor,sensor_name,ego_x,ego_y,ego_yaw,ego_vx,ego_vy,ego_yaw_rate,ego_length,ego_width,lane_yaw,mount_x,mount_y,mount_yaw,fov,min_range,max_range\n1,0.5,0,front,0,0,0,10,0,0,4.5,1.8,0,2.25,0,0,1,0.5,80\n' >"$work/onerun/scans.csv"
printf 'step,time,sensor,sensor_name,range,azimuth,range_rate,snr_db,x_ego,y_ego,x,y,radial_speed,vrx,vry,sensor_x,sensor_y,source,is_clutter,vclass\n' >"$work/onerun/detections.csv"
printf 'step,time,id,type,is_ego,x,y,yaw,vx,vy,speed,lateral_speed,yaw_rate,length,width,lane,x_ego,y_ego,vx_ego,vy_ego,rcs_dbsm\n1,0.5,ego,ego,1,0,0,0,10,0,10,0,0,4.5,1.8,l,0,0,0,0,10\n' >"$work/onerun/ground_truth.csv"
echo '{"complete": true}' >"$work/onerun/summary.json"  # a finished run: only the radars are wrong
check "nuscenes:export_not_five_radars" 2 "nuScenes has five channels" \
  "$dualgrid" export "$work/onerun" --format nuscenes --out "$work/nso_export"
check "nuscenes:bad_states" 2 "--ambig-states: expected 'all' or whole numbers" \
  "$dualgrid" filter "$work/ns_ok" --scene scene-test --ambig-states 3,x --no-figures -q --out "$work/nso_states"

echo "hostile inputs: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
