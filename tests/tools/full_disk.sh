#!/usr/bin/env bash
# An experiment on a full disk (issue 26): each failed seed's line keeps its reason, though the
# seed's own log cannot be written; an export (issue 42) names the file and the reason. A 256 KiB
# tmpfs holds the outputs; mounting needs root (CI runs as root), otherwise the test is skipped
# (exit 77).
# Usage: full_disk.sh DUALGRID SCENARIO
set -uo pipefail
dualgrid=$1
scenario=$2
mnt=$(mktemp -d "${TMPDIR:-/tmp}/dualgrid_full_disk.XXXXXX")
if ! mount -t tmpfs -o size=256k tmpfs "$mnt" 2>/dev/null; then
  echo "cannot mount a tmpfs (not root?): skipped"
  rmdir "$mnt"
  exit 77
fi
trap 'umount "$mnt"; rmdir "$mnt"' EXIT
out=$("$dualgrid" experiment "$scenario" --seeds 2 -j 2 --duration 2 --no-figures -q \
  --detections csv --out "$mnt/exp" 2>&1)
code=$?
echo "$out"
fail=0
[ "$code" -eq 1 ] || [ "$code" -eq 3 ] || { echo "FAIL: exit code $code, expected 1 or 3"; fail=1; }
lines=$(printf '%s\n' "$out" | grep -c '^dualgrid: seed [0-9]* failed: ')
[ "$lines" -ge 1 ] || { echo "FAIL: no per-seed failure line"; fail=1; }
if printf '%s\n' "$out" | grep '^dualgrid: seed [0-9]* failed: ' | grep -qv 'No space left on device'; then
  echo "FAIL: a per-seed line lost the reason (No space left on device)"
  fail=1
fi
# The dataset writers (issue 42): an export onto a full disk names the file and the system's reason.
run=$(mktemp -d "${TMPDIR:-/tmp}/dualgrid_full_disk_run.XXXXXX")
trap 'umount "$mnt"; rmdir "$mnt"; rm -rf "$run"' EXIT
"$dualgrid" run "$scenario" --duration 2 --no-figures -q --detections exact --out "$run/r" ||
  { echo "FAIL: cannot make the run to export"; fail=1; }
for format in radarscenes nuscenes; do
  out=$("$dualgrid" export "$run/r" --format "$format" --out "$mnt/export_$format" 2>&1)
  code=$?
  echo "$out"
  [ "$code" -eq 1 ] || { echo "FAIL: export $format: exit code $code, expected 1"; fail=1; }
  [[ "$out" == "dualgrid: error: cannot write $mnt/export_$format/"*": No space left on device" ]] ||
    { echo "FAIL: export $format: the file or the reason is missing"; fail=1; }
done
[ "$fail" -eq 0 ] && echo "full disk: the reason is kept"
exit "$fail"
