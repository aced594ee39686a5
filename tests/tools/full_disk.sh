#!/usr/bin/env bash
# An experiment on a full disk (issue 26): each failed seed's line keeps its reason, though the
# seed's own log cannot be written. A 256 KiB tmpfs holds the experiment folder; mounting needs
# root (CI runs as root), otherwise the test is skipped (exit 77).
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
[ "$fail" -eq 0 ] && echo "full disk: the reason is kept"
exit "$fail"
